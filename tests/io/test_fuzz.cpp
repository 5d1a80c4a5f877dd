// Bounded mutation fuzzing of every reader: each fixture is bit-flipped and truncated, and each
// mutant must give either a valid result or an InputError — no crash, no hang, no other error.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <chrono>
#include <fstream>
#include <random>

#include "../apps/cli_util.hpp"
#include "errors.hpp"
#include "test_util.hpp"
#include "trajectory_io.hpp"

using namespace gs;

namespace {

const std::filesystem::path kData = GS_TEST_DATA_DIR;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void spit(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(s.data(), static_cast<std::streamsize>(s.size()));
}

struct Outcome {
  int ok = 0, rejected = 0;
};

// Mutates `victim` (a copy inside dir) `rounds` times and reads `entry` each time.
Outcome fuzz(const std::filesystem::path& victim, const std::filesystem::path& entry, int rounds,
             unsigned seed) {
  const std::string original = slurp(victim);
  std::mt19937 rng(seed);
  Outcome out;
  for (int k = 0; k < rounds; ++k) {
    std::string m = original;
    switch (k % 4) {
      case 0:  // a few bit flips anywhere
      case 1: {
        const int flips = 1 + static_cast<int>(rng() % 8);
        for (int f = 0; f < flips && !m.empty(); ++f)
          m[rng() % m.size()] ^= static_cast<char>(1u << (rng() % 8));
        break;
      }
      case 2:  // truncation
        m.resize(rng() % (m.size() + 1));
        break;
      case 3: {  // a run of random bytes
        if (m.empty()) break;
        const std::size_t at = rng() % m.size(), len = 1 + rng() % 16;
        for (std::size_t i = at; i < std::min(m.size(), at + len); ++i)
          m[i] = static_cast<char>(rng());
        break;
      }
    }
    spit(victim, m);
    try {
      const Trajectory t = read_snapshots(entry);
      for (const auto& f : t.frames) validate_frame(f, "mutant");  // a valid result
      ++out.ok;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_FALSE(msg.empty());
      EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
      ++out.rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << victim << " mutant " << k << ": unexpected " << typeid(e).name() << ": "
                    << e.what();
    }
  }
  spit(victim, original);
  return out;
}

}  // namespace

class Fuzz : public ::testing::TestWithParam<std::vector<std::string>> {};

// Parameters: files copied into a scratch directory; the first is read, the last is mutated.
TEST_P(Fuzz, MutantsAreRejectedOrValid) {
  const auto files = GetParam();
  gs::test::ScratchDir dir("fuzz");
  for (const auto& f : files)
    std::filesystem::copy_file(kData / f, dir / std::filesystem::path(f).filename().string());
  const auto entry = dir / std::filesystem::path(files.front()).filename().string();
  const auto victim = dir / std::filesystem::path(files.back()).filename().string();
  const Outcome o = fuzz(victim, entry, 120, 12345u + static_cast<unsigned>(files.back().size()));
  EXPECT_GT(o.rejected, 0) << "mutations never detected";
  RecordProperty("ok", o.ok);
  RecordProperty("rejected", o.rejected);
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, Fuzz,
    ::testing::Values(std::vector<std::string>{"packing_small.csv"},
                      std::vector<std::string>{"yade/yade_spheres.20000.vtu"},
                      std::vector<std::string>{"yade/yade_export-spheres-00000000.vtk"},
                      std::vector<std::string>{"yade/yade_export-spheres-00000000.vtk",
                                               "yade/yade_export-intrs-00000000.vtk"},
                      std::vector<std::string>{"liggghts/dump.atoms"},
                      std::vector<std::string>{"liggghts/dump.atoms", "liggghts/dump.pairs"}));

