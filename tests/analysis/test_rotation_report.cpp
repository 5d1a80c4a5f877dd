// Seed 003's rotation measures (analysis/rotation_report.hpp) against exact answers: strain
// increments of a known direction, magnitude and volume change give back α^R_Δε, the
// non-coaxiality, (Δε)^R_v and (Δε)^R_q (also where the direction passes 45° and wraps); the
// contact fabric of normals along one direction has that direction as α_F, wall contacts and
// a clump's own members left out; cycles end where they should; a curve that is not a rotation
// run's is rejected naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "errors.hpp"
#include "rotation_report.hpp"

namespace ga = gs::analysis;

namespace {

constexpr double kRad = std::numbers::pi / 180.0;

// The strain increment per radian of α with major value l1 along (sin θ, 0, cos θ), minor l3
// along (cos θ, 0, −sin θ) and lyy along y.
Eigen::Matrix3d increment(double theta_deg, double l1, double l3, double lyy) {
  const double t = theta_deg * kRad;
  const Eigen::Vector3d u(std::sin(t), 0, std::cos(t)), w(std::cos(t), 0, -std::sin(t));
  return l1 * u * u.transpose() + l3 * w * w.transpose() +
         lyy * Eigen::Vector3d::UnitY() * Eigen::Vector3d::UnitY().transpose();
}

// Rows every 1° from 0 to `end`; over each 3° window the increment's major direction is 35°
// ahead of the window's middle α.
std::vector<ga::RotationState> rows(double end) {
  std::vector<ga::RotationState> r;
  Eigen::Matrix3d eps = Eigen::Matrix3d::Identity() * 0.01;  // (counted from the start)
  for (int a = 0; a <= static_cast<int>(end); ++a) {
    if (a > 0) {
      const int w = (a - 1) / 3;
      eps += increment(3.0 * w + 1.5 + 35.0, 0.01, -0.004, 0.002) * (1.0 * kRad);
    }
    ga::RotationState s;
    s.step = 1000 + a;
    s.stage = 4;
    s.alpha_deg = a;
    s.p = 5e5;
    s.eps = eps;
    s.eps_v = eps.trace();
    r.push_back(s);
  }
  return r;
}

}  // namespace

TEST(RotationReport, StrainIncrementsGiveDirectionAndNonCoaxiality) {
  const auto r = ga::rotation_rows(rows(360), "curve.csv");
  EXPECT_EQ(r.front().eps.norm(), 0.0);  // counted from the rotation's start
  const auto inc = ga::strain_increments(r, 3.0);
  ASSERT_EQ(inc.size(), 120u);
  for (const auto& s : inc) {
    EXPECT_NEAR(s.non_coaxiality_deg, 35.0, 1e-9) << s.alpha_deg;
    EXPECT_NEAR(s.alpha_d_eps_deg, ga::fold_axis_deg(s.alpha_deg + 35.0), 1e-9);
    EXPECT_NEAR(s.d_eps_v_R, 0.01 - 0.004, 1e-12);
    EXPECT_NEAR(s.d_eps_q_R, 0.5 * (0.01 + 0.004), 1e-12);
    EXPECT_NEAR(s.d_eps_yy_R, 0.002, 1e-12);
  }
  // Past 45° (θ = 96.5° at α = 61.5°) the paper's atan loses the quadrant; atan2 does not.
  EXPECT_NEAR(inc[20].alpha_deg, 61.5, 1e-12);
  EXPECT_NEAR(inc[20].alpha_d_eps_deg, -83.5, 1e-9);
  const auto cycles = ga::cycle_summaries(r, inc, {});
  ASSERT_EQ(cycles.size(), 2u);
  EXPECT_NEAR(cycles[0].non_coaxiality_deg, 35.0, 1e-9);
  EXPECT_NEAR(cycles[0].eps_v, r[180].eps_v, 1e-15);
  EXPECT_NEAR(cycles[1].eps_v, r[360].eps_v, 1e-15);
  EXPECT_NEAR(cycles[1].eps_yy, 0.002 * 2 * std::numbers::pi, 1e-12);
  EXPECT_THROW(ga::strain_increments(r, 0.0), std::invalid_argument);
}

TEST(RotationReport, FabricDirectionFromTheContactsBetweenBodies) {
  // Two dimers (clumps 10, 11) and a free sphere (5); contacts between bodies along 20° from z
  // in the x-z plane (either sign), one between the members of a clump and one with a wall
  // (id 99) along x, which must not count.
  gs::Frame f;
  f.step = 7;
  for (const auto& [id, clump] :
       {std::pair{1, 10}, std::pair{2, 10}, std::pair{3, 11}, std::pair{4, 11}, std::pair{5, -1}}) {
    gs::Particle p;
    p.id = id;
    p.radius = 1e-3;
    p.clump_id = clump;
    p.position = Eigen::Vector3d(id * 1e-3, 0, 0);
    f.particles.push_back(p);
  }
  const double t = 20 * kRad;
  const Eigen::Vector3d n(std::sin(t), 0, std::cos(t));
  auto contact = [&](int a, int b, const Eigen::Vector3d& dir) {
    gs::Contact c;
    c.id1 = a;
    c.id2 = b;
    c.normal = dir;
    f.contacts.push_back(c);
  };
  contact(2, 3, n);
  contact(4, 5, -n);
  contact(1, 5, n);
  contact(1, 2, Eigen::Vector3d::UnitX());   // members of clump 10
  contact(99, 3, Eigen::Vector3d::UnitX());  // a wall
  const auto s = ga::rotation_fabric(f, 50.0, "run.h5");
  EXPECT_EQ(s.contacts.contacts, 3u);
  EXPECT_EQ(s.contacts.particles, 3u);  // two clumps and a sphere
  EXPECT_NEAR(s.alpha_F_deg, 20.0, 1e-9);
  EXPECT_NEAR(s.alpha_minus_F_deg, 30.0, 1e-9);
  // All normals along n: M/ω = n nᵀ, D = 15/2 (n nᵀ − 1/3).
  const Eigen::Matrix3d D = 7.5 * (n * n.transpose() - Eigen::Matrix3d::Identity() / 3.0);
  EXPECT_NEAR((s.contacts.D - D).norm(), 0.0, 1e-12);
  gs::Frame empty = f;
  empty.contacts.resize(3);
  empty.contacts.erase(empty.contacts.begin(), empty.contacts.begin() + 3);
  EXPECT_THROW(ga::rotation_fabric(empty, 0.0, "run.h5"), gs::InputError);
}

TEST(RotationReport, RejectsACurveThatIsNotARotationRun) {
  const auto p = std::filesystem::temp_directory_path() / "gs_rotation_curve.csv";
  std::ofstream(p) << "step,time_s,axial_strain\n0,0,0\n";
  try {
    ga::read_rotation_curve(p);
    ADD_FAILURE() << "accepted";
  } catch (const gs::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing column (stage)"), std::string::npos) << e.what();
  }
  std::filesystem::remove(p);
  std::vector<ga::RotationState> none(3);
  EXPECT_THROW(ga::rotation_rows(none, "curve.csv"), gs::InputError);
}
