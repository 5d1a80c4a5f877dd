// The solver against exact answers: impact, inclined plane, moment–rotation, determinism.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "simulation.hpp"

using namespace gs;
using namespace gs::solver;

namespace {

Material material(double young = 1e8, double mu_deg = 30, double beta = 0, double eta = -1) {
  Material m;
  m.young_ec = young;
  m.stiffness_ratio = 0.3;
  m.friction_deg = mu_deg;
  m.density = 2600;
  m.rolling_beta = beta;
  m.rolling_eta = eta;
  return m;
}

Particle sphere(std::int64_t id, Eigen::Vector3d x, double r,
                Eigen::Vector3d v = Eigen::Vector3d::Zero()) {
  Particle p;
  p.id = id;
  p.position = x;
  p.radius = r;
  p.velocity = v;
  return p;
}

WallSpec plane(Eigen::Vector3d point, Eigen::Vector3d normal) {
  WallSpec w;
  w.shape = WallShape::Plane;
  w.center = point;
  w.normal = normal.normalized();
  return w;
}

}  // namespace

// Two equal spheres, head on, no damping: contact lasts π·sqrt(m*/Kn) (m* = m/2) and the
// rebound speed equals the approach speed. Then, between two fixed planes, the pair keeps
// colliding with each other and the planes for 1e5 steps: the kinetic energy in free flight
// stays at its initial value.
TEST(Physics, HeadOnImpactDurationRestitutionEnergy) {
  const double r = 1e-3, v0 = 0.05;
  SimulationConfig c;
  c.material = material();
  const double m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double kn = c.material.young_ec * r;  // 2·r·r/(r + r)
  const double duration = M_PI * std::sqrt(0.5 * m / kn);
  c.dt = duration / 2000;
  const double gap = 4e-6;
  Simulation sim(
      c, {sphere(0, {0, 0, 0}, r, {v0, 0, 0}), sphere(1, {2 * r + gap, 0, 0}, r, {-v0, 0, 0})},
      {plane({-r - gap, 0, 0}, {1, 0, 0}), plane({3 * r + 2 * gap, 0, 0}, {-1, 0, 0})});
  const double e0 = sim.kinetic_energy();
  std::int64_t first = -1, last = -1;
  double max_energy_error = 0;
  int collisions = 0;
  bool in_contact = false;
  for (int s = 0; s < 100000; ++s) {
    sim.step();
    const auto f = sim.frame();
    const bool pair_contact =
        std::any_of(f.contacts.begin(), f.contacts.end(),
                    [](const Contact& k) { return k.id1 == 0 && k.id2 == 1; });
    if (pair_contact && collisions == 0) {
      if (first < 0) first = s;
      last = s;
    }
    if (!pair_contact && first >= 0 && collisions == 0) {
      collisions = 1;
      // Restitution after the first sphere–sphere collision.
      const double v_after = sim.particles().vel[1].x() - sim.particles().vel[0].x();
      EXPECT_NEAR(v_after / (2 * v0), 1.0, 1e-6);
    }
    if (!f.contacts.empty()) {
      in_contact = true;
      continue;
    }
    if (in_contact) ++collisions;
    in_contact = false;
    max_energy_error = std::max(max_energy_error, std::abs(sim.kinetic_energy() - e0) / e0);
  }
  ASSERT_GE(first, 0);
  const double measured = static_cast<double>(last - first + 1) * c.dt;
  EXPECT_NEAR(measured / duration, 1.0, 0.01);
  EXPECT_GE(collisions, 8);  // sphere–sphere and sphere–plane impacts
  EXPECT_LT(max_energy_error, 1e-6) << "over 1e5 steps";
}

// A sphere on a plane inclined at θ (gravity along −z, plane normal rotated about y).
namespace {
struct InclineResult {
  double accel, roll_rate;
};
InclineResult incline(double theta_deg, double mu_deg, bool block_rotation, double beta = 0,
                      double* max_travel = nullptr) {
  const double th = theta_deg * M_PI / 180, r = 1e-3, g = 9.81;
  SimulationConfig c;
  c.material = material(1e8, mu_deg, beta, beta > 0 ? 1e9 : -1);
  c.gravity = Eigen::Vector3d(0, 0, -g);
  const Eigen::Vector3d n(-std::sin(th), 0, std::cos(th)),
      down_slope(-std::cos(th), 0, -std::sin(th));
  // Start at static overlap so the normal direction is at rest.
  const double m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double delta = m * g * std::cos(th) / (c.material.young_ec * r);
  c.dt = 2e-7;
  Simulation sim(c, {sphere(0, n * (r - delta), r)}, {plane({0, 0, 0}, n)});
  sim.particles().rot_blocked[0] = block_rotation;
  const int steps = 50000;  // 10 ms
  const Eigen::Vector3d x0 = sim.particles().pos[0];
  for (int s = 0; s < steps / 2; ++s) {
    sim.step();
    if (max_travel)
      *max_travel = std::max(*max_travel, std::abs((sim.particles().pos[0] - x0).dot(down_slope)));
  }
  const double v1 = sim.particles().vel[0].dot(down_slope), w1 = sim.particles().angvel[0].y();
  sim.run(steps / 2);
  const double v2 = sim.particles().vel[0].dot(down_slope), w2 = sim.particles().angvel[0].y();
  const double t = steps / 2 * c.dt;
  return {(v2 - v1) / t, (w2 - w1) / t};
}
}  // namespace