// Our own binary formats, made on the fly.
TEST(FuzzOwnFormats, Hdf5VtuVtpPvd) {
  gs::test::ScratchDir dir("fuzz_own");
  Trajectory t;
  t.frames = {gs::test::random_frame(30, 20, 1, 0.0), gs::test::random_frame(25, 10, 2, 1.0)};
  for (auto& f : t.frames) f.walls.clear();
  write_snapshots(dir / "run.h5", t);
  write_snapshots(dir / "one.vtu", t);
  write_snapshots(dir / "series.pvd", t);
  for (const auto& [entry, victim] : std::vector<std::pair<std::string, std::string>>{
           {"run.h5", "run.h5"},
           {"one.vtu", "one.vtu"},
           {"one.vtu", "one.vtp"},
           {"series.pvd", "series.pvd"},
           {"series.pvd", "series_files/particles_000001.vtu"}}) {
    const Outcome o = fuzz(dir / victim, dir / entry, 120, 777u);
    EXPECT_GT(o.rejected, 0) << victim;
  }
}

// ------------------------------------------------------------------ hostile headers (issue 15)
// Hand-made files that crashed the readers (negative counts, 200 000 nested elements), made them
// allocate gigabytes from a few kilobytes (a compression header claiming 2^30 blocks, a
// NumberOfPoints of 1e8 or 1e12), or read fewer values than the file holds without a word. Each
// must give its one exact line through the library and the CLI (exit 2, nothing written).

namespace {

std::string vtu_text(const std::string& npoints, const std::string& ncells,
                     const std::string& values = "") {
  const std::string v = values.empty() ? "0.001 0.001 0.001" : values;
  return R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints=")" +
         npoints + R"(" NumberOfCells=")" + ncells + R"(">
      <PointData>
        <DataArray type="Float64" Name="radius" format="ascii">)" +
         v + R"(</DataArray>
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

// Appended raw zlib data whose header claims `blocks` blocks, padded to ~7.7 kB.
std::string block_bomb(std::uint32_t blocks) {
  std::string s =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\">\n"
      "<UnstructuredGrid><Piece NumberOfPoints=\"3\" NumberOfCells=\"0\"><PointData>"
      "<DataArray type=\"Float64\" Name=\"radius\" format=\"appended\" offset=\"0\"/></PointData>"
      "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" "
      "offset=\"0\"/></Points></Piece></UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_";
  const std::uint32_t hdr[3] = {blocks, 32768, 100};
  s.append(reinterpret_cast<const char*>(hdr), sizeof hdr);
  s += std::string(7000, '\0') + "\n</AppendedData>\n</VTKFile>\n";
  return s;
}

struct Hostile {
  std::string file, content, what;  // what: the message after "FILE: "
};

void expect_hostile_rejected(const gs::test::ScratchDir& dir, const std::vector<Hostile>& cases) {
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  for (const auto& c : cases) {
    const auto path = dir / c.file;
    spit(path, c.content);
    const std::string msg = path.string() + ": " + c.what;
    try {
      (void)read_snapshots(path);
      ADD_FAILURE() << c.file << ": accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.what(), msg);
    }
    const auto r =
        gs::test::run_cli("convert " + path.string() + " " + (dir / "out.h5").string(), log);
    EXPECT_EQ(r.rc, 2) << c.file;
    EXPECT_EQ(r.err, "error: " + msg + "\n");
    EXPECT_EQ(r.out, "");
    EXPECT_FALSE(std::filesystem::exists(dir / "out.h5"));
    EXPECT_FALSE(std::filesystem::exists(dir / "out.h5.partial"));
  }
}

}  // namespace

TEST(HostileInputs, VtkXmlHeadersAreCheckedBeforeVtkTrustsThem) {
  gs::test::ScratchDir dir("hostile_vtu");
  std::string deep = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">";
  for (int i = 0; i < 200000; ++i) deep += "<a>";
  for (int i = 0; i < 200000; ++i) deep += "</a>";
  deep += "</VTKFile>\n";
  std::string forty;
  for (int i = 0; i < 40; ++i) forty += "0.001 ";
  const std::vector<Hostile> cases = {
      {"np-1.vtu", vtu_text("-1", "3"), "Piece NumberOfPoints is not a non-negative integer (-1)"},
      {"np-5.vtu", vtu_text("-5", "3"), "Piece NumberOfPoints is not a non-negative integer (-5)"},
      {"nc-1.vtu", vtu_text("3", "-1"), "Piece NumberOfCells is not a non-negative integer (-1)"},
      {"nc-5.vtu", vtu_text("3", "-5"), "Piece NumberOfCells is not a non-negative integer (-5)"},
      {"deep.vtu", deep, "XML elements nested too deep (more than 64 levels)"},
      {"bomb.vtu", block_bomb(1u << 30),
       "DataArray radius compression header claims more blocks than the file holds (1073741824 "
       "blocks)"},
      {"np1e8.vtu", vtu_text("100000000", "3"),
       "Piece NumberOfPoints exceeds what the file can hold (100000000)"},
      {"np1e12.vtu", vtu_text("1000000000000", "3"),
       "Piece NumberOfPoints exceeds what the file can hold (1000000000000)"},
      {"extra.vtu", vtu_text("3", "3", forty),
       "DataArray radius holds a different number of values than declared (40 values, expected "
       "3)"},
      {"short.vtu", vtu_text("3", "3", "0.001 0.001"),
       "DataArray radius holds a different number of values than declared (2 values, expected "
       "3)"},
  };
  expect_hostile_rejected(dir, cases);
}

