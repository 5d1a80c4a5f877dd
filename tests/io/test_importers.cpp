#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "errors.hpp"
#include "text_parse.hpp"
#include "trajectory_io.hpp"

using namespace gs;

namespace {

const std::filesystem::path kData = GS_TEST_DATA_DIR;

std::map<std::string, long> yade_expected() {
  std::ifstream in(kData / "yade" / "expected.txt");
  std::map<std::string, long> m;
  std::string k;
  long v;
  while (in >> k >> v) m[k] = v;
  return m;
}

}  // namespace

TEST(Importers, YadeLegacySpheresAndInteractionsMatchYadeCounts) {
  const auto expected = yade_expected();
  ASSERT_EQ(expected.at("spheres"), 40);
  const Trajectory t = read_snapshots(kData / "yade" / "yade_export-spheres-00000000.vtk");
  ASSERT_EQ(t.frames.size(), 1u);
  const Frame& f = t.frames[0];
  EXPECT_EQ(static_cast<long>(f.particles.size()), expected.at("spheres"));
  EXPECT_EQ(static_cast<long>(f.contacts.size()), expected.at("real_interactions"));
  long sphere_sphere = 0;
  std::map<std::int64_t, const Particle*> byid;
  for (const auto& p : f.particles) byid[p.id] = &p;
  for (const auto& c : f.contacts) {
    // YADE's normalForce is exerted by id1 on id2 along the id1->id2 normal: compressive.
    EXPECT_GE(c.normal_force.dot(c.normal), 0.0);
    // Legacy files keep 6 significant digits: orthogonal to that precision.
    EXPECT_NEAR(c.shear_force.dot(c.normal), 0.0, 1e-5 * c.shear_force.norm() + 1e-12);
    if (byid.count(c.id1) && byid.count(c.id2)) {
      ++sphere_sphere;
      // Overlap consistent with the centres (legacy files keep 6 significant digits).
      const double d = (byid[c.id2]->position - byid[c.id1]->position).norm();
      EXPECT_NEAR(byid[c.id1]->radius + byid[c.id2]->radius - d, c.overlap, 2e-7);
    }
  }
  EXPECT_EQ(sphere_sphere, expected.at("sphere_sphere_interactions"));
}

TEST(Importers, YadeXmlAndLegacyAgree) {
  const Frame x = read_snapshots(kData / "yade" / "yade_spheres.20000.vtu").frames.at(0);
  const Frame l = read_snapshots(kData / "yade" / "yade_export-spheres-00000000.vtk").frames.at(0);
  ASSERT_EQ(x.particles.size(), 40u);
  std::map<std::int64_t, const Particle*> byid;
  for (const auto& p : l.particles) byid[p.id] = &p;
  for (const auto& p : x.particles) {
    ASSERT_TRUE(byid.count(p.id)) << p.id;
    const Particle& q = *byid[p.id];
    // YADE writes Float32 positions in .vtu and 6 significant digits in legacy .vtk.
    EXPECT_NEAR((p.position - q.position).norm(), 0.0, 1e-7);
    EXPECT_NEAR(p.radius, q.radius, 1e-8);
    EXPECT_EQ(p.clump_id, -1);
  }
}

