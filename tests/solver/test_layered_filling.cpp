// Filling in layers (seed 004 §5.2): each layer inserted once the kinetic energy is negligible,
// without overlaps with the particles and walls already there; a region that cannot take a
// layer says how many particles fitted; a filling resumes from a checkpoint bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "layered_filling.hpp"
#include "mesh_walls.hpp"
#include "simulation.hpp"

using namespace gs;
using solver::FillSpec;

namespace {

solver::SimulationConfig config() {
  solver::SimulationConfig c;
  c.material.young_ec = 1e6;
  c.material.stiffness_ratio = 0.3;
  c.material.friction_deg = 25;
  c.material.density = 2550;
  c.dt = 1e-5;
  c.damping = 0.3;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  return c;
}

solver::WallSpec plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  solver::WallSpec w;
  w.shape = solver::WallShape::Plane;
  w.center = point;
  w.normal = normal;
  return w;
}

/// A 12 mm square box of plane walls, open at the top.
std::vector<solver::WallSpec> box() {
  const double a = 0.012;
  return {plane({0, 0, 0}, {0, 0, 1}), plane({0, 0, 0}, {1, 0, 0}), plane({a, 0, 0}, {-1, 0, 0}),
          plane({0, 0, 0}, {0, 1, 0}), plane({0, a, 0}, {0, -1, 0})};
}

FillSpec spec() {
  FillSpec f;
  f.region_lo_m = Eigen::Vector3d(0, 0, 0.012);
  f.region_hi_m = Eigen::Vector3d(0.012, 0.012, 0.02);
  f.layers = 3;
  f.count = 240;
  f.sizes.dmin_m = 1.2e-3;
  f.sizes.dmax_m = 1.8e-3;
  f.seed = 5;
  return f;
}

struct Filled {
  solver::FillParticles fp;
  solver::Simulation sim;
  solver::LayeredFilling fill;
  explicit Filled(const FillSpec& f = spec())
      : fp(solver::fill_particles(f, 0)),
        sim(config(), fp.particles, box()),
        fill(f, 0, fp.layers, 1000) {}
};

std::size_t in_scene(const solver::Simulation& sim) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) n += sim.particles().removed[i] == 0;
  return n;
}

/// Smallest gap (m) between particle i and every other particle in the scene and the box walls.
double smallest_gap(const solver::Simulation& sim, std::size_t i) {
  const auto& p = sim.particles();
  double gap = HUGE_VAL;
  for (std::size_t j = 0; j < p.size(); ++j)
    if (j != i && p.removed[j] == 0)
      gap = std::min(gap, (p.pos[i] - p.pos[j]).norm() - p.radius[i] - p.radius[j]);
  for (const auto& w : sim.walls())
    gap = std::min(gap, (p.pos[i] - w.pos).dot(w.normal) - p.radius[i]);
  return gap;
}

}  // namespace

TEST(LayeredFilling, EachLayerFollowsOnceTheKineticEnergyIsNegligible) {
  Filled s;
  s.fill.start(s.sim);
  EXPECT_EQ(in_scene(s.sim), 80u);
  int layers = 1;
  std::int64_t last = 0;
  while (!s.fill.finished(s.sim)) {
    const double ek = solver::LayeredFilling::settling_energy(s.sim),
                 threshold = s.fill.threshold(s.sim);
    s.fill.control(s.sim);
    if (s.fill.layers_inserted() > layers) {
      // Inserted only once the previous layer has fallen and come to rest.
      EXPECT_LT(ek, threshold);
      EXPECT_GE(s.sim.step_count() - last, 100);
      ++layers;
      last = s.sim.step_count();
      EXPECT_EQ(in_scene(s.sim), 80u * static_cast<std::size_t>(layers));
      // The new layer's particles overlap nothing (a layer at rest below, the walls).
      double gap = HUGE_VAL;
      for (const auto k : s.fp.layers[static_cast<std::size_t>(layers - 1)])
        gap = std::min(gap, smallest_gap(s.sim, k));
      EXPECT_GE(gap, 0.0);
      std::printf("layer %d inserted at step %lld (E_k %.3g J < %.3g J), smallest gap %.3g m\n",
                  layers, static_cast<long long>(last), ek, threshold, gap);
    }
    if (s.fill.finished(s.sim)) break;
    s.sim.step();
    ASSERT_LT(s.sim.step_count(), 300000);
  }
  EXPECT_EQ(layers, 3);
  EXPECT_EQ(in_scene(s.sim), 240u);
  EXPECT_LT(solver::LayeredFilling::settling_energy(s.sim), s.fill.threshold(s.sim));
  // All of it came to rest inside the box, below the fill region's top.
  for (std::size_t i = 0; i < 240; ++i) EXPECT_LT(s.sim.particles().pos[i].z(), 0.02);
}