// The binary flavours: our appended raw zlib .vtu and YADE's appended base64 one, with
// NumberOfPoints one short of the 40 values they hold (VTK read 39 particles, exit 0).
TEST(HostileInputs, BinaryVtuWithFewerPointsDeclaredThanStored) {
  gs::test::ScratchDir dir("hostile_vtu_bin");
  const std::string yade = slurp(kData / "yade/yade_spheres.20000.vtu");
  ASSERT_EQ(read_snapshots(kData / "yade/yade_spheres.20000.vtu").frames.at(0).particles.size(),
            40u);
  write_snapshots(dir / "ours.vtu", read_snapshots(kData / "yade/yade_spheres.20000.vtu"));
  const std::string ours = slurp(dir / "ours.vtu");
  auto edit = [](std::string s, const std::string& from, const std::string& to) {
    const auto k = s.find(from);
    EXPECT_NE(k, std::string::npos) << from;
    if (k != std::string::npos) s.replace(k, from.size(), to);
    return s;
  };
  auto cut_to_39 = [](std::string s) {
    const auto k = s.find("NumberOfPoints=\"40\"");
    EXPECT_NE(k, std::string::npos);
    s.replace(k, 19, "NumberOfPoints=\"39\"");
    return s;
  };
  const std::vector<Hostile> cases = {
      {"yade39.vtu", cut_to_39(yade),
       "DataArray radii holds a different number of bytes than declared (320 bytes, expected "
       "312)"},
      {"ours39.vtu", cut_to_39(slurp(dir / "ours.vtu")),
       "DataArray id holds a different number of bytes than declared (320 bytes, expected 312)"},
      // Mutants of the fuzz run that crashed VTK (SIGSEGV).
      {"type.vtu",
       edit(ours, "type=\"Float64\" Name=\"domain_hi\"", "type=\"Float10.5\" Name=\"domain_hi\""),
       "DataArray domain_hi has an unknown type (Float10.5)"},
      {"tuples.vtu",
       edit(ours, "Name=\"domain_lo\" NumberOfComponents=\"3\" NumberOfTuples=\"1\"",
            "Name=\"domain_lo\" NumberOfComponents=\"3\" NumberOfTuples=\"-1\""),
       "DataArray domain_lo NumberOfTuples is not a count the file can hold (-1)"},
      {"offset.vtu", edit(ours, "offset=\"0\"", "offset=\"1e30\""),
       "DataArray TimeValue offset is not a non-negative integer (1e30)"},
  };
  expect_hostile_rejected(dir, cases);
}

