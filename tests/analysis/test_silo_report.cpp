// The silo report (seed 004 §5.3.1) on a hand-built snapshot: saw-tooth faces and planes told
// apart by their normals, P, T, N, φ_w and the balance from the walls' forces, and the stress
// profiles from the wall contacts binned by height, against the sums done by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>

#include "silo_report.hpp"
#include "silo_theory.hpp"

using namespace gs;
using namespace gs::analysis;

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

// A silo `bins` mm wide between two plane walls, on a bottom plane, with one particle per 1 mm
// bin at mid-height (z = 10 mm) whose rotation about the depth axis y is rotation(x) (x in m; the
// x component, 0.3, is not the profile's), and the options that profile it in those bins.
Frame zone_silo(int bins, const std::function<double(double)>& rotation) {
  Frame f;
  f.walls = {wall(100, WallKind::Plane, {0, 0, 0}, {1, 0, 0}, {0, 0, 0}),
             wall(101, WallKind::Plane, {bins * 1e-3, 0, 0}, {-1, 0, 0}, {0, 0, 0}),
             wall(102, WallKind::Plane, {0, 0, 0}, {0, 0, 1}, {0, 0, 0})};
  for (int b = 0; b < bins; ++b) {
    Particle p;
    p.id = b;
    p.radius = 4e-4;
    p.mass = 1e-6;
    const double x = (b + 0.5) * 1e-3;
    p.position = Eigen::Vector3d(x, 0.002, 0.01);
    p.rotation = Eigen::Vector3d(0.3, rotation(x), 0);
    f.particles.push_back(p);
  }
  return f;
}