TEST(Physics, InclineSticksBelowFrictionAngle) {
  // Sliding would travel ½·a·t² ≈ 3e-6 m in 5 ms even at a = 0.25 m/s²; sticking leaves only
  // the elastic tangential displacement m·g·sinθ/Ks ≈ 1e-9 m (oscillating, undamped).
  double travel = 0;
  incline(15, 20, /*block_rotation=*/true, 0, &travel);
  EXPECT_LT(travel, 1e-8);
}

TEST(Physics, InclineSlidesAboveFrictionAngleWithAnalyticAcceleration) {
  const double th = 30 * M_PI / 180, mu = 20 * M_PI / 180;
  const auto res = incline(30, 20, /*block_rotation=*/true);
  const double expected = 9.81 * (std::sin(th) - std::cos(th) * std::tan(mu));
  EXPECT_NEAR(res.accel / expected, 1.0, 1e-3);
}

TEST(Physics, InclineRollsAtFiveSeventhsGSinTheta) {
  const double th = 20 * M_PI / 180;
  const auto res = incline(20, 30, /*block_rotation=*/false);  // tan μ > 2/7 tan θ: rolls
  EXPECT_NEAR(res.accel / (5.0 / 7.0 * 9.81 * std::sin(th)), 1.0, 1e-3);
  EXPECT_NEAR(res.roll_rate * 1e-3, -res.accel, 1e-3 * res.accel);  // v = −ω_y·r: no slip
}

// Two pressed spheres; the upper one is turned at a constant rate about x: the rolling moment
// grows with slope Kr, saturates at η·R_roll·|Fn|, and unloads elastically with slope Kr.
TEST(Physics, MomentRotationSlopePlateauUnloading) {
  const double ra = 1e-3, rb = 2e-3, beta = 0.7, eta = 0.4;
  for (auto rr : {RollingRadius::Min, RollingRadius::Mean}) {
    SimulationConfig c;
    c.material = material(1e8, 30, beta, eta);
    c.material.rolling_radius = rr;
    c.dt = 1e-7;
    const double overlap = 1e-6;
    Simulation sim(c, {sphere(0, {0, 0, 0}, ra), sphere(1, {0, 0, ra + rb - overlap}, rb)}, {});
    auto& p = sim.particles();
    p.fixed[0] = p.fixed[1] = 1;
    const double omega = 0.5;  // rad/s
    p.angvel[1] = Eigen::Vector3d(omega, 0, 0);
    const auto k = contact_stiffness(c.material.young_ec, 0.3, beta, ra, rb, rr);
    const double fn = k.kn * overlap;
    const double plateau = eta * k.rolling_radius_m * fn;
    const double theta_yield = plateau / k.kr;
    const int load_steps = static_cast<int>(1.5 * theta_yield / (omega * c.dt));
    double m_prev = 0;
    for (int s = 1; s <= load_steps; ++s) {
      sim.step();
      const double m = std::abs(sim.frame().contacts.at(0).bending_moment.x());
      const double elastic = k.kr * omega * c.dt * s;
      if (elastic < plateau * (1 - 1e-9)) {
        EXPECT_NEAR(m, elastic, 1e-9 * elastic) << "step " << s;
      } else {
        EXPECT_NEAR(m, plateau, 1e-12 * plateau) << "step " << s;
      }
      m_prev = m;
    }
    EXPECT_NEAR(m_prev, plateau, 1e-12 * plateau);
    p.angvel[1] = Eigen::Vector3d(-omega, 0, 0);  // unload
    for (int s = 1; s <= 100; ++s) {
      sim.step();
      const double m = std::abs(sim.frame().contacts.at(0).bending_moment.x());
      EXPECT_NEAR(m, plateau - k.kr * omega * c.dt * s, 1e-9 * plateau) << "unloading step " << s;
    }
  }
}

