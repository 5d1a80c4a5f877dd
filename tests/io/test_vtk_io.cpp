#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkStringArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <fstream>

#include "../apps/cli_util.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "test_util.hpp"
#include "trajectory_io.hpp"
#include "vtk_io.hpp"

using namespace gs;
using gs::test::random_frame;
using gs::test::ScratchDir;

TEST(VtkIo, ParticlesAndContactsRoundTripThroughVtkReaders) {
  ScratchDir dir("vtk");
  const Frame f = random_frame(40, 25, 4);
  write_vtu_particles(dir / "p.vtu", f);
  write_vtp_contacts(dir / "p.vtp", f);
  Frame r = read_vtu_particles(dir / "p.vtu");
  read_vtp_contacts(dir / "p.vtp", r);
  gs::test::expect_same_frame(f, r, /*with_walls=*/false);
}

TEST(VtkIo, Hdf5ToVtuToHdf5IsExact) {
  ScratchDir dir("vtk_h5");
  Trajectory t;
  t.metadata.provenance = "test";
  t.frames = {random_frame(33, 10, 5)};
  t.frames[0].walls.clear();  // walls are not part of the ParaView particle output
  write_snapshots(dir / "a.h5", t);
  write_snapshots(dir / "b.vtu", read_snapshots(dir / "a.h5"));
  write_snapshots(dir / "c.h5", read_snapshots(dir / "b.vtu"));  // .vtp picked up beside .vtu
  const Trajectory back = read_snapshots(dir / "c.h5");
  ASSERT_EQ(back.frames.size(), 1u);
  gs::test::expect_same_frame(t.frames[0], back.frames[0]);
}