analysis::SiloReportOptions zone_options() {
  analysis::SiloReportOptions o;
  o.bin = 0.005;
  o.zone_bin = 0.001;
  o.zone_band = 0.002;
  o.zone_height = 0.01;
  return o;
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
  auto logistic = [](double x) { return 1 / (1 + std::exp((x - 0.005) / 0.001)); };
  // (the sign of the rotation does not matter: the profile is of |rotation about y|)
  const Frame f = zone_silo(20, [&](double x) {
    const int b = static_cast<int>(x / 1e-3);
    return (b % 2 ? -1 : 1) * (logistic(x) + logistic(0.02 - x));
  });
  analysis::SiloReportOptions o = zone_options();
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

// The wall zones' extent: a step profile of |rotation| across a 40 mm silo, 1 rad out to 6 mm
// from the left wall and to 10 mm from the right one, 0.1 rad in between, one particle per 1 mm
// bin. Smoothed by [1 2 1]/4 the left step reads 1, …, 1 (bin 4), 0.775 (bin 5), 0.325 (bin 6),
// 0.1: the core (the median of the middle third) is 0.1, and twice it, 0.2, is crossed between
// the centres of bins 6 and 7, at 6.5 + (0.325 − 0.2)/(0.325 − 0.1) mm; the right one mirrors it
// 4 mm further in. The inflection method meanwhile finds the step's edge (6 and 10 mm).
TEST(SiloReport, WallZoneExtentWhereTheRotationFallsToTwiceTheCore) {
  const Frame f = zone_silo(40, [](double x) { return (x < 0.006 || x > 0.03) ? -1.0 : 0.1; });
  analysis::SiloReportOptions o = zone_options();
  const auto r = analysis::silo_report(f, o);
  ASSERT_EQ(r.zone_across.size(), 40u);
  EXPECT_DOUBLE_EQ(r.zone_core, 0.1);
  const double cross = (6.5 + 0.125 / 0.225) * 1e-3;
  EXPECT_NEAR(r.zone_extent_left, cross, 1e-15);
  EXPECT_NEAR(r.zone_extent_right, cross + 0.004, 1e-15);
  EXPECT_NEAR(r.zone_left, 0.006, 1e-15);
  EXPECT_NEAR(r.zone_right, 0.010, 1e-15);
  // Three times the core, 0.3, is crossed just past bin 6's centre; a factor that leaves the
  // peak below its level finds no extent; a factor of 1 or less is refused.
  o.zone_extent_factor = 3;
  EXPECT_NEAR(analysis::silo_report(f, o).zone_extent_left, (6.5 + 0.025 / 0.225) * 1e-3, 1e-15);
  o.zone_extent_factor = 20;
  EXPECT_TRUE(std::isnan(analysis::silo_report(f, o).zone_extent_left));
  o.zone_extent_factor = 1;
  EXPECT_THROW(analysis::silo_report(f, o), std::invalid_argument);
}

// The seed's REV cells (§4.2.3, §5.3.1) in place of the bins: cells 5 mm wide moved by 1 mm
// across a 40 mm silo with one particle per mm, from flush with the left wall (centre 2.5 mm) to
// flush with the right one (37.5 mm): 36 cells of five particles each. The step profile of the
// test above (1 rad out to 6 mm from the left wall and to 10 mm from the right one, 0.1 rad in
// between) averages to 1, 1, 0.82, 0.64, 0.46, 0.28, 0.1, … (k of the five particles on the
// step: 0.1 + 0.18·k), unsmoothed, and mirrored 4 mm further in from the right. The core is
// 0.1, and twice it is crossed 0.08/0.18 of a step past the cell at 7.5 mm (the left) and
// before the cell at 28.5 mm (the right).
TEST(SiloReport, WallZonesInTheSeedsRevCells) {
  const Frame f = zone_silo(40, [](double x) { return (x < 0.006 || x > 0.03) ? -1.0 : 0.1; });
  analysis::SiloReportOptions o = zone_options();
  o.zone_window = 0.005;
  const auto r = analysis::silo_report(f, o);
  ASSERT_EQ(r.zone_across.size(), 36u);
  EXPECT_NEAR(r.zone_across.front(), 0.0025, 1e-15);
  EXPECT_NEAR(r.zone_across.back(), 0.0375, 1e-15);
  const double left[] = {1, 1, 0.82, 0.64, 0.46, 0.28, 0.1, 0.1};
  for (int b = 0; b < 8; ++b) {
    EXPECT_NEAR(r.zone_rotation[b], left[b], 1e-15) << b;
    EXPECT_NEAR(r.zone_rotation[35 - 4 - b], left[b], 1e-15) << b;  // (the right, 4 mm in)
  }
  EXPECT_NEAR(r.zone_core, 0.1, 1e-15);
  const double past = 0.08 / 0.18 * 1e-3;
  EXPECT_NEAR(r.zone_extent_left, 0.0075 + past, 1e-15);
  EXPECT_NEAR(r.zone_extent_right, 0.04 - (0.0285 - past), 1e-15);
  // The logistic of the inflection test above, averaged in the cells, stays point-symmetric
  // about 5 mm from each wall: the inflection is there still (in a silo 40 mm wide, where the
  // other wall's tail, e^-30 of the peak, does not reach).
  auto logistic = [](double x) { return 1 / (1 + std::exp((x - 0.005) / 0.001)); };
  const Frame g = zone_silo(40, [&](double x) { return logistic(x) + logistic(0.04 - x); });
  const auto z = analysis::silo_report(g, o);
  ASSERT_EQ(z.zone_across.size(), 36u);
  EXPECT_NEAR(z.zone_left, 0.005, 1e-12);
  EXPECT_NEAR(z.zone_right, 0.005, 1e-12);
  // A silo narrower than a cell and two steps has no profile (the zones NaN).
  const auto narrow = analysis::silo_report(zone_silo(6, [](double) { return 1.0; }), o);
  EXPECT_TRUE(narrow.zone_across.empty());
  EXPECT_TRUE(std::isnan(narrow.zone_left) && std::isnan(narrow.zone_extent_left));
}

// Exact answers for the slice method of seed 004 §5.3.1: Eq 5.2 at φw = φi reduces to
// K = cos²φ / (1 + sin²φ); at 35°/32° it is the printed 0.83. Eq 5.1 with the seed's own
// inputs (γ = 16 kN/m³, b = 0.2 m, depth 0.6 m, h = 0.5 m, the printed K and the experimental
// φw, R = b as the seed writes it) gives Table 5.3's Drescher row, 533 / 490 / 537 N, to 1 N.
TEST(SiloTheory, DrescherRatioAndJanssenBottomForceAgainstTheSeed) {
  const double phi = 35 * M_PI / 180;
  EXPECT_NEAR(drescher_lateral_ratio(35, 35),
              std::cos(phi) * std::cos(phi) / (1 + std::sin(phi) * std::sin(phi)), 1e-14);
  EXPECT_NEAR(drescher_lateral_ratio(35, 32), 0.83, 0.005);
  EXPECT_THROW(drescher_lateral_ratio(35, 36), std::invalid_argument);
  EXPECT_THROW(drescher_lateral_ratio(35, 0), std::invalid_argument);
  const double printed_k[] = {1.73, 1.21, 0.83}, phi_w[] = {17, 27, 32}, table[] = {533, 490, 537};
  for (int i = 0; i < 3; ++i) {
    const double mu = std::tan(phi_w[i] * M_PI / 180);
    const double P = janssen_vertical_stress(16e3, printed_k[i], mu, 0.2, 0.5) * 0.2 * 0.6;
    EXPECT_NEAR(P, table[i], 1.0) << "phi_w " << phi_w[i];
  }
  // Shallow fill: hydrostatic, γh·(1 − h/(2·z0)) to second order (z0 = R/(Kμ) = 0.5 m); deep fill:
  // Janssen's asymptote γR/(Kμ).
  EXPECT_NEAR(janssen_vertical_stress(1e4, 0.5, 0.4, 0.1, 1e-6), 1e4 * 1e-6 * (1 - 1e-6), 1e-14);
  EXPECT_NEAR(janssen_vertical_stress(1e4, 0.5, 0.4, 0.1, 100), 1e4 * 0.1 / 0.2, 1e-9);
  EXPECT_THROW(janssen_vertical_stress(1e4, 0.5, 0.0, 0.1, 1), std::invalid_argument);
}

namespace {

/// Simple cubic packing of spheres of radius r between a left plane (x = 0) and a right plane
/// (x = 20r), 2 deep (y in [0, 4r]) and 20 high on a bottom plane at z = 0: void ratio
/// 6/π − 1 in any box aligned with the lattice cells.
Frame cubic_silo(double r) {
  Frame f;
  f.walls = {wall(1000, WallKind::Plane, {0, 0, 0}, {1, 0, 0}, {0, 0, 0}),
             wall(1001, WallKind::Plane, {20 * r, 0, 0}, {-1, 0, 0}, {0, 0, 0}),
             wall(1002, WallKind::Plane, {0, 0, 0}, {0, 0, 1}, {0, 0, 0})};
  std::int64_t id = 0;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 20; ++k) {
        Particle p;
        p.id = id++;
        p.position = Eigen::Vector3d((2 * i + 1) * r, (2 * j + 1) * r, (2 * k + 1) * r);
        p.radius = r;
        p.mass = 1e-3;
        f.particles.push_back(p);
      }
  return f;
}

/// A compressive contact of id1 on id2 at `point`: normal n (normalised), force fn·n.
Contact between(std::int64_t a, std::int64_t b, Eigen::Vector3d point, Eigen::Vector3d n,
                double fn = 0.1) {
  Contact c;
  c.id1 = a;
  c.id2 = b;
  c.point = point;
  c.normal = n.normalized();
  c.normal_force = fn * c.normal;
  return c;
}

}  // namespace

