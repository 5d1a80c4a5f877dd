// Outlets: particles leaving the region kept are removed, counted and weighed, and a run with
// removals resumes from a checkpoint bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "mesh_walls.hpp"
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

namespace {

// A block of 4 x 4 x 8 spheres (radii 0.996-1 mm, 2 mm apart: touching or a few µm apart) sliding
// down a vertical wall of 6 x 12 squares of facets (YADE's contacts) at x = -1 mm through the
// outlet plane z = 0, gravity 30 degrees off the vertical pressing it onto the wall: sphere pairs,
// facet pairs within reach and facet pairs deferred, in contact as their spheres leave.
std::vector<Particle> block() {
  std::vector<Particle> ps;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        Particle p;
        p.id = static_cast<std::int64_t>(ps.size());
        p.radius = 1e-3 * (1 - 0.002 * ((i + 2 * j + k) % 3));
        p.position = {2e-3 * i + p.radius - 1.001e-3, 2e-3 * j, 1.2e-3 + 2e-3 * k};
        ps.push_back(p);
      }
  return ps;
}

solver::MeshTriangles side_wall() {
  solver::MeshTriangles m;
  const int ny = 6, nz = 12;
  const double y0 = -2e-3, z0 = -30e-3, hy = 12e-3 / ny, hz = 50e-3 / nz, x = -1e-3;
  for (int a = 0; a < ny; ++a)
    for (int b = 0; b < nz; ++b) {
      const Eigen::Vector3d p00(x, y0 + a * hy, z0 + b * hz),
          p10(x, y0 + (a + 1) * hy, z0 + b * hz), p01(x, y0 + a * hy, z0 + (b + 1) * hz),
          p11(x, y0 + (a + 1) * hy, z0 + (b + 1) * hz);
      m.triangles.push_back({p00, p10, p11});
      m.triangles.push_back({p00, p11, p01});
      m.group.push_back("side");
      m.group.push_back("side");
    }
  return m;
}

solver::SimulationConfig block_config(int threads) {
  solver::SimulationConfig c = falling();
  c.material.friction_deg = 30;
  c.dt = 1e-5;
  c.damping = 0.1;
  c.threads = threads;
  c.gravity = Eigen::Vector3d(-9.81 * std::sin(M_PI / 6), 0, -9.81 * std::cos(M_PI / 6));
  return c;
}

solver::Simulation block_run(int threads) {
  solver::Simulation sim(block_config(threads), block(),
                         solver::mesh_walls(side_wall(), solver::MeshContact::YadeParity));
  sim.set_outlet(Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, 1, 1));
  return sim;
}

void expect_same_state(const solver::Simulation& a, const solver::Simulation& b, int step) {
  ASSERT_EQ(a.removed_count(), b.removed_count()) << "step " << step;
  ASSERT_EQ(a.contact_count(), b.contact_count()) << "step " << step;
  ASSERT_EQ(a.particles().pos, b.particles().pos) << "step " << step;
  ASSERT_EQ(a.particles().vel, b.particles().vel) << "step " << step;
  ASSERT_EQ(a.particles().angvel, b.particles().angvel) << "step " << step;
  ASSERT_EQ(a.walls()[0].force, b.walls()[0].force) << "step " << step;
}

}  // namespace

// Exact answer: a sphere leaving through the outlet takes its pairs out of the contact pass
// without a neighbour-list build (Simulation::drop_removed_pairs). The run must be the run whose
// list is built anew after every removal (as it was before; forced here through
// invalidate_neighbors) to the bit, after every step and between steps (the contact count read
// right after a removal), on one thread and two, and through a checkpoint written right after a
// removal; and it must build its list fewer times.
TEST(Outlet, RemovalDropsPairsWithoutABuildAndChangesNoBit) {
  solver::Simulation dropped = block_run(1), rebuilt = block_run(1), two = block_run(2);
  const auto path = std::filesystem::temp_directory_path() / "gs_outlet_dropped_checkpoint.bin";
  std::filesystem::remove(path);
  int removal_steps = 0;
  std::size_t contacts_at_removal = 0;
  for (int s = 1; s <= 9000; ++s) {
    const std::size_t before = dropped.removed_count();
    dropped.step();
    rebuilt.step();
    two.step();
    if (rebuilt.removed_count() != before) {
      rebuilt.invalidate_neighbors();
      ++removal_steps;
      contacts_at_removal += dropped.contact_count();
      if (removal_steps == 20) dropped.save_checkpoint(path);
    }
    expect_same_state(dropped, rebuilt, s);
    expect_same_state(dropped, two, s);
    if (HasFatalFailure()) return;
  }
  // (the case is what it is meant to be: spheres leave on many steps, in contact as they
  // leave, and the list is built fewer times)
  EXPECT_GT(removal_steps, 40);
  EXPECT_GT(dropped.removed_count(), 64u);
  std::printf(
      "%zu spheres out on %d steps, %zu contacts just after them, list builds %lld (%lld "
      "building after every removal)\n",
      dropped.removed_count(), removal_steps, contacts_at_removal,
      static_cast<long long>(dropped.neighbor_list_builds()),
      static_cast<long long>(rebuilt.neighbor_list_builds()));
  EXPECT_GT(contacts_at_removal, 0u);
  EXPECT_LT(dropped.neighbor_list_builds(), rebuilt.neighbor_list_builds());
  // The checkpoint after the 20th removal, resumed, ends where the straight run does.
  ASSERT_TRUE(std::filesystem::exists(path));
  solver::Simulation resumed = block_run(1);
  resumed.load_checkpoint(path);
  std::filesystem::remove(path);
  const std::int64_t left = 9000 - resumed.step_count();
  ASSERT_GT(left, 0);
  solver::Simulation straight = block_run(1);
  straight.run(resumed.step_count());
  resumed.run(left);
  straight.run(left);
  expect_same_state(resumed, straight, 9000);
  expect_same_state(resumed, dropped, 9000);
}