// Twisting moment (off unless enabled): incremental, slope Ktw = βtw·Ks·RA·RB, plateau at
// ηtw·R_roll·|Fn|, elastic unloading; the bending moment stays zero under a pure twist.
TEST(Physics, TwistMomentSlopePlateauUnloadingAndOffByDefault) {
  const double ra = 1e-3, rb = 2e-3, beta_tw = 0.5, eta_tw = 0.3;
  for (bool enabled : {true, false}) {
    SimulationConfig c;
    c.material = material(1e8, 30, 0.7, 0.4);
    c.dt = 1e-7;
    if (enabled) {
      c.twist_beta = beta_tw;
      c.twist_eta = eta_tw;
    }
    const double overlap = 1e-6;
    Simulation sim(c, {sphere(0, {0, 0, 0}, ra), sphere(1, {0, 0, ra + rb - overlap}, rb)}, {});
    auto& p = sim.particles();
    p.fixed[0] = p.fixed[1] = 1;
    const double omega = 0.5;  // rad/s about the contact normal
    p.angvel[1] = Eigen::Vector3d(0, 0, omega);
    const auto k = contact_stiffness(c.material.young_ec, 0.3, 0.7, ra, rb, RollingRadius::Min);
    const double ktw = beta_tw * k.ks * ra * rb;
    const double plateau = eta_tw * k.rolling_radius_m * k.kn * overlap;
    const int load_steps = static_cast<int>(1.5 * plateau / ktw / (omega * c.dt));
    for (int s = 1; s <= load_steps; ++s) {
      sim.step();
      const auto contact = sim.frame().contacts.at(0);
      EXPECT_EQ(contact.bending_moment.norm(), 0.0) << "step " << s;
      const double m = std::abs(contact.twisting_moment.z());
      if (!enabled) {
        ASSERT_EQ(contact.twisting_moment.norm(), 0.0) << "step " << s;
        continue;
      }
      const double elastic = ktw * omega * c.dt * s;
      if (elastic < plateau * (1 - 1e-9))
        EXPECT_NEAR(m, elastic, 1e-9 * elastic) << "step " << s;
      else
        EXPECT_NEAR(m, plateau, 1e-12 * plateau) << "step " << s;
    }
    if (!enabled) continue;
    p.angvel[1] = Eigen::Vector3d(0, 0, -omega);  // unload
    for (int s = 1; s <= 100; ++s) {
      sim.step();
      const double m = std::abs(sim.frame().contacts.at(0).twisting_moment.z());
      EXPECT_NEAR(m, plateau - ktw * omega * c.dt * s, 1e-9 * plateau) << "unloading step " << s;
    }
  }
}

namespace {
std::vector<Particle> random_packing(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Particle> ps;
  // Jittered lattice, slightly overlapping neighbours, random velocities.
  const int side = static_cast<int>(std::ceil(std::cbrt(n)));
  for (int i = 0; i < n; ++i) {
    const int x = i % side, y = (i / side) % side, z = i / (side * side);
    ps.push_back(sphere(
        i, Eigen::Vector3d(x, y, z) * 1.98e-3 + Eigen::Vector3d(u(rng), u(rng), u(rng)) * 5e-5,
        1e-3 * (0.95 + 0.1 * u(rng)),
        Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) * 0.1));
  }
  return ps;
}
SimulationConfig packing_config(int threads) {
  SimulationConfig c;
  c.material = material(1e8, 25, 0.5, 0.3);
  c.dt = 2e-7;
  c.damping = 0.1;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.threads = threads;
  c.max_overlap_ratio = 0.2;
  return c;
}
std::vector<WallSpec> box_walls() {
  WallSpec b;
  b.shape = WallShape::Box;
  b.center = Eigen::Vector3d(0.01, 0.01, -0.00205);
  b.half_extents = Eigen::Vector3d(0.05, 0.05, 0.001);
  return {b};
}
}  // namespace

TEST(Physics, OneAndTwoThreadsGiveIdenticalResults) {
  const auto ps = random_packing(343, 3);
  Simulation a(packing_config(1), ps, box_walls()), b(packing_config(2), ps, box_walls());
  std::size_t most = 0;
  for (int s = 0; s < 1500; ++s) {
    a.step();
    b.step();
    most = std::max(most, a.contact_count());
  }
  ASSERT_GT(most, 100u);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    ASSERT_EQ(a.particles().pos[i], b.particles().pos[i]) << i;
    ASSERT_EQ(a.particles().angvel[i], b.particles().angvel[i]) << i;
  }
  EXPECT_EQ(a.walls()[0].force, b.walls()[0].force);
}

