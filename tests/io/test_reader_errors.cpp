// Every reader rejects negative mass, non-unit normals (contacts, plane walls) and duplicate
// particle ids, and the CLI reports each as exactly one line `error: FILE: what (value)`, exit
// code 2, nothing on stdout and nothing written. Inputs are hand-written (ASCII VTK XML, legacy
// VTK, CSV, LIGGGHTS dump) or valid HDF5 files patched behind the library's back.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "../apps/cli_util.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "test_util.hpp"
#include "trajectory_io.hpp"

using namespace gs;
using gs::test::ScratchDir;
namespace fs = std::filesystem;

namespace {

std::string error_of(const fs::path& file) {
  try {
    (void)read_snapshots(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

void write_text(const fs::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << s;
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> s;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    s.insert(fs::relative(e.path(), dir).string());
  return s;
}

// The library error and the CLI error agree, to the byte: `info` prints exactly
// "error: <message>\n" and nothing on stdout, exit 2; `convert` to HDF5 also exits 2 with the same
// line and leaves the directory as it was (no output, no .partial, no temporary).
void expect_cli_rejects(const fs::path& file, const std::string& message,
                        const ScratchDir& scratch) {
  const auto log = scratch.path / "log";
  fs::create_directories(log);
  const auto before = listing(scratch.path);
  const auto info = gs::test::run_cli("info " + file.string(), log);
  EXPECT_EQ(info.rc, 2) << info.err;
  EXPECT_EQ(info.err, "error: " + message + "\n");
  EXPECT_EQ(info.out, "");
  const auto out = scratch.path / "converted.h5";
  const auto conv = gs::test::run_cli("convert " + file.string() + " " + out.string(), log);
  EXPECT_EQ(conv.rc, 2) << conv.err;
  EXPECT_EQ(conv.err, "error: " + message + "\n");
  EXPECT_EQ(listing(scratch.path), before);
}

// ------------------------------------------------------------------ hand-written inputs

// ASCII VTK XML particles: three spheres with ids `ids` and masses `masses` (text as written).
std::string vtu(const std::string& ids, const std::string& masses) {
  return R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="3" NumberOfCells="3">
      <PointData>
        <DataArray type="Float64" Name="radius" format="ascii">0.001 0.001 0.001</DataArray>
        <DataArray type="Float64" Name="id" format="ascii">)" +
         ids + R"(</DataArray>
        <DataArray type="Float64" Name="mass" format="ascii">)" +
         masses + R"(</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 0.002 0 0 0.004 0 0</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">1 2 3</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">1 1 1</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
)";
}

// ASCII VTK XML contacts: one contact 1-2 with normal `normal`.
std::string vtp(const std::string& normal) {
  return R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="2" NumberOfVerts="0" NumberOfLines="1" NumberOfStrips="0" NumberOfPolys="0">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 0.002 0 0</DataArray>
      </Points>
      <Lines>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">2</DataArray>
      </Lines>
      <CellData>
        <DataArray type="Float64" Name="id1" format="ascii">1</DataArray>
        <DataArray type="Float64" Name="id2" format="ascii">2</DataArray>
        <DataArray type="Float64" Name="point" NumberOfComponents="3" format="ascii">0.001 0 0</DataArray>
        <DataArray type="Float64" Name="normal" NumberOfComponents="3" format="ascii">)" +
         normal + R"(</DataArray>
        <DataArray type="Float64" Name="normal_force" NumberOfComponents="3" format="ascii">1 0 0</DataArray>
        <DataArray type="Float64" Name="shear_force" NumberOfComponents="3" format="ascii">0 0 0</DataArray>
      </CellData>
    </Piece>
  </PolyData>
</VTKFile>
)";
}

std::string pvd(const std::string& timestep, const std::string& file) {
  return "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
         "  <Collection>\n    <DataSet timestep=\"" +
         timestep + "\" part=\"0\" file=\"" + file + "\"/>\n  </Collection>\n</VTKFile>\n";
}

