// End to end (issue 14): `granoscope simulate` on a tiny clump scene (a stack of four two-sphere
// clumps, seed 003 §2.4, at different angles, on a floor) writes the clump bodies into its
// trajectory, and `granoscope analyze fabric` on it computes the particle-orientation fabric D^p
// (seed 003 §4.3 with eq 20–21) from the bodies, says so, and agrees with the member-based
// computation on the same frame; the same frame without its bodies (imported data) takes the
// member path and gives the same D^p.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "cli_util.hpp"
#include "fabric.hpp"
#include "hdf5_trajectory.hpp"

namespace fs = std::filesystem;
namespace ga = gs::analysis;
using gs::test::read_doubles;
using gs::test::run;

namespace {

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Eigen::Matrix3d matrix(const std::vector<double>& v) {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = v.at(static_cast<std::size_t>(k));
  return m;
}

}  // namespace

TEST(CmdFabricClumps, SimulatedClumpStackUsesTheBodiesAndAgreesWithTheMembers) {
  const auto dir = gs::test::temp_dir("gs_fabric_clumps");
  // Four horizontal dimers (members of radius r at +-0.7 r along the axis) stacked at angles
  // 0, 50, 100, 150 deg about z; each rests on the one below by its closest member pair, with an
  // overlap of 2e-7 m (about the overlap of their weight under g = 100 m/s^2).
  const double r = 1e-3, a = 0.7 * r, overlap = 2e-7, pi = std::numbers::pi;
  std::ostringstream clumps;
  clumps.precision(17);
  clumps << "template,x,y,z,qw,qx,qy,qz\n";
  double z = r - overlap;
  for (int k = 0; k < 4; ++k) {
    const double th = k * 50.0 * pi / 180.0;
    clumps << "dimer,0.01,0.01," << z << "," << std::cos(th / 2) << ",0,0," << std::sin(th / 2)
           << "\n";
    const double h = 2 * a * std::sin(25.0 * pi / 180.0);  // closest members, horizontally
    z += std::sqrt(std::pow(2 * r - overlap, 2) - h * h);
  }
  std::ofstream(dir / "clumps.csv") << clumps.str();
  std::ofstream(dir / "packing.csv")
      << "id,x,y,z,r\n0,0.03,0.03," << r - overlap << "," << r << "\n";
  std::ofstream(dir / "scene.toml") << R"([scene]
name = "clump_stack"
packing = "packing.csv"
[material]
young_Pa = 1.0e7
stiffness_ratio = 0.3
friction_deg = 30.0
density_kg_m3 = 2500.0
[solver]
dt_s = 2.0e-6
damping = 0.4
gravity_m_s2 = [0.0, 0.0, -100.0]
steps = 400
[output]
trajectory = "c.h5"
every = 200
history_every = 200
checkpoint_every = 400
[[walls]]
name = "floor"
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[clump_template]]
name = "dimer"
members = [[-0.0007, 0.0, 0.0, 0.001], [0.0007, 0.0, 0.0, 0.001]]
[clumps]
packing = "clumps.csv"
mass = "union"
)";
  ASSERT_EQ(run("simulate " + (dir / "scene.toml").string() + " -q -o " + (dir / "out").string(),
                dir / "log"),
            0)
      << text_of(dir / "log");
  const auto traj = dir / "out" / "c.h5";
  const gs::Frame last = gs::read_hdf5_trajectory(traj).frames.back();
  EXPECT_EQ(last.step, 400);
  ASSERT_EQ(last.clumps.size(), 4u);
  for (const auto& c : last.clumps) EXPECT_EQ(c.template_name, "dimer");

  ASSERT_EQ(run("info " + traj.string(), dir / "info"), 0);
  EXPECT_NE(text_of(dir / "info").find("clumps:       4 bodies (last frame)"), std::string::npos)
      << text_of(dir / "info");
  ASSERT_EQ(run("analyze fabric " + traj.string() + " -o " + (dir / "f.h5").string(), dir / "log"),
            0)
      << text_of(dir / "log");
  EXPECT_NE(text_of(dir / "log").find("4 clumps (orientation from the clump bodies)"),
            std::string::npos)
      << text_of(dir / "log");
  const Eigen::Matrix3d d_cli = matrix(read_doubles(dir / "f.h5", "/orientation/D"));
  const auto bodies = ga::body_orientation_fabric(last.clumps, 3);
  const auto members = ga::member_orientation_fabric(last);
  ASSERT_EQ(members.bodies, 4u);
  EXPECT_LT((d_cli - bodies.D).norm(), 1e-15) << d_cli;
  EXPECT_LT((d_cli - members.D).norm(), 1e-9) << d_cli << "\n" << members.D;
  // Horizontal axes at 0, 50, 100, 150 deg: Phi_zz = 0, so D^p_zz = -2.5 (to the little they
  // tilted while settling).
  EXPECT_NEAR(d_cli(2, 2), -2.5, 1e-3);

  // Imported data: the same frame with clump_id but no bodies takes the member path.
  gs::Trajectory plain;
  plain.frames = {last};
  plain.frames[0].clumps.clear();
  gs::write_hdf5_trajectory(dir / "plain.h5", plain);
  ASSERT_EQ(run("analyze fabric " + (dir / "plain.h5").string() + " -o " + (dir / "g.h5").string(),
                dir / "log"),
            0)
      << text_of(dir / "log");
  EXPECT_NE(text_of(dir / "log").find("4 clumps (orientation from the clump members)"),
            std::string::npos)
      << text_of(dir / "log");
  const Eigen::Matrix3d d_members = matrix(read_doubles(dir / "g.h5", "/orientation/D"));
  EXPECT_LT((d_members - d_cli).norm(), 1e-9);
  fs::remove_all(dir);
}
