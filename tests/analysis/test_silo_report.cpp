// The silo report (seed 004 §5.3.1) on a hand-built snapshot: saw-tooth faces and planes told
// apart by their normals, P, T, N, φ_w and the balance from the walls' forces, and the stress
// profiles from the wall contacts binned by height, against the sums done by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "silo_report.hpp"

using namespace gs;

namespace {

Wall wall(std::int64_t id, WallKind kind, Eigen::Vector3d a, Eigen::Vector3d b,
          Eigen::Vector3d force) {
  Wall w;
  w.id = id;
  w.kind = kind;
  w.a = a;
  w.b = b;
  w.force = force;
  return w;
}

Contact on_wall(std::int64_t wall, std::int64_t particle, Eigen::Vector3d point,
                Eigen::Vector3d force_on_wall) {
  Contact c;  // YADE's convention: the forces of id1 (the wall) on id2 (the particle)
  c.id1 = wall;
  c.id2 = particle;
  c.point = point;
  c.normal_force = -0.25 * force_on_wall;
  c.shear_force = -0.75 * force_on_wall;
  return c;
}

/// A silo 0.1 m wide (x), 0.01 m deep (y): a rising and a falling tooth face and a land on the
/// left, a plane on the right, a bottom box with its top at z = 0, front and back planes.
Frame silo() {
  Frame f;
  const double s = std::sqrt(0.5);
  f.walls = {
      wall(10, WallKind::Facet, {0.001, 0.005, 0.02}, {s, 0, s}, {-1.0, 0, -0.5}),
      wall(11, WallKind::Facet, {0.001, 0.005, 0.03}, {s, 0, -s}, {-2.0, 0, -0.25}),
      wall(12, WallKind::Facet, {0.0, 0.005, 0.04}, {1, 0, 0}, {-0.5, 0, 0.0}),
      wall(13, WallKind::Plane, {0.1, 0, 0}, {-1, 0, 0}, {3.0, 0, -1.0}),
      wall(14, WallKind::Box, {0.05, 0.005, -0.01}, {0.06, 0.01, 0.01}, {0.1, 0, -4.0}),
      wall(15, WallKind::Plane, {0, 0, 0}, {0, 1, 0}, {0, -7.0, 0}),
      wall(16, WallKind::Plane, {0, 0.01, 0}, {0, -1, 0}, {0, 7.0, 0}),
  };
  for (int i = 0; i < 3; ++i) {
    Particle p;
    p.id = i;
    p.position = Eigen::Vector3d(0.02 + 0.03 * i, 0.005, i == 2 ? -0.001 : 0.01);
    p.radius = 0.005;
    p.mass = 0.1 * (i + 1);
    f.particles.push_back(p);
  }
  f.contacts = {on_wall(10, 0, {0.001, 0.005, 0.004}, {-1.0, 0, -0.5}),
                on_wall(11, 0, {0.001, 0.005, 0.006}, {-2.0, 0, -0.25}),
                on_wall(13, 1, {0.1, 0.005, 0.012}, {3.0, 0, -1.0})};
  return f;
}

}  // namespace

TEST(SiloReport, ForcesAndProfilesByHand) {
  analysis::SiloReportOptions o;
  o.bin = 0.005;
  const auto r = analysis::silo_report(silo(), o);
  EXPECT_EQ(r.side_walls_left, 3u);  // two tooth faces and a land
  EXPECT_EQ(r.side_walls_right, 1u);
  EXPECT_EQ(r.bottom_walls, 1u);  // (the front and back planes are neither)
  EXPECT_DOUBLE_EQ(r.bottom_level, 0.0);
  // G: the two particles above z = 0 (the third sits below the bottom's top).
  EXPECT_DOUBLE_EQ(r.G, (0.1 + 0.2) * 9.81);
  EXPECT_DOUBLE_EQ(r.P, 4.0);
  EXPECT_DOUBLE_EQ(r.T_left, 0.5 + 0.25 + 0.0);
  EXPECT_DOUBLE_EQ(r.N_left, 1.0 + 2.0 + 0.5);
  EXPECT_DOUBLE_EQ(r.T_right, 1.0);
  EXPECT_DOUBLE_EQ(r.N_right, 3.0);
  EXPECT_DOUBLE_EQ(r.phi_left_deg, std::atan2(0.75, 3.5) * 180 / M_PI);
  EXPECT_DOUBLE_EQ(r.balance, (4.0 + 0.75 + 1.0) / r.G);
  // Profiles: bins of 5 mm from z = 0 up to the highest particle top (15 mm): 3 bins; depth =
  // the particles' extent across y (0.01 m).
  ASSERT_EQ(r.profile.height.size(), 3u);
  const double area = 0.005 * 0.01;
  EXPECT_DOUBLE_EQ(r.profile.sigma11_left[0], 1.0 / area);
  EXPECT_DOUBLE_EQ(r.profile.sigma21_left[0], 0.5 / area);
  EXPECT_DOUBLE_EQ(r.profile.sigma11_left[1], 2.0 / area);
  EXPECT_DOUBLE_EQ(r.profile.sigma21_left[1], 0.25 / area);
  EXPECT_DOUBLE_EQ(r.profile.sigma11_right[2], 3.0 / area);
  EXPECT_DOUBLE_EQ(r.profile.sigma21_right[2], 1.0 / area);
  EXPECT_EQ(r.profile.contacts_left[0] + r.profile.contacts_left[1], 2.0);
  EXPECT_EQ(r.profile.sigma11_right[0], 0.0);
}