// YADE VTKExporter legacy spheres: ids and masses one per line.
std::string legacy_spheres(const std::string& ids, const std::string& masses) {
  return "# vtk DataFile Version 3.0.\ncomment\nASCII\n\nDATASET POLYDATA\nPOINTS 3 double\n"
         "0 0 0\n0.002 0 0\n0.004 0 0\nPOINT_DATA 3\nSCALARS radius double 1\n"
         "LOOKUP_TABLE default\n0.001\n0.001\n0.001\nSCALARS id double 1\nLOOKUP_TABLE default\n" +
         ids + "\nSCALARS mass double 1\nLOOKUP_TABLE default\n" + masses + "\n";
}

std::string legacy_intrs(const std::string& normal) {
  return "# vtk DataFile Version 3.0.\ncomment\nASCII\n\nDATASET POLYDATA\nPOINTS 2 double\n"
         "0 0 0\n0.002 0 0\nLINES 1 3\n2 0 1\nCELL_DATA 1\nSCALARS id1 double 1\n"
         "LOOKUP_TABLE default\n10\nSCALARS id2 double 1\nLOOKUP_TABLE default\n11\n"
         "VECTORS normal double\n" +
         normal + "\n";
}

std::string liggghts(const std::string& rows) {
  return "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 0.01\n"
         "0 0.01\n0 0.01\nITEM: ATOMS id type x y z radius mass\n" +
         rows;
}

// ------------------------------------------------------------------ HDF5 patching

// Overwrites row `row` of dataset `name` (rows of `v.size()` values) in an existing file.
template <class T>
void patch_row(const fs::path& file, const char* name, hsize_t row, const std::vector<T>& v) {
  const hid_t mt = std::is_same_v<T, double> ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT64;
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  ASSERT_GE(d, 0) << name;
  hid_t fs = H5Dget_space(d);
  const int rank = H5Sget_simple_extent_ndims(fs);
  hsize_t start[2] = {row, 0}, count[2] = {1, v.size()};
  H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, nullptr, count, nullptr);
  hsize_t n = v.size();
  hid_t ms = H5Screate_simple(1, &n, nullptr);
  ASSERT_EQ(rank == 1 ? 1u : v.size(), v.size());
  EXPECT_GE(H5Dwrite(d, mt, ms, fs, H5P_DEFAULT, v.data()), 0);
  H5Sclose(ms);
  H5Sclose(fs);
  H5Dclose(d);
  H5Fclose(f);
}

// One frame: particles 1, 2, 3 (mass 1e-5), contact 1-2 along +x, plane wall 4 (normal +z).
Trajectory small_run() {
  Frame f;
  for (int i = 0; i < 3; ++i) {
    Particle p;
    p.id = i + 1;
    p.position = {0.002 * i, 0, 0};
    p.radius = 0.001;
    p.mass = 1e-5;
    f.particles.push_back(p);
  }
  Contact c;
  c.id1 = 1;
  c.id2 = 2;
  c.point = {0.001, 0, 0};
  c.normal = {1, 0, 0};
  f.contacts.push_back(c);
  Wall w;
  w.id = 4;
  w.kind = WallKind::Plane;
  w.b = {0, 0, 1};
  f.walls.push_back(w);
  Trajectory t;
  t.metadata.provenance = "test";
  t.frames = {f};
  return t;
}

}  // namespace

// Exact messages: the particle/contact/wall named by id, the offending value in parentheses
// (17 significant digits: -0.5, |n| = 2, ...).
TEST(ReaderErrors, Hdf5NegativeMassNonUnitNormalsDuplicateIds) {
  ScratchDir dir("rerr_h5");
  write_hdf5_trajectory(dir / "good.h5", small_run());
  ASSERT_EQ(read_snapshots(dir / "good.h5").frames.at(0).particles.size(), 3u);
  struct Case {
    const char* file;
    const char* dataset;
    hsize_t row;
    std::vector<double> f64;
    std::vector<std::int64_t> i64;
    std::string what;
  };
  const std::vector<Case> cases = {
      {"mass.h5", "/particles/mass", 2, {-0.5}, {}, "particle 3 mass is negative (-0.5)"},
      {"normal.h5",
       "/contacts/normal",
       0,
       {0, 2, 0},
       {},
       "contact 1-2 normal is not a unit vector, |n| (2)"},
      {"wall.h5",
       "/walls/b",
       0,
       {0, 0, 0.5},
       {},
       "wall 4 plane normal is not a unit vector, |n| (0.5)"},
      {"dup.h5", "/particles/id", 2, {}, {1}, "duplicate particle id (1)"},
  };
  for (const auto& c : cases) {
    const auto bad = dir / c.file;
    fs::copy_file(dir / "good.h5", bad);
    if (c.i64.empty())
      patch_row(bad, c.dataset, c.row, c.f64);
    else
      patch_row(bad, c.dataset, c.row, c.i64);
    const std::string msg = bad.string() + " frame 0: " + c.what;
    EXPECT_EQ(error_of(bad), msg);
    expect_cli_rejects(bad, msg, dir);
  }
}