// With a small time step a layer placed at rest gains next to no kinetic energy in its first
// steps (here 1e-3 of the threshold after the 100 steps it must fall at least): the next layer
// still waits until this one has fallen out of the region and come to rest on the floor.
TEST(LayeredFilling, ALayerAtRestInTheRegionHasNotSettled) {
  FillSpec f = spec();
  f.layers = 2;
  f.count = 80;
  const auto fp = solver::fill_particles(f, 0);
  auto c = config();
  c.dt = 1e-6;
  solver::Simulation sim(c, fp.particles, box());
  solver::LayeredFilling fill(f, 0, fp.layers, 1000);
  fill.start(sim);
  std::int64_t second = -1;
  while (!fill.finished(sim)) {
    fill.control(sim);
    if (second < 0 && fill.layers_inserted() == 2) {
      second = sim.step_count();
      for (const auto k : fp.layers[0]) EXPECT_LT(sim.particles().pos[k].z(), f.region_lo_m.z());
    }
    if (fill.finished(sim)) break;
    sim.step();
    ASSERT_LT(sim.step_count(), 2000000);
  }
  // At least the time to fall through the region's 8 mm: sqrt(2·0.008/g) = 40 ms.
  EXPECT_GE(second, 40000);
  std::printf("second layer at step %lld (%.1f ms)\n", static_cast<long long>(second),
              1e3 * second * c.dt);
}

TEST(LayeredFilling, ResumesFromACheckpointBitForBit) {
  Filled a, b;
  a.fill.start(a.sim);
  auto advance = [](Filled& s, std::int64_t until) {
    while (s.sim.step_count() < until && !s.fill.finished(s.sim)) {
      s.fill.control(s.sim);
      if (s.fill.finished(s.sim)) break;
      s.sim.step();
    }
  };
  // Past the second insertion, mid-fall.
  std::int64_t k = 0;
  while (a.fill.layers_inserted() < 2) advance(a, k += 1000);
  advance(a, a.sim.step_count() + 777);
  const auto ck = std::filesystem::temp_directory_path() / "gs_fill_ck.bin";
  a.sim.save_checkpoint(ck, a.fill.save_state());
  b.fill.load_state(b.sim.load_checkpoint(ck));
  std::filesystem::remove(ck);
  const std::int64_t end = a.sim.step_count() + 60000;
  advance(a, end);
  advance(b, end);
  ASSERT_EQ(a.sim.step_count(), b.sim.step_count());
  EXPECT_EQ(a.fill.layers_inserted(), 3);
  EXPECT_EQ(b.fill.layers_inserted(), 3);
  for (std::size_t i = 0; i < a.sim.particles().size(); ++i) {
    EXPECT_EQ(a.sim.particles().pos[i], b.sim.particles().pos[i]) << i;
    EXPECT_EQ(a.sim.particles().removed[i], b.sim.particles().removed[i]) << i;
  }
}