// Exact answer: 6/π − 1 in every box of the three layers (at 0.2, 0.5 and 0.8 of the 40r fill,
// bands 4r thick, boxes 2r wide: all aligned with the lattice's cells).
TEST(SiloReport, VoidRatioAcrossTheWidthOfACubicPacking) {
  const double r = 0.001;
  SiloReportOptions o;
  o.bin = 5 * r;
  o.layer_fractions = {0.2, 0.5, 0.8};
  o.layer_bin = 2 * r;
  o.layer_band = 4 * r;
  const auto rep = silo_report(cubic_silo(r), o);
  EXPECT_NEAR(rep.fill_height, 40 * r, 1e-15);
  EXPECT_NEAR(rep.width, 20 * r, 1e-15);
  ASSERT_EQ(rep.layers.size(), 3u);
  for (const auto& L : rep.layers) {
    ASSERT_EQ(L.void_ratio.size(), 10u);
    for (std::size_t b = 0; b < 10; ++b) {
      EXPECT_NEAR(L.void_ratio[b], 6 / M_PI - 1, 1e-9) << "layer " << L.height << " box " << b;
      EXPECT_NEAR(L.across[b], (2 * b + 1) * r, 1e-15);
    }
  }
  EXPECT_NEAR(rep.layers[1].height, 20 * r, 1e-15);
  // Boxes of 3r (floor(20/3) = 6 boxes of 20r/6) cut the spheres: the mean over the width is
  // still the packing's (the boxes tile the cells' rows).
  o.layer_bin = 3 * r;
  const auto cut = silo_report(cubic_silo(r), o);
  double solid = 0;
  for (const double e : cut.layers[1].void_ratio) solid += 1 / (1 + e);
  EXPECT_NEAR(solid / 6, M_PI / 6, 1e-9);
  o.layer_fractions = {1.2};
  EXPECT_THROW(silo_report(cubic_silo(r), o), std::invalid_argument);
}