TEST(Importers, LiggghtsAtomsAndPairsMatchTheDump) {
  const Trajectory t = read_snapshots(kData / "liggghts" / "dump.atoms");
  ASSERT_EQ(t.frames.size(), 2u);
  EXPECT_EQ(t.frames[0].step, 10000);
  EXPECT_EQ(t.frames[1].step, 20000);
  // Counts as the dump headers state them (NUMBER OF ATOMS / NUMBER OF ENTRIES).
  EXPECT_EQ(t.frames[0].particles.size(), 60u);
  EXPECT_EQ(t.frames[1].particles.size(), 60u);
  EXPECT_EQ(t.frames[0].contacts.size(), 11u);
  EXPECT_EQ(t.frames[1].contacts.size(), 54u);
  // First atom row of the first frame, as written in the file.
  const Particle& p = t.frames[0].particles[0];
  EXPECT_EQ(p.id, 24);
  EXPECT_EQ(p.position, Eigen::Vector3d(0.0103262, 0.00334231, 0.00396832));
  EXPECT_EQ(p.velocity, Eigen::Vector3d(-0.135135, 0.0437695, -0.0408926));
  EXPECT_EQ(p.angular_velocity, Eigen::Vector3d(13.4987, 33.4149, -9.11373));
  EXPECT_EQ(p.radius, 0.003);
  EXPECT_EQ(p.mass, 0.000294053);
  for (const auto& f : t.frames)
    for (const auto& c : f.contacts) EXPECT_GT(c.overlap, 0.0);
  // Sign convention: for an atom clear of the walls, the dumped total force (fx, fy, fz) is
  // gravity plus the sum of its pair forces as imported (force by id1 on id2; id1 receives the
  // opposite). In this fixture 18 of the 24 free atoms balance to 1e-4 N (the dump keeps 6
  // digits); the other 6 are off by 1e-3..7e-3 N, which we read as LIGGGHTS's local dump not
  // listing every pair that contributed to f (left alone). The reversed convention balances
  // none of them, so the check discriminates.
  const Frame& f = t.frames[1];
  std::map<std::int64_t, Eigen::Vector3d> ours, reversed;
  for (const auto& p : f.particles)
    ours[p.id] = reversed[p.id] = Eigen::Vector3d(0, 0, -9.81 * p.mass);
  for (const auto& c : f.contacts) {
    const Eigen::Vector3d on2 = c.normal_force + c.shear_force;
    ours[c.id1] -= on2;
    ours[c.id2] += on2;
    reversed[c.id1] += on2;
    reversed[c.id2] -= on2;
  }
  const std::string text = text::read_text_file(kData / "liggghts" / "dump.atoms");
  const auto lines = text::split_lines(text);
  std::size_t first = 0;  // rows of the second frame: after the second "ITEM: ATOMS" line
  for (std::size_t i = 0, seen = 0; i < lines.size(); ++i)
    if (lines[i].rfind("ITEM: ATOMS", 0) == 0 && ++seen == 2) first = i + 1;
  ASSERT_GT(first, 0u);
  int checked = 0, balanced = 0, balanced_reversed = 0;
  for (std::size_t i = first; i < first + 60; ++i) {
    const auto tok = text::split_ws(lines[i]);
    const auto id = text::to_int(tok[0], "dump", i, "id");
    const Eigen::Vector3d x(text::to_double(tok[2], "dump", i, "x"),
                            text::to_double(tok[3], "dump", i, "y"),
                            text::to_double(tok[4], "dump", i, "z"));
    const double r = text::to_double(tok[14], "dump", i, "radius");
    const double gap = std::min({x.x(), 0.04 - x.x(), x.y(), 0.04 - x.y(), x.z()}) - r;
    if (gap < 1e-5) continue;  // touching (or about to touch) a wall: wall forces are not dumped
    const Eigen::Vector3d dumped(text::to_double(tok[8], "dump", i, "fx"),
                                 text::to_double(tok[9], "dump", i, "fy"),
                                 text::to_double(tok[10], "dump", i, "fz"));
    ++checked;
    balanced += (ours[id] - dumped).norm() < 1e-4;
    balanced_reversed += (reversed[id] - dumped).norm() < 1e-4;
  }
  EXPECT_EQ(checked, 24);
  EXPECT_EQ(balanced, 18);
  EXPECT_EQ(balanced_reversed, 2);  // the two atoms with no pair at all (gravity only)
  // With a time step, times follow the steps.
  ImportOptions o;
  o.liggghts.dt = 1e-5;
  EXPECT_DOUBLE_EQ(read_snapshots(kData / "liggghts" / "dump.atoms", o).frames[1].time, 0.2);
}

TEST(Importers, PackingCsvFixture) {
  const Frame f = read_snapshots(kData / "packing_small.csv").frames.at(0);
  ASSERT_EQ(f.particles.size(), 8u);
  EXPECT_EQ(f.particles[7].radius, 0.0015);
  EXPECT_NEAR((f.domain.hi - Eigen::Vector3d(0.0045, 0.0045, 0.005)).norm(), 0.0, 1e-15);
}