// Clump bodies (schema_version 2): a NaN in a clump dataset, a non-unit orientation, a mass of
// zero, a member naming a missing clump, a clump left without members. Each gives its one line
// through the library, `info`, `convert` and `analyze fabric` (exit 2).
TEST(ReaderErrors, Hdf5ClumpBodiesNaNBadOrientationMassAndMissingClumps) {
  ScratchDir dir("rerr_h5_clumps");
  Trajectory t = small_run();
  auto& f = t.frames[0];
  f.particles[0].clump_id = f.particles[1].clump_id = 10;  // particles 1 and 2: clump 10
  Clump c;
  c.id = 10;
  c.template_name = "dimer";
  c.position = {0.001, 0, 0};
  c.mass = 2e-5;
  c.principal_inertia = {1e-12, 3e-12, 3e-12};
  f.clumps = {c};
  write_hdf5_trajectory(dir / "good.h5", t);
  ASSERT_EQ(read_snapshots(dir / "good.h5").frames.at(0).clumps.size(), 1u);
  struct Case {
    const char* file;
    const char* dataset;
    hsize_t row;
    std::vector<double> f64;
    std::vector<std::int64_t> i64;
    std::string what;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Case> cases = {
      {"nan_mass.h5", "/clumps/mass", 0, {nan}, {}, "clump 10 mass is not finite (nan)"},
      {"nan_pos.h5",
       "/clumps/position",
       0,
       {0, nan, 0},
       {},
       "clump 10 position is not finite (nan)"},
      {"ori.h5",
       "/clumps/orientation",
       0,
       {2, 0, 0, 0},
       {},
       "clump 10 orientation is not a unit quaternion, |q| (2)"},
      {"mass0.h5", "/clumps/mass", 0, {0}, {}, "clump 10 mass is not positive (0)"},
      {"missing.h5", "/particles/clump_id", 2, {}, {11}, "particle 3 names a missing clump (11)"},
      {"orphan.h5", "/clumps/id", 0, {}, {11}, "particle 1 names a missing clump (10)"},
  };
  for (const auto& k : cases) {
    const auto bad = dir / k.file;
    fs::copy_file(dir / "good.h5", bad);
    if (k.i64.empty())
      patch_row(bad, k.dataset, k.row, k.f64);
    else
      patch_row(bad, k.dataset, k.row, k.i64);
    const std::string msg = bad.string() + " frame 0: " + k.what;
    EXPECT_EQ(error_of(bad), msg);
    expect_cli_rejects(bad, msg, dir);
    const auto log = dir / "log";
    const auto fab = gs::test::run_cli(
        "analyze fabric " + bad.string() + " -o " + (dir / "fabric.h5").string(), log);
    EXPECT_EQ(fab.rc, 2) << fab.err;
    EXPECT_EQ(fab.err, "error: " + msg + "\n");
    EXPECT_FALSE(fs::exists(dir / "fabric.h5"));
  }
  // A clump without members: the members of clump 10 leave it (clump_id -1).
  const auto orphan = dir / "no_members.h5";
  fs::copy_file(dir / "good.h5", orphan);
  patch_row(orphan, "/particles/clump_id", 0, std::vector<std::int64_t>{-1});
  patch_row(orphan, "/particles/clump_id", 1, std::vector<std::int64_t>{-1});
  const std::string msg = orphan.string() + " frame 0: clump has no member particle (10)";
  EXPECT_EQ(error_of(orphan), msg);
  expect_cli_rejects(orphan, msg, dir);
}

TEST(ReaderErrors, VtuVtpNegativeMassNonUnitNormalDuplicateAndFractionalIds) {
  ScratchDir dir("rerr_vtu");
  write_text(dir / "good.vtu", vtu("1 2 3", "1e-5 1e-5 1e-5"));
  write_text(dir / "good.vtp", vtp("1 0 0"));
  const Frame ok = read_snapshots(dir / "good.vtu").frames.at(0);
  ASSERT_EQ(ok.particles.size(), 3u);
  ASSERT_EQ(ok.contacts.size(), 1u);  // the .vtp beside it was read
  EXPECT_EQ(ok.particles[2].mass, 1e-5);

  write_text(dir / "mass.vtu", vtu("1 2 3", "1e-5 1e-5 -0.5"));
  write_text(dir / "dup.vtu", vtu("1 2 1", "1e-5 1e-5 1e-5"));
  write_text(dir / "frac.vtu", vtu("1 2 2.5", "1e-5 1e-5 1e-5"));
  write_text(dir / "normal.vtu", vtu("1 2 3", "1e-5 1e-5 1e-5"));
  write_text(dir / "normal.vtp", vtp("0 2 0"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"mass.vtu", "mass.vtu: particle 3 mass is negative (-0.5)"},
      {"dup.vtu", "dup.vtu: duplicate particle id (1)"},
      {"frac.vtu", "frac.vtu: particle id is not an integer (2.5)"},
      {"normal.vtu", "normal.vtp: contact 1-2 normal is not a unit vector, |n| (2)"},
  };
  for (const auto& [file, what] : cases) {
    const std::string msg = (dir.path / what).string();
    EXPECT_EQ(error_of(dir / file), msg);
    expect_cli_rejects(dir / file, msg, dir);
  }
}

// A .pvd reports the frame file at fault, and its own bad timestep (NaN used to be accepted when
// no contact series sat beside it: `info` printed "time: nan .. nan").
TEST(ReaderErrors, PvdNamesTheBadFrameFileAndRejectsNonFiniteTimesteps) {
  ScratchDir dir("rerr_pvd");
  fs::create_directories(dir / "s_files");
  write_text(dir / "s_files" / "p0.vtu", vtu("1 2 3", "1e-5 1e-5 1e-5"));
  write_text(dir / "s_files" / "p1.vtu", vtu("1 2 3", "1e-5 -0.5 1e-5"));
  write_text(dir / "good.pvd", pvd("0.25", "s_files/p0.vtu"));
  EXPECT_EQ(read_snapshots(dir / "good.pvd").frames.at(0).time, 0.25);
  write_text(dir / "mass.pvd", pvd("0.5", "s_files/p1.vtu"));
  const std::string mass_msg =
      (dir.path / "s_files/p1.vtu").string() + ": particle 2 mass is negative (-0.5)";
  EXPECT_EQ(error_of(dir / "mass.pvd"), mass_msg);
  expect_cli_rejects(dir / "mass.pvd", mass_msg, dir);
  for (const char* t : {"nan", "inf"}) {
    write_text(dir / "time.pvd", pvd(t, "s_files/p0.vtu"));
    const std::string msg =
        (dir / "time.pvd").string() + ": DataSet timestep is not finite (" + t + ")";
    EXPECT_EQ(error_of(dir / "time.pvd"), msg);
    expect_cli_rejects(dir / "time.pvd", msg, dir);
  }
}

TEST(ReaderErrors, YadeLegacyVtkNegativeMassNonUnitNormalDuplicateIds) {
  ScratchDir dir("rerr_vtk");
  write_text(dir / "good-spheres-0.vtk", legacy_spheres("10\n11\n12", "1e-5\n1e-5\n1e-5"));
  write_text(dir / "good-intrs-0.vtk", legacy_intrs("1 0 0"));
  const Frame ok = read_snapshots(dir / "good-spheres-0.vtk").frames.at(0);
  ASSERT_EQ(ok.particles.size(), 3u);
  ASSERT_EQ(ok.contacts.size(), 1u);
  EXPECT_EQ(ok.particles[1].id, 11);

  write_text(dir / "mass-spheres-0.vtk", legacy_spheres("10\n11\n12", "1e-5\n-0.5\n1e-5"));
  write_text(dir / "dup-spheres-0.vtk", legacy_spheres("10\n12\n12", "1e-5\n1e-5\n1e-5"));
  write_text(dir / "frac-spheres-0.vtk", legacy_spheres("10\n11.5\n12", "1e-5\n1e-5\n1e-5"));
  write_text(dir / "normal-spheres-0.vtk", legacy_spheres("10\n11\n12", "1e-5\n1e-5\n1e-5"));
  write_text(dir / "normal-intrs-0.vtk", legacy_intrs("0 3 0"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"mass-spheres-0.vtk", "mass-spheres-0.vtk: particle 11 mass is negative (-0.5)"},
      {"dup-spheres-0.vtk", "dup-spheres-0.vtk: duplicate particle id (12)"},
      {"frac-spheres-0.vtk", "frac-spheres-0.vtk: particle id is not an integer (11.5)"},
      {"normal-spheres-0.vtk",
       "normal-intrs-0.vtk: contact 10-11 normal is not a unit vector, |n| (3)"},
  };
  for (const auto& [file, what] : cases) {
    const std::string msg = (dir.path / what).string();
    EXPECT_EQ(error_of(dir / file), msg);
    expect_cli_rejects(dir / file, msg, dir);
  }
}

// CSV packings carry no mass and no normals: duplicate ids are what can go wrong.
TEST(ReaderErrors, PackingCsvDuplicateIds) {
  ScratchDir dir("rerr_csv");
  write_text(dir / "dup.csv", "id,x,y,z,r\n1,0,0,0,0.001\n2,0.002,0,0,0.001\n1,0.004,0,0,0.001\n");
  const std::string msg = (dir / "dup.csv").string() + ": duplicate particle id (1)";
  EXPECT_EQ(error_of(dir / "dup.csv"), msg);
  expect_cli_rejects(dir / "dup.csv", msg, dir);
}

// LIGGGHTS normals are computed from the centres (always unit); mass and ids come from the dump.
TEST(ReaderErrors, LiggghtsDumpNegativeMassDuplicateIds) {
  ScratchDir dir("rerr_lig");
  write_text(dir / "mass.dump",
             liggghts("1 1 0.002 0.002 0.002 0.001 -0.5\n2 1 0.006 0.002 0.002 0.001 1e-5\n"));
  write_text(dir / "dup.dump",
             liggghts("7 1 0.002 0.002 0.002 0.001 1e-5\n7 1 0.006 0.002 0.002 0.001 1e-5\n"));
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"mass.dump", "mass.dump timestep 100: particle 1 mass is negative (-0.5)"},
      {"dup.dump", "dup.dump timestep 100: duplicate particle id (7)"},
  };
  for (const auto& [file, what] : cases) {
    const std::string msg = (dir.path / what).string();
    EXPECT_EQ(error_of(dir / file), msg);
    expect_cli_rejects(dir / file, msg, dir);
  }
}