TEST(VtkIo, PvdSeriesRoundTrip) {
  ScratchDir dir("pvd");
  Trajectory t;
  t.frames = {random_frame(10, 4, 1, 0.0), random_frame(12, 5, 2, 0.5), random_frame(8, 0, 3, 1.5)};
  for (auto& f : t.frames) f.walls.clear();
  write_snapshots(dir / "run.pvd", t);
  EXPECT_TRUE(std::filesystem::exists(dir / "run_contacts.pvd"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "run_files"));
  const Trajectory r = read_snapshots(dir / "run.pvd");
  ASSERT_EQ(r.frames.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) gs::test::expect_same_frame(t.frames[i], r.frames[i]);
  // Nothing left under temporary names.
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(VtkIo, PackingCsvRoundTripIsExact) {
  ScratchDir dir("csv");
  Trajectory t;
  t.frames = {random_frame(25, 0, 6)};
  write_snapshots(dir / "p.csv", t);
  const Frame r = read_snapshots(dir / "p.csv").frames.at(0);
  ASSERT_EQ(r.particles.size(), 25u);
  for (std::size_t i = 0; i < 25; ++i) {
    EXPECT_EQ(r.particles[i].id, t.frames[0].particles[i].id);
    EXPECT_EQ(r.particles[i].position, t.frames[0].particles[i].position);
    EXPECT_EQ(r.particles[i].radius, t.frames[0].particles[i].radius);
  }
}

// Clump bodies go to `<stem>_clumps.vtu` beside the particles (as the contacts go to the .vtp):
// exact round trip of every field; axis_1..3 are the columns of the orientation's rotation
// matrix (unit), the template index names the field-data template_names; a frame without bodies
// removes a stale clumps file instead of leaving it to be read back with the wrong frame.
TEST(VtkIo, ClumpBodiesRoundTripBesideTheParticlesWithTheirPrincipalAxes) {
  ScratchDir dir("vtk_clumps");
  Trajectory t;
  t.frames = {gs::test::with_clump_bodies(random_frame(40, 25, 4), 4)};
  t.frames[0].walls.clear();
  ASSERT_EQ(t.frames[0].clumps.size(), 10u);
  write_snapshots(dir / "p.vtu", t);
  ASSERT_TRUE(std::filesystem::exists(dir / "p_clumps.vtu"));
  gs::test::expect_same_frame(t.frames[0], read_snapshots(dir / "p.vtu").frames.at(0));

  vtkNew<vtkXMLUnstructuredGridReader> r;
  r->SetFileName((dir / "p_clumps.vtu").c_str());
  r->Update();
  vtkUnstructuredGrid* g = r->GetOutput();
  ASSERT_EQ(g->GetNumberOfPoints(), 10);
  auto* names = vtkStringArray::SafeDownCast(g->GetFieldData()->GetAbstractArray("template_names"));
  ASSERT_NE(names, nullptr);
  vtkDataArray* tpl = g->GetPointData()->GetArray("template");
  ASSERT_NE(tpl, nullptr);
  for (vtkIdType i = 0; i < 10; ++i) {
    const auto& c = t.frames[0].clumps[static_cast<std::size_t>(i)];
    const Eigen::Matrix3d rot = c.orientation.toRotationMatrix();
    for (int k = 0; k < 3; ++k) {
      vtkDataArray* a = g->GetPointData()->GetArray(("axis_" + std::to_string(k + 1)).c_str());
      ASSERT_NE(a, nullptr);
      double v[3];
      a->GetTuple(i, v);
      const Eigen::Vector3d axis(v[0], v[1], v[2]);
      EXPECT_LT((axis - rot.col(k)).norm(), 1e-14) << i << " axis " << k;
      EXPECT_NEAR(axis.norm(), 1.0, 1e-14);
    }
    const auto k = static_cast<vtkIdType>(tpl->GetComponent(i, 0));
    EXPECT_EQ(names->GetValue(k), c.template_name);
  }

  Trajectory plain;
  plain.frames = {random_frame(10, 3, 2)};
  plain.frames[0].walls.clear();
  write_snapshots(dir / "p.vtu", plain);
  EXPECT_FALSE(std::filesystem::exists(dir / "p_clumps.vtu"));
  EXPECT_TRUE(read_snapshots(dir / "p.vtu").frames.at(0).clumps.empty());
}

// `granoscope convert` carries the bodies HDF5 -> .pvd (`<stem>_clumps.pvd`) -> HDF5, exactly;
// a frame of the series without bodies has an empty clumps file.
TEST(VtkIo, ConvertCarriesClumpBodiesThroughPvdSeries) {
  ScratchDir dir("pvd_clumps");
  Trajectory t;
  t.metadata.provenance = "test";
  t.frames = {gs::test::with_clump_bodies(random_frame(10, 4, 1, 0.0), 1),
              random_frame(12, 5, 2, 0.5),
              gs::test::with_clump_bodies(random_frame(8, 0, 3, 1.5), 3)};
  for (auto& f : t.frames) f.walls.clear();
  write_snapshots(dir / "a.h5", t);
  const auto log = dir / "log";
  std::filesystem::create_directories(log);
  auto r = gs::test::run_cli(
      "convert " + (dir / "a.h5").string() + " " + (dir / "run.pvd").string(), log);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "run_clumps.pvd"));
  r = gs::test::run_cli("convert " + (dir / "run.pvd").string() + " " + (dir / "b.h5").string(),
                        log);
  ASSERT_EQ(r.rc, 0) << r.err;
  const Trajectory back = read_snapshots(dir / "b.h5");
  ASSERT_EQ(back.frames.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) gs::test::expect_same_frame(t.frames[i], back.frames[i]);
  // Written again without bodies: the stale clump series goes.
  Trajectory plain;
  plain.frames = {random_frame(10, 4, 1)};
  plain.frames[0].walls.clear();
  write_snapshots(dir / "run.pvd", plain);
  EXPECT_FALSE(std::filesystem::exists(dir / "run_clumps.pvd"));
  EXPECT_TRUE(read_snapshots(dir / "run.pvd").frames.at(0).clumps.empty());
}