// A packing CSV may carry velocities (vx, vy, vz: all three or none).
TEST(Importers, PackingCsvVelocities) {
  const auto dir = std::filesystem::temp_directory_path() / ("gs_pv_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "a.csv")
      << "id,x,y,z,r,vz,vx,vy\n0,0,0,0,0.001,-5,1,2.5\n1,0.01,0,0,0.001,0,0,0\n";
  const Frame f = read_snapshots(dir / "a.csv").frames.at(0);
  EXPECT_EQ(f.particles[0].velocity, Eigen::Vector3d(1, 2.5, -5));
  EXPECT_EQ(f.particles[1].velocity, Eigen::Vector3d::Zero());
  std::ofstream(dir / "b.csv") << "id,x,y,z,r,vx\n0,0,0,0,0.001,1\n";
  try {
    (void)read_snapshots(dir / "b.csv");
    ADD_FAILURE() << "accepted vx alone";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("give vx, vy and vz, or none"), std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

// DEM8 particle text (Radius[m] PosX[m] PosY[m] PosZ[m], whitespace, CRLF): detected by content,
// ids in file order; `max_particles` stops before a trailing row that is not a particle, which
// is otherwise refused with its line.
TEST(Importers, Dem8ParticleText) {
  const auto dir = std::filesystem::temp_directory_path() / ("gs_pt_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string text =
      "Radius[m]\tPosX[m] PosY[m] PosZ[m]\r\n 0.001 0.1 0.2 0.3\r\n 0.002\t-0.1 0 1e-3\r\n"
      " 5 0.01 0.01 0 0 0.06\r\n\r\n";
  std::ofstream(dir / "bed.txt") << text;
  ImportOptions o;
  o.max_particles = 2;
  const Frame f = read_snapshots(dir / "bed.txt", o).frames.at(0);
  ASSERT_EQ(f.particles.size(), 2u);
  EXPECT_EQ(f.particles[1].id, 1);
  EXPECT_EQ(f.particles[1].radius, 0.002);
  EXPECT_EQ(f.particles[1].position, Eigen::Vector3d(-0.1, 0, 1e-3));
  EXPECT_EQ(f.particles[0].position, Eigen::Vector3d(0.1, 0.2, 0.3));
  try {
    (void)read_snapshots(dir / "bed.txt");
    ADD_FAILURE() << "accepted the 6-field row";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              (dir / "bed.txt").string() + ": line 4: expected 4 fields (6)");
  }
  std::ofstream(dir / "nohead.txt") << "Radius[m] PosX[m] PosY[m]\n0.001 0 0\n";
  try {
    (void)read_snapshots(dir / "nohead.txt");
    ADD_FAILURE() << "accepted a header without PosZ";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing column in header (PosZ)"), std::string::npos);
  }
  const auto shared = std::filesystem::path(GS_SOURCE_DIR) / ".." / "shared" / "dem8";
  if (std::filesystem::exists(shared / "case3_penetration" / "25KParticles.txt")) {
    o.max_particles = 25000;
    const Frame bed =
        read_snapshots(shared / "case3_penetration" / "25KParticles.txt", o).frames.at(0);
    EXPECT_EQ(bed.particles.size(), 25000u);
    for (const auto& p : bed.particles) EXPECT_EQ(p.radius, 0.001);
  }
  std::filesystem::remove_all(dir);
  if (!std::filesystem::exists(shared / "case3_penetration" / "25KParticles.txt"))
    GTEST_SKIP() << "the benchmark's own bed file: ../shared/dem8 absent (the rest ran)";
}

TEST(TextParse, StrictNumbers) {
  EXPECT_EQ(text::to_double("1.5e-3", "f", 1, "x"), 1.5e-3);
  EXPECT_EQ(text::to_double("+2", "f", 1, "x"), 2.0);
  EXPECT_THROW(text::to_double("1.5x", "f", 1, "x"), InputError);
  EXPECT_THROW(text::to_double("", "f", 1, "x"), InputError);
  EXPECT_EQ(text::to_int("42", "f", 1, "id"), 42);
  EXPECT_EQ(text::to_int("42.0", "f", 1, "id"), 42);
  EXPECT_THROW(text::to_int("4.5", "f", 1, "id"), InputError);
}