// Damaged files of each VTK flavour, through the CLI: the exact one-line messages (file, what,
// the offending token in parentheses), exit 2, nothing written.
TEST(ReaderErrors, DamagedVtkVtuPvdFilesAreOneLineThroughTheCli) {
  ScratchDir dir("rerr_damaged");
  write_text(dir / "bad-spheres-0.vtk",
             "# vtk DataFile Version 3.0.\nc\nASCII\nDATASET POLYDATA\nPOINTS 2 double\n0 0 0\n"
             "1 abc 0\n");
  write_text(dir / "cut.vtu", vtu("1 2 3", "1e-5 1e-5 1e-5").substr(0, 200));
  write_text(dir / "missing.pvd", pvd("0", "gone/p.vtu"));
  // A NUL byte right after the 37-byte header.
  write_text(dir / "binary.vtk",
             std::string("# vtk DataFile Version 3.0.\nc\nBINARY\n") + std::string(1, '\0') + "x");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bad-spheres-0.vtk", "bad-spheres-0.vtk: line 7: bad number in point coordinate (abc)"},
      {"binary.vtk", "binary.vtk: binary content in a text file (NUL byte at offset 37)"},
      {"missing.pvd", "gone/p.vtu: no such file"},
  };
  for (const auto& [file, what] : cases) {
    const std::string msg = (dir.path / what).string();
    EXPECT_EQ(error_of(dir / file), msg);
    expect_cli_rejects(dir / file, msg, dir);
  }
  // A truncated XML file: VTK's parser reads no points; the message names the file.
  const std::string cut = error_of(dir / "cut.vtu");
  EXPECT_EQ(cut.rfind((dir / "cut.vtu").string() + ": ", 0), 0u) << cut;
  expect_cli_rejects(dir / "cut.vtu", cut, dir);
}
