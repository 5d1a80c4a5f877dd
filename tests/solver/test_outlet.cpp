// Outlets: particles leaving the region kept are removed, counted and weighed, and a run with
// removals resumes from a checkpoint bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "simulation.hpp"

using namespace gs;

namespace {

solver::SimulationConfig falling() {
  solver::SimulationConfig c;
  c.material.young_ec = 1e7;
  c.material.stiffness_ratio = 0.3;
  c.material.density = 2500;
  c.dt = 1e-4;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  return c;
}

/// 50 spheres far apart (no contacts), heights 1 … 50 cm, radii 1 … 5 mm.
std::vector<Particle> column() {
  std::vector<Particle> ps;
  for (int i = 0; i < 50; ++i) {
    Particle p;
    p.id = 100 + i;
    p.position = {0.02 * (i % 7), 0.02 * (i / 7), 0.01 * (i + 1)};
    p.radius = 1e-3 * (1 + i % 5);
    ps.push_back(p);
  }
  return ps;
}

}  // namespace

// Exact answer: in free fall the leapfrog gives v_n = v_{n−1} + dt·g and z_n = z_{n−1} + dt·v_n
// for every sphere (no contacts): a sphere is removed after the first step whose z_n < 0, so the
// removed count and mass after each step are those of the spheres the same recurrence puts below
// the outlet (computed here with the same operations); frames lose exactly those spheres.
TEST(Outlet, RemovesCountsAndWeighsTheSpheresThatLeave) {
  const auto ps = column();
  solver::Simulation sim(falling(), ps, {});
  sim.set_outlet(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 1));
  std::vector<double> z(ps.size()), v(ps.size(), 0.0);
  std::vector<bool> out(ps.size(), false);
  for (std::size_t i = 0; i < ps.size(); ++i) z[i] = ps[i].position.z();
  const double dt = 1e-4, g = -9.81;
  std::size_t count = 0;
  double mass = 0, lag = 0;
  for (int s = 1; s <= 3500; ++s) {
    sim.step();
    for (std::size_t i = 0; i < ps.size(); ++i) {
      if (out[i]) continue;
      v[i] = v[i] + dt * (0.0 / sim.particles().mass[i] + g);
      z[i] = z[i] + v[i] * dt;
      if (z[i] < 0) {
        out[i] = true;
        ++count;
        mass += sim.particles().mass[i];
        lag += 0.5 * sim.particles().mass[i] * g * g * dt * dt * s;
      }
    }
    ASSERT_EQ(sim.removed_count(), count) << "step " << s;
    ASSERT_EQ(sim.removed_mass(), mass) << "step " << s;
    if (s % 500 == 0) {
      EXPECT_EQ(sim.frame().particles.size(), ps.size() - count);
    }
  }
  EXPECT_EQ(count, 50u);  // all of them by 0.35 s (t = √(2·0.5/g) = 0.319 s for the highest)
  // The kinetic energy they took away is the ledger's outflow term. The ledger's gravity work
  // takes each step's power at the velocity before the update (m·g·v_{k−1}·dt), so after n steps
  // of free fall it lags the kinetic energy ½m(n·g·dt)² by exactly ½m·g²dt²·n: the residual is
  // the sum of those lags, and nothing else.
  const auto& e = sim.energy();
  EXPECT_NEAR(e.residual(), lag, 1e-9 * lag);
  EXPECT_GT(e.outflow, 0.99 * e.gravity_work);
}

// Exact answer: a run with removals, checkpointed half way (after 25 removals) and resumed in a
// new simulation, is the uninterrupted run to the bit: positions, velocities, removed flags,
// count and mass.
TEST(Outlet, RemovalSurvivesCheckpointBitForBit) {
  const auto ps = column();
  const auto path = std::filesystem::temp_directory_path() / "gs_outlet_checkpoint.bin";
  solver::Simulation a(falling(), ps, {});
  a.set_outlet(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 1));
  a.run(2400);
  ASSERT_GT(a.removed_count(), 10u);
  ASSERT_LT(a.removed_count(), 50u);
  a.save_checkpoint(path);
  solver::Simulation b(falling(), ps, {});
  b.set_outlet(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 1));
  b.load_checkpoint(path);
  std::filesystem::remove(path);
  a.run(1000);
  b.run(1000);
  EXPECT_EQ(a.removed_count(), b.removed_count());
  EXPECT_EQ(a.removed_mass(), b.removed_mass());
  EXPECT_EQ(a.particles().removed, b.particles().removed);
  EXPECT_EQ(a.particles().pos, b.particles().pos);
  EXPECT_EQ(a.particles().vel, b.particles().vel);
}

TEST(Outlet, RejectsAnEmptyRegion) {
  solver::Simulation sim(falling(), column(), {});
  EXPECT_THROW(sim.set_outlet(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 1, 0)),
               std::invalid_argument);
}