// One sphere dropped 12 mm onto the floor bounces (Cundall damping 0.3, no viscous damping): at
// the top of its first bounce it stands still for a moment, its kinetic energy below the
// threshold for a few dozen steps. With hold_steps = 1 the filling ends there, the sphere in the
// air; held for 2 000 steps (20 ms, longer than that moment and shorter than a bounce) it ends
// only once the sphere rests on the floor. The hold's count is in the checkpoint: a run resumed
// in the middle of it ends at the same step.
TEST(LayeredFilling, AMomentOfRestInABounceIsNotRestWithAHold) {
  FillSpec f = spec();
  f.layers = 1;
  f.count = 1;
  f.sizes.dmin_m = f.sizes.dmax_m = 1.5e-3;
  auto fill_until_done = [](Filled& s, std::int64_t stop = -1) {
    while (!s.fill.finished(s.sim) && s.sim.step_count() != stop) {
      s.fill.control(s.sim);
      if (s.fill.finished(s.sim)) break;
      s.sim.step();
      if (s.sim.step_count() > 2000000) ADD_FAILURE() << "no end";
    }
  };
  Filled once(f);
  once.fill.start(once.sim);
  fill_until_done(once);
  const double r = 0.75e-3;
  const double height = once.sim.particles().pos[0].z() - r;
  std::printf("hold 1: ended at step %lld, the sphere %.3g m above the floor\n",
              static_cast<long long>(once.sim.step_count()), height);
  EXPECT_GT(height, 1e-3);  // (at the top of its first bounce)

  f.hold_steps = 2000;
  Filled held(f);
  held.fill.start(held.sim);
  fill_until_done(held);
  const double rest = held.sim.particles().pos[0].z() - r;
  std::printf("hold 2000: ended at step %lld, the sphere %.3g m above the floor, %.3g m/s\n",
              static_cast<long long>(held.sim.step_count()), rest,
              held.sim.particles().vel[0].norm());
  EXPECT_LT(rest, 0.0);  // (on the floor: pressed into it by its weight)
  EXPECT_GT(rest, -1e-5);
  EXPECT_LT(solver::LayeredFilling::settling_energy(held.sim), held.fill.threshold(held.sim));
  EXPECT_GT(held.sim.step_count(), once.sim.step_count() + 2000);

  // Resumed from a checkpoint taken 500 steps before the end, inside the hold.
  Filled a(f), b(f);
  a.fill.start(a.sim);
  fill_until_done(a, held.sim.step_count() - 500);
  const auto ck = std::filesystem::temp_directory_path() / "gs_fill_hold_ck.bin";
  a.sim.save_checkpoint(ck, a.fill.save_state());
  b.fill.load_state(b.sim.load_checkpoint(ck));
  std::filesystem::remove(ck);
  fill_until_done(b);
  EXPECT_EQ(b.sim.step_count(), held.sim.step_count());
  EXPECT_EQ(b.sim.particles().pos[0], held.sim.particles().pos[0]);
}

// A region that cannot take a layer: the error says how many of its particles fitted.
TEST(LayeredFilling, ARegionTooSmallSaysHowManyFitted) {
  FillSpec f = spec();
  f.region_hi_m.z() = 0.0142;  // a 2.2 mm slab: one sphere deep
  f.max_attempts = 2000;
  Filled s(f);
  try {
    s.fill.start(s.sim);
    FAIL() << "no error";
  } catch (const solver::FillError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("layer 1 of 3: the region took "), std::string::npos) << what;
    EXPECT_NE(what.find(" of its 80 particles"), std::string::npos) << what;
    const int took = std::stoi(what.substr(what.find("took ") + 5));
    EXPECT_GT(took, 10);  // some fitted, one sphere deep
    EXPECT_LT(took, 80);
    std::printf("%s\n", what.c_str());
  }
}

// Placement keeps clear of facet walls: a region cut by a tilted triangle gets spheres on both
// sides, none closer to it than its radius.
TEST(LayeredFilling, PlacementKeepsClearOfMeshFacets) {
  solver::MeshTriangles m;
  m.triangles = {{Eigen::Vector3d(-0.05, -0.05, 0.0), Eigen::Vector3d(0.05, -0.05, 0.004),
                  Eigen::Vector3d(0.0, 0.05, 0.012)}};
  m.group = {"ramp"};
  solver::Simulation sim(config(), {}, solver::mesh_walls(m, solver::MeshContact::Merged));
  std::vector<double> radii(200, 0.5e-3);
  const auto x = solver::place_in_region(sim, radii, Eigen::Vector3d(-0.005, -0.005, 0),
                                         Eigen::Vector3d(0.005, 0.005, 0.01), 9, 20000);
  ASSERT_EQ(x.size(), 200u);
  const auto& f = sim.walls()[0].facets[0];
  const Eigen::Vector3d n = f.normal.eigen(), p0 = sim.walls()[0].pos + f.offset.eigen();
  int above = 0;
  double closest = HUGE_VAL;
  for (const auto& xi : x) {
    const double d = (xi - p0).dot(n);
    above += d > 0;
    closest = std::min(closest, std::abs(d));
  }
  std::printf("%d above, %zu below the ramp; closest centre %.4g m (radius 5e-4 m)\n", above,
              x.size() - static_cast<std::size_t>(above), closest);
  EXPECT_GT(above, 20);
  EXPECT_LT(above, 180);
  EXPECT_GE(closest, 0.5e-3);
}