// HDF5: a file of a few kilobytes whose datasets declare 10^8 particles (took 23 GB and was
// killed); links into other files (followed silently); and a long trajectory of empty frames,
// which `convert` wrote in super-linear time (10^4 frames 2.5 s, 3·10^4 frames 9.6 s).
TEST(HostileInputs, Hdf5DeclaredRowsExternalLinksAndLongTrajectories) {
  gs::test::ScratchDir dir("hostile_h5");
  Trajectory t;
  t.frames = {gs::test::random_frame(30, 20, 1, 0.0)};
  for (auto& f : t.frames) f.walls.clear();
  write_snapshots(dir / "good.h5", t);
  ASSERT_EQ(read_snapshots(dir / "good.h5").frames.size(), 1u);

  // 10^8 particles declared: the datasets extended (no chunk written), the frame index patched.
  std::filesystem::copy_file(dir / "good.h5", dir / "big.h5");
  {
    const hid_t f = H5Fopen((dir / "big.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    for (const char* d : {"id", "position", "radius", "velocity", "angular_velocity", "orientation",
                          "rotation", "mass", "clump_id", "material_id"}) {
      const hid_t ds = H5Dopen2(f, (std::string("/particles/") + d).c_str(), H5P_DEFAULT);
      ASSERT_GE(ds, 0) << d;
      const hid_t sp = H5Dget_space(ds);
      hsize_t dims[2] = {0, 0};
      const int rank = H5Sget_simple_extent_dims(sp, dims, nullptr);
      dims[0] = 100000000;
      ASSERT_GE(rank, 1);
      EXPECT_GE(H5Dset_extent(ds, dims), 0);
      H5Sclose(sp);
      H5Dclose(ds);
    }
    const hid_t e = H5Dopen2(f, "/frames/end", H5P_DEFAULT);
    const std::int64_t end[3] = {100000000, 20, 0};
    EXPECT_GE(H5Dwrite(e, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, end), 0);
    H5Dclose(e);
    H5Fclose(f);
  }
  const std::string big = (dir / "big.h5").string();
  try {
    (void)read_snapshots(dir / "big.h5");
    ADD_FAILURE() << "10^8 declared particles accepted";
  } catch (const InputError& e) {
    const std::string want =
        big +
        ": dataset declares more rows than the file stores (/particles/id: 100000000 rows in ";
    EXPECT_EQ(std::string(e.what()).rfind(want, 0), 0u) << e.what();
  }

  // External links: one dataset, and a whole group, into another (valid) file.
  std::filesystem::copy_file(dir / "good.h5", dir / "other.h5");
  for (const auto& [file, link] : std::vector<std::pair<std::string, std::string>>{
           {"ext_ds.h5", "/particles/radius"}, {"ext_group.h5", "/particles"}}) {
    std::filesystem::copy_file(dir / "good.h5", dir / file);
    const hid_t f = H5Fopen((dir / file).c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    EXPECT_GE(H5Ldelete(f, link.c_str(), H5P_DEFAULT), 0);
    EXPECT_GE(H5Lcreate_external((dir / "other.h5").c_str(), link.c_str(), f, link.c_str(),
                                 H5P_DEFAULT, H5P_DEFAULT),
              0);
    H5Fclose(f);
  }
  const std::vector<Hostile> links = {
      {"ext_ds.h5", slurp(dir / "ext_ds.h5"), "external link not followed (/particles/radius)"},
      {"ext_group.h5", slurp(dir / "ext_group.h5"), "external link not followed (/particles)"},
  };
  expect_hostile_rejected(dir, links);

  // 2·10^5 empty frames: written and read back in linear time (was ~15 minutes extrapolated).
  Trajectory many;
  many.frames.resize(200000);
  for (std::size_t i = 0; i < many.frames.size(); ++i) {
    many.frames[i].step = static_cast<std::int64_t>(i);
    many.frames[i].time = static_cast<double>(i);
  }
  const auto t0 = std::chrono::steady_clock::now();
  write_snapshots(dir / "many.h5", many);
  const Trajectory back = read_snapshots(dir / "many.h5");
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(back.frames.size(), many.frames.size());
  EXPECT_EQ(back.frames.back().step, 199999);
  EXPECT_LT(secs, 60.0);
}

// Silently wrong imports: two LIGGGHTS blocks with one TIMESTEP (every pair went to the last),
// a .pvd cut in half (8 of 17 frames, exit 0); and a CSV with a UTF-8 byte-order mark (its id
// column was "missing"), which is accepted.
TEST(HostileInputs, RepeatedTimestepsCutCollectionsAndByteOrderMarks) {
  gs::test::ScratchDir dir("hostile_text");
  const std::string block =
      "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 0.01\n0 0.01\n"
      "0 0.01\nITEM: ATOMS id type x y z radius mass\n1 1 0.002 0.002 0.002 0.001 1e-5\n"
      "2 1 0.0039 0.002 0.002 0.001 1e-5\n";
  std::string series =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
      "  <Collection>\n";
  for (int i = 0; i < 17; ++i)
    series += "    <DataSet timestep=\"" + std::to_string(i) + "\" part=\"0\" file=\"p.vtu\"/>\n";
  series += "  </Collection>\n</VTKFile>\n";
  spit(dir / "p.vtu", vtu_text("3", "3"));
  spit(dir / "full.pvd", series);
  ASSERT_EQ(read_snapshots(dir / "full.pvd").frames.size(), 17u);
  const std::vector<Hostile> cases = {
      {"twice.dump", block + block, "line 12: timestep repeats the block at line 1 (100)"},
      {"cut.pvd", series.substr(0, series.size() / 2),
       "truncated collection (no closing </Collection> and </VTKFile>)"},
  };
  expect_hostile_rejected(dir, cases);

  spit(dir / "bom.csv", "\xEF\xBB\xBFid,x,y,z,r\n1,0,0,0,0.001\n2,0.003,0,0,0.001\n");
  const Frame f = read_snapshots(dir / "bom.csv").frames.at(0);
  ASSERT_EQ(f.particles.size(), 2u);
  EXPECT_EQ(f.particles[1].id, 2);
  EXPECT_EQ(f.particles[1].position.x(), 0.003);
}

// Already one clean line before issue 15, kept in the corpus: ids NaN or 1e30 in a .vtu, a
// fractional interaction id in legacy VTK.
TEST(HostileInputs, NonIntegralIdsStayRejected) {
  gs::test::ScratchDir dir("hostile_ids");
  const std::string rad = "Name=\"radius\" format=\"ascii\">0.001 0.001 0.001</DataArray>";
  auto with_ids = [&](const std::string& ids) {
    std::string s = vtu_text("3", "3");
    s.replace(s.find(rad), rad.size(),
              rad + "\n        <DataArray type=\"Float64\" Name=\"id\" format=\"ascii\">" + ids +
                  "</DataArray>");
    return s;
  };
  spit(dir / "f-spheres-0.vtk",
       "# vtk DataFile Version 3.0.\nc\nASCII\nDATASET POLYDATA\nPOINTS 2 double\n0 0 0\n"
       "0.002 0 0\nPOINT_DATA 2\nSCALARS radius double 1\nLOOKUP_TABLE default\n0.001\n0.001\n"
       "SCALARS id double 1\nLOOKUP_TABLE default\n10\n11\n");
  const std::string intrs =
      "# vtk DataFile Version 3.0.\nc\nASCII\nDATASET POLYDATA\nPOINTS 2 double\n0 0 0\n"
      "0.002 0 0\nLINES 1 3\n2 0 1\nCELL_DATA 1\nSCALARS id1 double 1\nLOOKUP_TABLE default\n"
      "10.5\nSCALARS id2 double 1\nLOOKUP_TABLE default\n11\n";
  spit(dir / "f-intrs-0.vtk", intrs);
  try {
    (void)read_snapshots(dir / "f-spheres-0.vtk");
    ADD_FAILURE() << "fractional interaction id accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.what(),
              (dir / "f-intrs-0.vtk").string() + ": interaction id1 is not an integer (10.5)");
  }
  const std::vector<Hostile> cases = {
      {"nan.vtu", with_ids("1 nan 3"), "particle id is not an integer (nan)"},
      {"big.vtu", with_ids("1 1e30 3"), "particle id is not an integer (1e+30)"},
  };
  expect_hostile_rejected(dir, cases);
}