namespace {

// Two dimers and two spheres in a row along x, pressed together (overlaps of 2 µm) and moving
// against each other; no gravity, no damping: what the contacts store and the bodies carry is
// all the energy there is.
struct Row {
  std::vector<Particle> ps;
  std::vector<solver::ClumpBody> clumps;
};

Row row() {
  Row r;
  const double rad = 1e-3, gap = -2e-6;
  double x = 0;
  auto sphere = [&](double cx, double vx) {
    Particle p;
    p.id = static_cast<std::int64_t>(r.ps.size());
    p.position = {cx, 0, 0};
    p.radius = rad;
    p.velocity = {vx, 0, 0};
    r.ps.push_back(p);
    return static_cast<std::uint32_t>(r.ps.size() - 1);
  };
  for (int k = 0; k < 4; ++k) {
    const double v = k < 2 ? 0.01 : -0.01;
    if (k == 1 || k == 2) {  // a dimer: members 1.4 r apart along x
      const auto a = sphere(x + rad, v), b = sphere(x + 2.4 * rad, v);
      r.clumps.push_back(solver::make_clump_body({a, b}, {r.ps[a].position, r.ps[b].position},
                                                 {rad, rad}, 2500, solver::ClumpMassModel::Union));
      r.clumps.back().vel = {v, 0, 0};
      x += 3.4 * rad + gap;
    } else {
      sphere(x + rad, v);
      x += 2 * rad + gap;
    }
  }
  return r;
}

solver::SimulationConfig still() {
  solver::SimulationConfig c = falling();
  c.gravity.setZero();
  c.dt = 1e-6;
  return c;
}

}  // namespace

// Exact answer: removing a member removes its whole clump (both members, the body, its contacts)
// and nothing else; the energy the removed bodies carried (kinetic and the elastic energy of
// their contacts) is what the ledger's outflow gains, to round-off; removed count and mass are
// the members' count and the clump's mass.
TEST(RemoveParticles, TakesWholeClumpsAndTheirEnergy) {
  const Row r = row();
  solver::Simulation sim(still(), r.ps, {});
  sim.set_clumps(r.clumps);
  sim.run(50);
  const auto before = sim.energy();
  ASSERT_GT(before.elastic_normal, 0.0);
  const double clump_mass = sim.clumps()[0].mass;
  sim.remove_particles({2});  // the second member of the first dimer
  const auto after = sim.energy();
  EXPECT_EQ(sim.clumps().size(), 1u);
  EXPECT_EQ(sim.removed_count(), 2u);
  EXPECT_EQ(sim.removed_mass(), clump_mass);
  EXPECT_EQ(sim.particles().removed[1], 1);
  EXPECT_EQ(sim.particles().removed[2], 1);
  EXPECT_EQ(sim.particles().removed[0] + sim.particles().removed[3] + sim.particles().removed[4] +
                sim.particles().removed[5],
            0);
  EXPECT_EQ(sim.particles().clump[3], 0);  // the second dimer is now clump 0
  const double gone = before.stored() - after.stored();
  EXPECT_GT(gone, 0.0);
  EXPECT_NEAR(after.outflow - before.outflow, gone, 1e-12 * before.stored());
  const auto f = sim.frame();
  EXPECT_EQ(f.particles.size(), 4u);
  for (const auto& c : f.contacts) {
    EXPECT_NE(c.id1, 1);
    EXPECT_NE(c.id2, 2);
  }
  // The rest goes on, and the ledger balances as well as without a removal (the leapfrog's
  // own residual, measured on the same run without one).
  sim.run(200);
  const auto later = sim.energy();
  solver::Simulation whole(still(), r.ps, {});
  whole.set_clumps(r.clumps);
  whole.run(50);
  const double r0 = whole.energy().residual();
  whole.run(200);
  const double own = std::abs(whole.energy().residual() - r0);
  std::printf("residual drift over 200 steps: %g J with the removal, %g J without (stored %g J)\n",
              later.residual() - after.residual(), own, before.stored());
  EXPECT_LT(std::abs(later.residual() - after.residual()), 2 * own + 1e-15);
  EXPECT_THROW(sim.remove_particles({6}), std::invalid_argument);
}

// Exact answer: a run that removed a clump, checkpointed and resumed in a simulation built from
// the scene as it was (all clumps), is the uninterrupted run to the bit.
TEST(RemoveParticles, RemovedClumpsSurviveCheckpointBitForBit) {
  const Row r = row();
  const auto path = std::filesystem::temp_directory_path() / "gs_remove_checkpoint.bin";
  solver::Simulation a(still(), r.ps, {});
  a.set_clumps(r.clumps);
  a.run(40);
  a.remove_particles({0, 3});  // the first sphere and the second dimer
  a.run(30);
  a.save_checkpoint(path);
  solver::Simulation b(still(), r.ps, {});
  b.set_clumps(r.clumps);
  b.load_checkpoint(path);
  std::filesystem::remove(path);
  ASSERT_EQ(b.clumps().size(), 1u);
  a.run(300);
  b.run(300);
  EXPECT_EQ(a.removed_count(), 3u);
  EXPECT_EQ(a.removed_count(), b.removed_count());
  EXPECT_EQ(a.removed_mass(), b.removed_mass());
  EXPECT_EQ(a.particles().pos, b.particles().pos);
  EXPECT_EQ(a.particles().vel, b.particles().vel);
  EXPECT_EQ(a.clumps()[0].pos, b.clumps()[0].pos);
  EXPECT_EQ(a.clumps()[0].angmom, b.clumps()[0].angmom);
}
