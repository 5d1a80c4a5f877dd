#include <gtest/gtest.h>

#include <cmath>

#include "cohesive_frictional_law.hpp"
#include "contact_stiffness.hpp"
#include "simulation.hpp"

using gs::solver::contact_stiffness;
using gs::solver::RollingRadius;

TEST(ContactStiffness, HandComputedPair) {
  // Ec = 300 MPa, nu_c = 0.3, beta = 0.7, RA = 1 mm, RB = 3 mm.
  const auto k = contact_stiffness(3e8, 0.3, 0.7, 1e-3, 3e-3, RollingRadius::Mean);
  EXPECT_DOUBLE_EQ(k.kn, 3e8 * 2 * 3e-6 / 4e-3);  // 450 000 N/m
  EXPECT_DOUBLE_EQ(k.ks, 0.3 * 450000.0);
  EXPECT_DOUBLE_EQ(k.kr, 0.7 * 135000.0 * 3e-6);
  EXPECT_DOUBLE_EQ(k.rolling_radius_m, 2e-3);
  EXPECT_DOUBLE_EQ(
      contact_stiffness(3e8, 0.3, 0.7, 1e-3, 3e-3, RollingRadius::Min).rolling_radius_m, 1e-3);
}

TEST(ContactStiffness, WallConventionEqualRadii) {
  // Sphere–box: both radii = R gives Kn = Ec·R and Kr = beta·Ks·R².
  const double R = 2e-3;
  const auto k = contact_stiffness(3e7, 0.3, 0.7, R, R, RollingRadius::Min);
  EXPECT_DOUBLE_EQ(k.kn, 3e7 * R);
  EXPECT_DOUBLE_EQ(k.kr, 0.7 * 0.3 * 3e7 * R * R * R);
}

TEST(ContactStiffness, RejectsDegenerateInput) {
  EXPECT_THROW(contact_stiffness(3e8, 0.3, 0.7, 0.0, 1e-3, RollingRadius::Min),
               std::invalid_argument);
  EXPECT_THROW(contact_stiffness(3e8, 0.3, 0.7, -1e-3, 1e-3, RollingRadius::Min),
               std::invalid_argument);
  EXPECT_THROW(contact_stiffness(0.0, 0.3, 0.7, 1e-3, 1e-3, RollingRadius::Min),
               std::invalid_argument);
  EXPECT_THROW(contact_stiffness(3e8, 0.3, 0.7, std::nan(""), 1e-3, RollingRadius::Min),
               std::invalid_argument);
}

// Seed 003 §2.4's constant stiffness: Kn as given whatever the radii (a pair, a wall, a YADE
// facet's 2R), Ks = νc·Kn (kn = ks there: νc = 1), Kr = β·Ks·r1·r2.
TEST(ContactStiffness, ConstantStiffnessIgnoresTheRadii) {
  gs::solver::Material m;
  m.normal_stiffness_N_m = 1e5;
  m.stiffness_ratio = 1.0;
  m.rolling_beta = 0.5;
  m.friction_deg = 26.56505117707799;
  for (const auto& [ra, rb] : {std::pair{3e-4, 5e-4}, {4e-4, 4e-4}, {8e-4, 4e-4}}) {
    const auto p = gs::solver::contact_params(m, ra, rb, 0.0, -1.0);
    EXPECT_EQ(p.kn, 1e5);
    EXPECT_EQ(p.ks, 1e5);
    EXPECT_DOUBLE_EQ(p.kr, 0.5 * 1e5 * ra * rb);
    EXPECT_DOUBLE_EQ(p.tan_friction, 0.5);
  }
}

// Exact answer: two spheres of 0.3 and 0.5 mm at rest with an overlap δ carry Kn·δ after one
// step (the leapfrog moves nothing before the forces of a step at rest), and a sphere pressed
// into a plane wall the same Kn·δ: the radii do not enter.
TEST(ContactStiffness, ConstantStiffnessInTheEngine) {
  gs::solver::SimulationConfig c;
  c.material.normal_stiffness_N_m = 1e5;
  c.material.stiffness_ratio = 1.0;
  c.material.density = 2700;
  c.dt = 1e-7;
  std::vector<gs::Particle> ps(3);
  ps[0].id = 0;
  ps[0].radius = 3e-4;
  ps[1].id = 1;
  ps[1].radius = 5e-4;
  ps[1].position = {8e-4 - 2e-6, 0, 0};
  ps[2].id = 2;
  ps[2].radius = 4e-4;
  ps[2].position = {0, 0, 5e-3 - 4e-4 + 3e-6};  // 3 µm into the plane z = 5 mm
  gs::solver::WallSpec w;
  w.name = "lid";
  w.shape = gs::solver::WallShape::Plane;
  w.center = {0, 0, 5e-3};
  w.normal = {0, 0, -1};
  gs::solver::Simulation sim(c, ps, {w});
  sim.step();
  const auto f = sim.frame();
  ASSERT_EQ(f.contacts.size(), 2u);
  for (const auto& k : f.contacts) {
    const double expect = k.id1 == 0 ? 1e5 * (8e-4 - (8e-4 - 2e-6)) : 1e5 * 3e-6;
    EXPECT_NEAR(k.normal_force.norm(), expect, 1e-9 * expect) << k.id1 << "-" << k.id2;
  }
  // Without a modulus the engine needs the constant Kn; with the Hertz-Mindlin law it refuses it.
  c.material.normal_stiffness_N_m = 0;
  EXPECT_THROW(gs::solver::Simulation(c, ps, {}), std::invalid_argument);
  c.material.normal_stiffness_N_m = 1e5;
  c.law = gs::solver::ContactLaw::HertzMindlin;
  EXPECT_THROW(gs::solver::Simulation(c, ps, {}), std::invalid_argument);
  // dt "auto": sqrt(m/Kn) of the smallest sphere.
  EXPECT_DOUBLE_EQ(gs::solver::material_timestep({3e-4, 5e-4}, c.material),
                   std::sqrt(2700 * 4.0 / 3.0 * M_PI * 2.7e-11 / 1e5));
}