// The CLI: a thread count of a million crashed `simulate` (SIGSEGV), from the command line or
// the scene; --threads -1 was taken by `dic`; CLI11's range errors printed a 309-digit bound; a
// mistyped subcommand was "A subcommand is required"; libpng printed its own line before ours and
// a 250 kB PNG claiming 16 000 x 16 000 pixels took 4.3 GB.
TEST(HostileInputs, CliThreadsSubcommandsAndImages) {
  gs::test::ScratchDir dir("hostile_cli");
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  const std::string scenes = std::string(GS_TEST_DATA_DIR) + "/scenes/";
  std::filesystem::copy_file(scenes + "drop_packing.csv", dir / "drop_packing.csv");
  std::string scene = slurp(scenes + "drop.toml");
  scene.replace(scene.find("threads = 1"), 11, "threads = 1000000");
  spit(dir / "drop.toml", scene);
  const auto out = dir / "out";
  struct Case {
    std::string args, err;
  };
  const std::string png = (dir / "big.png").string(), crc = (dir / "crc.png").string();
  // Signature and IHDR only: 16 000 x 16 000, and 64 x 64 with a wrong CRC.
  spit(dir / "big.png",
       std::string(
           "\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x3e\x80\0\0\x3e\x80\x08\0\0\0\0\xde\xad\xbe\xef",
           33));
  spit(dir / "crc.png",
       std::string(
           "\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x40\0\0\0\x40\x08\0\0\0\0\xde\xad\xbe\xef", 33));
  const std::vector<Case> cases = {
      {"simulate " + (dir / "drop.toml").string() + " -o " + out.string(),
       (dir / "drop.toml").string() + ": solver.threads: must be at most 1024 (1000000)"},
      {"simulate " + scenes + "drop.toml -o " + out.string() + " --threads 1000000",
       "--threads: Value 1000000 not in range 1 to 1024"},
      {"simulate " + scenes + "drop.toml -o " + out.string() + " --threads -1",
       "--threads: Value -1 not in range 1 to 1024"},
      {"simulate " + scenes + "drop.toml -o " + out.string() + " --steps -1",
       "--steps: Value -1 not in range 0 to 9223372036854775807"},
      {"dic " + crc + " " + crc + " -o " + (dir / "d.h5").string() + " --threads -1",
       "--threads: Value -1 not in range 0 to 1024"},
      {"frobnicate",
       "unknown subcommand (frobnicate); one of: info, convert, figures, simulate, surface, "
       "render, dic, analyze"},
      {"analyze frob",
       "unknown analyze subcommand (frob); one of: strain, voidcells, rev, shearzone, invariants, "
       "fabric, rose, chains, walls, silo, rotation, interface, hhd, vortices, materials"},
      {"dic " + png + " " + png + " -o " + (dir / "d.h5").string(),
       png + ": image too large (16000 x 16000 pixels, at most 100000000)"},
      {"dic " + crc + " " + crc + " -o " + (dir / "d.h5").string(),
       crc + ": cannot decode image (libpng error: IHDR: CRC error)"},
  };
  for (const auto& c : cases) {
    const auto r = gs::test::run_cli(c.args, log);
    EXPECT_EQ(r.rc, 2) << c.args;
    EXPECT_EQ(r.err, "error: " + c.err + "\n") << c.args;
    EXPECT_EQ(r.out, "");
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(dir / "d.h5"));
  }
}

