#include <gtest/gtest.h>

#include <fstream>

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