TEST(SiloReport, RefusesWhatIsNoSilo) {
  analysis::SiloReportOptions o;
  o.bin = 0.005;
  Frame f = silo();
  f.walls.erase(f.walls.begin() + 3);  // no right wall
  EXPECT_THROW(analysis::silo_report(f, o), std::invalid_argument);
  f = silo();
  f.contacts.clear();  // wall forces without contacts: no profiles to be had
  try {
    analysis::silo_report(f, o);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no wall contact"), std::string::npos) << e.what();
  }
  o.bin = 0;
  EXPECT_THROW(analysis::silo_report(silo(), o), std::invalid_argument);
  o.bin = 0.005;
  o.across = Eigen::Vector3d(1, 0, 1);
  EXPECT_THROW(analysis::silo_report(silo(), o), std::invalid_argument);
}

// The wall zones: rotations across a 20 mm silo falling off from each wall as a logistic
// 1/(1 + exp((x − 5 mm)/1 mm)) (and its mirror from the right wall), one particle per 1 mm bin at
// mid-height: the inflection point, hence each zone's thickness, is at 5 mm (a logistic is
// point-symmetric about it, and so is its smoothing).
TEST(SiloReport, WallZoneThicknessAtTheInflectionOfTheRotationProfile) {
  Frame f;
  f.walls = {wall(100, WallKind::Plane, {0, 0, 0}, {1, 0, 0}, {0, 0, 0}),
             wall(101, WallKind::Plane, {0.02, 0, 0}, {-1, 0, 0}, {0, 0, 0}),
             wall(102, WallKind::Plane, {0, 0, 0}, {0, 0, 1}, {0, 0, 0})};
  auto logistic = [](double x) { return 1 / (1 + std::exp((x - 0.005) / 0.001)); };
  for (int b = 0; b < 20; ++b) {
    Particle p;
    p.id = b;
    p.radius = 4e-4;
    p.mass = 1e-6;
    const double x = (b + 0.5) * 1e-3;
    p.position = Eigen::Vector3d(x, 0.002, 0.01);
    // (the sign of the rotation does not matter: the profile is of |rotation about y|)
    p.rotation = Eigen::Vector3d(0.3, (b % 2 ? -1 : 1) * (logistic(x) + logistic(0.02 - x)), 0);
    f.particles.push_back(p);
  }
  analysis::SiloReportOptions o;
  o.bin = 0.005;
  o.zone_bin = 0.001;
  o.zone_band = 0.002;
  o.zone_height = 0.01;
  const auto r = analysis::silo_report(f, o);
  ASSERT_EQ(r.zone_across.size(), 20u);
  // (the other wall's tail, e^-10 of the peak at 5 mm, breaks the symmetry by 1e-3 of a bin)
  EXPECT_NEAR(r.zone_left, 0.005, 2e-6);
  EXPECT_NEAR(r.zone_right, 0.005, 2e-6);
  EXPECT_EQ(r.zone_left, r.zone_right);  // (the two walls' profiles mirror each other)
  // Out of the band: no particle, a flat profile, no zone.
  o.zone_height = 0.02;
  const auto none = analysis::silo_report(f, o);
  EXPECT_TRUE(std::isnan(none.zone_left));
}