// Lattice placement: sites of spacing 1.05·d from the bottom up, each jittered by at most
// ±1 % of d per axis. A 10 mm cube takes floor((10 − 1)/1.05) + 1 = 9 sites per axis (729);
// 200 spheres fill the two lowest levels (81 each) and 38 of the third; none overlaps another
// (the closest pair is at least 0.05·d − 2·0.01·d apart); 800 asked for, 729 fit.
TEST(LayeredFilling, LatticePlacementFillsFromTheBottomUp) {
  solver::Simulation sim(config(), {}, {});
  const double r = 0.5e-3, d = 2 * r, a = 1.05 * d;
  const Eigen::Vector3d lo(0, 0, 0.01), hi(0.01, 0.01, 0.02);
  const auto x = solver::place_in_region(sim, std::vector<double>(200, r), lo, hi, 3, 1, true);
  ASSERT_EQ(x.size(), 200u);
  std::map<long, int> per_level;
  double closest = HUGE_VAL;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double level = (x[i].z() - lo.z() - r) / a;
    EXPECT_NEAR(level, std::round(level), 0.01 * d / a + 1e-12) << i;
    ++per_level[std::lround(level)];
    EXPECT_TRUE((x[i].array() >= (lo.array() + r)).all() &&
                (x[i].array() <= (hi.array() - r)).all())
        << i;
    for (std::size_t j = 0; j < i; ++j) closest = std::min(closest, (x[i] - x[j]).norm() - d);
  }
  EXPECT_EQ(per_level, (std::map<long, int>{{0, 81}, {1, 81}, {2, 38}}));
  EXPECT_GE(closest, 0.05 * d - 2 * 0.01 * d - 1e-15);
  EXPECT_LE(closest, 0.05 * d + 2 * 0.01 * d);
  EXPECT_EQ(solver::place_in_region(sim, std::vector<double>(800, r), lo, hi, 3, 1, true).size(),
            729u);
  // Sites taken by particles already in the scene, or cut by a wall, are skipped.
  solver::Simulation walled(config(), {}, {plane({0, 0, 0.0105}, {0, 0, 1})});
  const auto y = solver::place_in_region(walled, std::vector<double>(800, r), lo, hi, 3, 1, true);
  EXPECT_EQ(y.size(), 648u);  // the lowest level (centres at 0.0105 ± jitter) is in the wall
  for (const auto& yi : y) EXPECT_GE(yi.z() - 0.0105, r);
}

// [fill] damping: the filling runs with its own global damping, and the solver's comes back
// when the filling ends, also in a run resumed from a checkpoint taken while filling.
TEST(LayeredFilling, FillDampingEndsWithTheFilling) {
  FillSpec f = spec();
  f.layers = 1;
  f.count = 80;
  f.damping = 0.6;
  const auto fp = solver::fill_particles(f, 0);
  solver::Simulation a(config(), fp.particles, box());  // solver damping 0.3
  solver::LayeredFilling fa(f, 0, fp.layers, 1000);
  fa.start(a);
  EXPECT_EQ(a.config().damping, 0.6);
  for (int s = 0; s < 3000; ++s) {
    fa.control(a);
    a.step();
  }
  ASSERT_FALSE(fa.finished(a));
  const auto ck = std::filesystem::temp_directory_path() / "gs_fill_damping_ck.bin";
  a.save_checkpoint(ck, fa.save_state());
  auto c = config();
  c.damping = 0.0;
  solver::Simulation b(c, fp.particles, box());
  solver::LayeredFilling fb(f, 0, fp.layers, 1000);
  fb.load_state(b.load_checkpoint(ck));
  std::filesystem::remove(ck);
  EXPECT_EQ(b.config().damping, 0.6);  // the checkpoint's, while filling
  for (auto* run : {&a, &b}) {
    auto& fill = run == &a ? fa : fb;
    while (!fill.finished(*run)) {
      fill.control(*run);
      if (fill.finished(*run)) break;
      run->step();
      ASSERT_LT(run->step_count(), 300000);
    }
    EXPECT_EQ(run->config().damping, 0.3);  // the scene's solver damping, back
  }
  EXPECT_EQ(a.step_count(), b.step_count());
}