// Hand-computed fabric: in the left half, contacts at +30° and −30° from the wall normal (in the
// across–up plane) give a planar tensor diag(cos²30°, sin²30°): major direction 0°, anisotropy
// cos 60° = 1/2; the right half's vertical contact and wall contacts are left out. All at +30°:
// direction 30°, anisotropy 1.
TEST(SiloReport, LeftHalfContactOrientation) {
  const double r = 0.001;
  Frame f = cubic_silo(r);
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  f.contacts = {between(0, 1, {5 * r, r, 10 * r}, {c, 0, s}),
                between(2, 3, {6 * r, r, 12 * r}, {c, 0, -s}),
                between(4, 5, {3 * r, 2 * r, 14 * r}, {-c, 0.3, -s}),  // (projected: -150° ≡ 30°)
                between(6, 7, {4 * r, r, 16 * r}, {-c, 0, s}),
                between(8, 9, {15 * r, r, 10 * r}, {0, 0, 1}),  // right half
                between(1000, 9, {0, r, 10 * r}, {1, 0, 0})};   // wall contact
  SiloReportOptions o;
  o.bin = 5 * r;
  o.fabric_bins = 12;
  const auto rep = silo_report(f, o);
  EXPECT_EQ(rep.fabric_contacts, 4u);
  EXPECT_NEAR(rep.fabric_angle_deg, 0.0, 1e-9);
  EXPECT_NEAR(rep.fabric_anisotropy, 0.5, 1e-12);
  ASSERT_EQ(rep.rose_density.size(), 12u);
  f.contacts = {f.contacts[0], f.contacts[2]};
  const auto one = silo_report(f, o);
  EXPECT_NEAR(one.fabric_angle_deg, 30.0, 1e-9);
  EXPECT_NEAR(one.fabric_anisotropy, 1.0, 1e-12);
}