TEST(Physics, CheckpointResumesBitForBit) {
  const auto ps = random_packing(216, 5);
  Simulation straight(packing_config(2), ps, box_walls());
  straight.run(1200);
  Simulation first(packing_config(2), ps, box_walls());
  first.run(500);
  const auto ckpt =
      std::filesystem::temp_directory_path() / ("gs_ckpt_" + std::to_string(::getpid()));
  first.save_checkpoint(ckpt);
  Simulation resumed(packing_config(1), ps, box_walls());
  resumed.load_checkpoint(ckpt);
  std::filesystem::remove(ckpt);
  EXPECT_EQ(resumed.step_count(), 500);
  resumed.run(700);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    ASSERT_EQ(straight.particles().pos[i], resumed.particles().pos[i]) << i;
    ASSERT_EQ(straight.particles().vel[i], resumed.particles().vel[i]) << i;
  }
  EXPECT_EQ(straight.energy().residual(), resumed.energy().residual());
}

TEST(Physics, BlowUpIsDetected) {
  SimulationConfig c;
  c.material = material();
  c.dt = 1e-4;  // far above critical
  Simulation sim(
      c, {sphere(0, {0, 0, 0}, 1e-3, {1, 0, 0}), sphere(1, {2.1e-3, 0, 0}, 1e-3, {-1, 0, 0})}, {});
  EXPECT_THROW(sim.run(100), BlowUp);
}

// A servo-controlled plane presses a sphere onto a fixed floor and settles at the target stress.
TEST(Physics, ServoWallReachesTargetStress) {
  const double r = 1e-3;
  SimulationConfig c;
  c.material = material(1e8, 30);
  c.dt = 1e-7;
  c.damping = 0.3;
  WallSpec top = plane({0, 0, 2 * r + 1e-5}, {0, 0, -1});
  top.servo_stress_Pa = 1e3;
  top.servo_area_m2 = 1e-6;  // target force 1e-3 N
  top.servo_gain = 1e-4;     // m/s per Pa
  top.servo_max_velocity = 0.05;
  Simulation sim(c, {sphere(0, {0, 0, r}, r)}, {plane({0, 0, 0}, {0, 0, 1}), top});
  sim.run(200000);
  const double force = sim.walls()[1].force.dot(Eigen::Vector3d(0, 0, 1));
  EXPECT_NEAR(force, 1e-3, 1e-5);                      // stress within 1 %
  EXPECT_NEAR(sim.walls()[0].force.z(), -1e-3, 1e-5);  // transmitted to the floor
  EXPECT_NEAR(sim.frame().contacts.at(0).overlap, 1e-3 / (1e8 * r), 1e-9);  // Fn = Kn·u
}

TEST(Physics, EnergyLedgerCatchesAnUnstableRun) {
  // A sphere resting on a floor with dt above the critical 2/ω: each bounce creates energy and
  // the ledger residual flags it before anything becomes non-finite.
  SimulationConfig c;
  c.material = material();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.max_overlap_ratio = 1e9;  // let the ledger be the one to catch it
  const double r = 1e-3, m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double omega = std::sqrt(c.material.young_ec * r / m);
  auto make = [&](double dt) {
    c.dt = dt;
    return Simulation(c, {sphere(0, {0, 0, r - 2e-9}, r)}, {plane({0, 0, 0}, {0, 0, 1})});
  };
  Simulation bad = make(2.2 / omega);
  EXPECT_THROW(
      {
        for (int s = 0; s < 10000; ++s) {
          bad.step();
          bad.check_energy();
        }
      },
      BlowUp);
  Simulation good = make(0.2 / omega);  // the same check passes a stable run
  for (int s = 0; s < 10000; ++s) {
    good.step();
    good.check_energy();
  }
}

// Simple-cubic lattice under uniform overlap δ, sheared at γ̇: I = γ̇·d/sqrt(p/ρ) with the
// Love–Weber mean stress p = (Σ Fn·|l|)/(3V) computed by hand.
TEST(Physics, InertialNumberOfAShearedLattice) {
  const double r = 1e-3, delta = 1e-6, rate = 2.0;
  const int n = 3;
  std::vector<Particle> ps;
  for (int i = 0; i < n * n * n; ++i) {
    const Eigen::Vector3d x = Eigen::Vector3d(i % n, (i / n) % n, i / (n * n)) * (2 * r - delta);
    ps.push_back(sphere(i, x, r, Eigen::Vector3d(rate * x.y(), 0, 0)));
  }
  SimulationConfig c;
  c.material = material(1e8, 30);
  c.dt = 1e-9;
  Simulation sim(c, ps, {});
  sim.step();
  ASSERT_EQ(sim.contact_count(), 54u);  // 3·(n−1)·n²
  const double kn = c.material.young_ec * r;
  const double volume = std::pow((n - 1) * (2 * r - delta) + 2 * r, 3);  // bounding box
  const double p = 54 * kn * delta * (2 * r - delta) / 3 / volume;
  const double expected = rate * 2 * r / std::sqrt(p / c.material.density);
  EXPECT_NEAR(sim.inertial_number() / expected, 1.0, 1e-6);
}