// Wrong results without a word: two particles at one centre simulated with no contact; strain
// of coordinates scaled by 1e150 or 1e-300 came out as zero gradients, exit 0; an interpreter
// named by GRANOSCOPE_PYTHON that does not exist was passed over for another.
TEST(HostileInputs, CoincidentCentresUnrepresentableScalesAndMissingInterpreter) {
  gs::test::ScratchDir dir("hostile_results");
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  const std::string scenes = std::string(GS_TEST_DATA_DIR) + "/scenes/";
  std::string packing = slurp(scenes + "drop_packing.csv");
  {  // particle 1 moved onto particle 0
    const auto l1 = packing.find('\n') + 1, l2 = packing.find('\n', l1) + 1;
    const auto l3 = packing.find('\n', l2) + 1;
    const std::string row0 = packing.substr(l1, l2 - l1), row1 = packing.substr(l2, l3 - l2);
    const std::string xyz0 = row0.substr(row0.find(','), row0.rfind(',') - row0.find(','));
    const std::string moved = row1.substr(0, row1.find(',')) + xyz0 + row1.substr(row1.rfind(','));
    packing.replace(l2, l3 - l2, moved);
    spit(dir / "drop_packing.csv", packing);
    std::filesystem::copy_file(scenes + "drop.toml", dir / "drop.toml");
    const std::string xyz = xyz0.substr(1);
    std::string shown;
    for (char c : xyz) shown += c == ',' ? std::string(", ") : std::string(1, c);
    const auto r = gs::test::run_cli(
        "simulate " + (dir / "drop.toml").string() + " -o " + (dir / "run").string(), log);
    EXPECT_EQ(r.rc, 2);
    EXPECT_EQ(r.err, "error: " + (dir / "drop.toml").string() +
                         ": particles: particles 0 and 1 have the same centre (" + shown + ")\n");
    EXPECT_FALSE(std::filesystem::exists(dir / "run"));
  }
  for (const double scale : {1e150, 1e-300}) {
    Trajectory t;
    t.frames = {gs::test::random_frame(40, 0, 3, 0.0), gs::test::random_frame(40, 0, 3, 1.0)};
    for (auto& f : t.frames) {
      f.walls.clear();
      f.domain.periodic = false;
      for (auto& p : f.particles) {
        p.position *= scale;
        p.radius *= scale;
      }
      f.domain.lo *= scale;
      f.domain.hi *= scale;
    }
    for (auto& p : t.frames[1].particles) p.position *= 1.01;
    const auto in = dir / "scaled.h5";
    std::filesystem::remove(in);
    write_snapshots(in, t);
    const auto r = gs::test::run_cli(
        "analyze strain " + in.string() + " --from 0 --to 1 -o " + (dir / "st.h5").string(), log);
    EXPECT_EQ(r.rc, 2) << r.err;
    EXPECT_EQ(r.err.rfind("error: " + in.string() +
                              ": particle positions span a length the geometry cannot handle (",
                          0),
              0u)
        << r.err;
    EXPECT_NE(r.err.find(" m; 1e-90 to 1e90)\n"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "st.h5"));
  }
  write_snapshots(dir / "run.h5", [] {
    Trajectory t;
    t.frames = {gs::test::random_frame(5, 0, 1, 0.0)};
    t.frames[0].walls.clear();
    return t;
  }());
  const std::string cmd = "GRANOSCOPE_PYTHON=/nonexistent/python3 " + gs::test::kGranoscope +
                          " figures " + (dir / "run.h5").string() + " -o " +
                          (dir / "figs2").string() + " >" + (log / "o").string() + " 2>" +
                          (log / "e").string();
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_EQ(gs::test::slurp(log / "e"),
            "error: GRANOSCOPE_PYTHON: no such interpreter (/nonexistent/python3)\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "figs2"));
}

// Partial outputs after errors (issue 15): with writes failing as on a full disk (a 4 kB file
// size limit, SIGXFSZ ignored: EFBIG), `convert` to .pvd / .vtu / .h5 and `render` give one line
// and exit 2, and leave nothing under a final name (a .pvd and its _files/ were left, after 89
// lines of VTK's own diagnostics).
TEST(HostileInputs, FailedWritesLeaveNoOutputAndOneLine) {
  gs::test::ScratchDir dir("hostile_full");
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  Trajectory t;
  for (unsigned k = 0; k < 4; ++k) t.frames.push_back(gs::test::random_frame(200, 100, k, k));
  for (auto& f : t.frames) f.walls.clear();
  write_snapshots(dir / "in.h5", t);
  write_snapshots(dir / "packing.h5", read_snapshots(kData / "packing_small.csv"));
  const auto out = dir / "out";
  for (const std::string& args :
       {"convert " + (dir / "in.h5").string() + " " + (out / "x.pvd").string(),
        "convert " + (dir / "in.h5").string() + " " + (out / "x.vtu").string(),
        "convert " + (dir / "in.h5").string() + " " + (out / "x.h5").string(),
        "render " + (dir / "packing.h5").string() + " -o " + (out / "r").string()}) {
    std::filesystem::remove_all(out);
    std::filesystem::create_directories(out);
    const std::string cmd = "bash -c \"trap '' XFSZ; ulimit -f 4; " + gs::test::kGranoscope + " " +
                            args + "\" >" + (log / "o").string() + " 2>" + (log / "e").string();
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << args;
    EXPECT_EQ(WEXITSTATUS(status), 2) << args;
    const std::string err = gs::test::slurp(log / "e");
    EXPECT_EQ(err.rfind("error: " + out.string() + "/", 0), 0u) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_EQ(err.find(".tmp-"), std::string::npos) << err;  // final names, not temporaries
    EXPECT_EQ(err.find(".staging-"), std::string::npos) << err;
    EXPECT_EQ(gs::test::slurp(log / "o"), "");
    std::vector<std::string> left;
    for (const auto& e : std::filesystem::recursive_directory_iterator(out))
      if (!e.is_directory()) left.push_back(e.path().string());
    EXPECT_TRUE(left.empty()) << args << ": " << (left.empty() ? "" : left.front());
  }
}

// Outputs that escape or clobber (issue 15): a scene's output names with a directory part (an
// absolute trajectory path replaced a file anywhere on disk), empty or clashing names (found only
// after the whole run), and an output naming an input, directly or through a link (`analyze rev
// in.h5 -o in.h5` overwrote its input).
TEST(HostileInputs, OutputsStayInTheirDirectoryAndNeverReplaceAnInput) {
  gs::test::ScratchDir dir("hostile_outputs");
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  const std::string scenes = std::string(GS_TEST_DATA_DIR) + "/scenes/";
  std::filesystem::copy_file(scenes + "drop_packing.csv", dir / "drop_packing.csv");
  const std::string scene = slurp(scenes + "drop.toml");
  const auto victim = dir / "victim.h5";
  spit(victim, "precious");
  const std::string out = (dir / "out").string();
  struct Case {
    std::string from, to, err;
  };
  const std::vector<Case> cases = {
      {"trajectory = \"drop.h5\"", "trajectory = \"" + victim.string() + "\"",
       "output.trajectory: must be a file name inside the output directory (no directory part) (" +
           victim.string() + ")"},
      {"trajectory = \"drop.h5\"", "trajectory = \"../victim.h5\"",
       "output.trajectory: must be a file name inside the output directory (no directory part) "
       "(../victim.h5)"},
      {"trajectory = \"drop.h5\"", "trajectory = \"sub/drop.h5\"",
       "output.trajectory: must be a file name inside the output directory (no directory part) "
       "(sub/drop.h5)"},
      {"trajectory = \"drop.h5\"", "trajectory = \"\"", "output.trajectory: must not be empty"},
      {"trajectory = \"drop.h5\"", "trajectory = \"history.csv\"",
       "output.history: names the same file as output.trajectory (history.csv)"},
      {"trajectory = \"drop.h5\"", "trajectory = \"checkpoint.txt\"",
       "(checkpoint index): names the same file as output.trajectory (checkpoint.txt)"},
      {"name = \"drop\"", "name = \"../../evil\"",
       "scene.name: must be a file name inside the output directory (no directory part) "
       "(../../evil)"},
  };
  for (const auto& c : cases) {
    std::string s = scene;
    s.replace(s.find(c.from), c.from.size(), c.to);
    spit(dir / "drop.toml", s);
    const auto r =
        gs::test::run_cli("simulate " + (dir / "drop.toml").string() + " -q -o " + out, log);
    EXPECT_EQ(r.rc, 2) << c.to;
    EXPECT_EQ(r.err, "error: " + (dir / "drop.toml").string() + ": " + c.err + "\n");
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  EXPECT_EQ(slurp(victim), "precious");

  Trajectory t;
  t.frames = {gs::test::random_frame(30, 20, 1, 0.0), gs::test::random_frame(30, 20, 1, 1.0)};
  for (auto& f : t.frames) f.walls.clear();
  const auto in = dir / "in.h5";
  write_snapshots(in, t);
  write_snapshots(dir / "in.vtu", t);
  std::filesystem::create_symlink(in, dir / "alias.h5");
  const std::string before = slurp(in), vtu_before = slurp(dir / "in.vtu");
  const std::vector<std::pair<std::string, std::string>> clobber = {
      {"analyze rev " + in.string() + " -o " + in.string(), in.string()},
      {"convert " + in.string() + " " + (dir / "alias.h5").string(), (dir / "alias.h5").string()},
      {"convert " + (dir / "in.vtu").string() + " " + (dir / "in.vtu").string(),
       (dir / "in.vtp").string()},
  };
  for (const auto& [args, file] : clobber) {
    const auto r = gs::test::run_cli(args, log);
    EXPECT_EQ(r.rc, 2) << args;
    EXPECT_EQ(r.err, "error: " + file + ": output would replace an input\n") << args;
  }
  EXPECT_EQ(slurp(in), before);
  EXPECT_EQ(slurp(dir / "in.vtu"), vtu_before);
}