// Hand-set velocity fields on the cubic packing (10 bands of 4r, wall columns 2r): everything
// going down is mass flow from the bottom; only the middle columns going down is funnel flow;
// the walls moving in the upper half only is mixed flow with its transition at mid-height; one
// wall stagnant is funnel flow whatever the other does; nothing moving is a silo at rest.
TEST(SiloReport, FlowPatternFromTheVelocityField) {
  const double r = 0.001;
  SiloReportOptions o;
  o.bin = 5 * r;
  o.flow_bands = 10;
  o.flow_wall_width = 2 * r;
  auto run = [&](auto down) {
    Frame f = cubic_silo(r);
    for (Particle& p : f.particles) p.velocity = {0, 0, -down(p.position.x(), p.position.z())};
    return silo_report(f, o);
  };
  const auto mass = run([](double, double) { return 1.0; });
  EXPECT_EQ(mass.flow, FlowPattern::Mass);
  EXPECT_DOUBLE_EQ(mass.transition_left, 0.0);
  EXPECT_DOUBLE_EQ(mass.transition_right, 0.0);
  EXPECT_DOUBLE_EQ(mass.flow_speed, 1.0);
  const auto funnel = run([&](double x, double) { return x > 8 * r && x < 12 * r ? 1.0 : 0.0; });
  EXPECT_EQ(funnel.flow, FlowPattern::Funnel);
  EXPECT_TRUE(std::isnan(funnel.transition_left));
  const auto mixed =
      run([&](double x, double z) { return z > 20 * r || (x > 8 * r && x < 12 * r) ? 1.0 : 0.0; });
  EXPECT_EQ(mixed.flow, FlowPattern::Mixed);
  EXPECT_NEAR(mixed.transition_left, 20 * r, 1e-15);
  EXPECT_NEAR(mixed.transition_right, 20 * r, 1e-15);
  // A wall creeping at 5 % of the channel's speed is stagnant (threshold 10 %).
  const auto creep = run([&](double x, double) { return x > 8 * r && x < 12 * r ? 1.0 : 0.05; });
  EXPECT_EQ(creep.flow, FlowPattern::Funnel);
  const auto right = run([&](double x, double) { return x > 4 * r ? 1.0 : 0.0; });
  EXPECT_EQ(right.flow, FlowPattern::Funnel);
  EXPECT_TRUE(std::isnan(right.transition_left));
  EXPECT_DOUBLE_EQ(right.transition_right, 0.0);
  EXPECT_EQ(run([](double, double) { return 0.0; }).flow, FlowPattern::Rest);
  EXPECT_STREQ(flow_pattern_name(FlowPattern::Mixed), "mixed");
  // A crater over an outlet at the right wall: the three columns next to it hold no grains above
  // z = 24r (bands 6–9 empty at that wall). Everything that is there moving down is mass flow:
  // the right wall is judged up to the band below its own surface (band 5), not through the
  // empty bands above it. Its column stagnant under the crater is still funnel flow.
  auto crater = [&](auto down, bool bare) {
    Frame f = cubic_silo(r);
    std::vector<Particle> kept;
    for (Particle p : f.particles) {
      if (p.position.x() > 14 * r && p.position.z() > 24 * r) continue;
      if (bare && p.position.x() > 18 * r) continue;
      p.velocity = {0, 0, -down(p.position.x(), p.position.z())};
      kept.push_back(p);
    }
    f.particles = kept;
    return silo_report(f, o);
  };
  const auto sunk = crater([](double, double) { return 1.0; }, false);
  EXPECT_EQ(sunk.flow, FlowPattern::Mass);
  EXPECT_DOUBLE_EQ(sunk.transition_right, 0.0);
  EXPECT_DOUBLE_EQ(sunk.transition_left, 0.0);
  EXPECT_EQ(crater([&](double x, double) { return x > 18 * r ? 0.0 : 1.0; }, false).flow,
            FlowPattern::Funnel);
  // A wall swept bare (no grains in its column) holds no dead zone: the other wall decides.
  const auto bare = crater([](double, double) { return 1.0; }, true);
  EXPECT_TRUE(std::isnan(bare.transition_right));
  EXPECT_EQ(bare.flow, FlowPattern::Mass);
  EXPECT_EQ(
      crater([&](double x, double z) { return x < 2 * r && z < 20 * r ? 0.0 : 1.0; }, true).flow,
      FlowPattern::Mixed);
}

// Hand-set: the reference frame holds the grains 0.3r higher in the left half and 0 elsewhere,
// the rotation about the depth axis (up × across = z × x = y) is
// 0.2 rad in the box at the left wall and −0.1 rad elsewhere: the boxes' means are these.
TEST(SiloReport, LayerDisplacementAndRotationSinceTheReference) {
  const double r = 0.001;
  Frame now = cubic_silo(r), before = cubic_silo(r);
  for (std::size_t i = 0; i < now.particles.size(); ++i) {
    const double x = now.particles[i].position.x();
    if (x < 10 * r) before.particles[i].position.z() += 0.3 * r;
    now.particles[i].rotation = Eigen::Vector3d(0.5, x < 2 * r ? 0.2 : -0.1, 0.7);
  }
  SiloReportOptions o;
  o.bin = 5 * r;
  o.layer_fractions = {0.5};
  o.layer_bin = 2 * r;
  o.layer_band = 4 * r;
  const auto rep = silo_report(now, o, &before);
  ASSERT_EQ(rep.layers.size(), 1u);
  const auto& L = rep.layers[0];
  ASSERT_EQ(L.displacement_down.size(), 10u);
  for (std::size_t b = 0; b < 10; ++b) {
    EXPECT_NEAR(L.displacement_down[b], b < 5 ? 0.3 * r : 0.0, 1e-15) << b;
    EXPECT_NEAR(L.rotation[b], b == 0 ? 0.2 : 0.1, 1e-15) << b;
  }
  const auto alone = silo_report(now, o);
  EXPECT_TRUE(std::isnan(alone.layers[0].displacement_down[0]));
}

// Exact answer: a row of five grains in equilibrium between the side walls, each contact
// pushing with Fn along x: in the near-wall cells (2r wide, the bin's height, the row's depth)
// the Love–Weber stress is the wall's σ11 = Fn / (bin·depth) on both sides, with no shear.
TEST(SiloReport, LoveWeberNearWallCellsEqualTheWallStressOfARowInEquilibrium) {
  const double r = 0.001, Fn = 0.3;
  Frame f;
  f.walls = {wall(100, WallKind::Plane, {0, 0, 0}, {1, 0, 0}, {-Fn, 0, 0}),
             wall(101, WallKind::Plane, {10 * r, 0, 0}, {-1, 0, 0}, {Fn, 0, 0}),
             wall(102, WallKind::Plane, {0, 0, 0}, {0, 0, 1}, {0, 0, 0})};
  for (int i = 0; i < 5; ++i) {
    Particle p;
    p.id = i;
    p.position = Eigen::Vector3d((2 * i + 1) * r, 0, 3 * r);
    p.radius = r;
    p.mass = 1e-5;
    f.particles.push_back(p);
  }
  f.contacts.push_back(between(100, 0, {0, 0, 3 * r}, {1, 0, 0}, Fn));
  for (int i = 0; i < 4; ++i)
    f.contacts.push_back(between(i, i + 1, {(2 * i + 2) * r, 0, 3 * r}, {1, 0, 0}, Fn));
  f.contacts.push_back(between(101, 4, {10 * r, 0, 3 * r}, {-1, 0, 0}, Fn));
  SiloReportOptions o;
  o.bin = 4 * r;
  o.rev_width = 2 * r;
  const auto rep = silo_report(f, o);
  ASSERT_EQ(rep.profile.height.size(), 1u);
  const double s11 = Fn / (4 * r * 2 * r);
  EXPECT_NEAR(rep.profile.sigma11_left[0], s11, 1e-9 * s11);
  EXPECT_NEAR(rep.profile.sigma11_right[0], s11, 1e-9 * s11);
  EXPECT_NEAR(rep.profile.lw_sigma11_left[0], s11, 1e-9 * s11);
  EXPECT_NEAR(rep.profile.lw_sigma11_right[0], s11, 1e-9 * s11);
  EXPECT_NEAR(rep.profile.lw_sigma21_left[0], 0.0, 1e-9 * s11);
  EXPECT_NEAR(rep.profile.lw_sigma21_right[0], 0.0, 1e-9 * s11);
  // A cell twice as wide holds one more half branch per side: the same stress.
  o.rev_width = 4 * r;
  EXPECT_NEAR(silo_report(f, o).profile.lw_sigma11_left[0], s11, 1e-9 * s11);
}
