// Specimen generation and the flexible membrane: exact answers (volumes, force balance,
// distribution moments) on small synthetic configurations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cuboid_walls.hpp"
#include "flexible_membrane.hpp"
#include "loading_programme.hpp"
#include "specimen_generation.hpp"
#include "specimen_preparation.hpp"

namespace gs::solver {
namespace {

TEST(SpecimenGeneration, UniformVariatesAreReproducibleAndInRange) {
  std::mt19937_64 a(7), b(7);
  for (int i = 0; i < 1000; ++i) {
    const double u = uniform01(a);
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    ASSERT_EQ(u, uniform01(b));
  }
}

TEST(SpecimenGeneration, UniformDistributionMomentsByNumber) {
  std::mt19937_64 rng(1);
  const SizeSpec s{0.002, 0.006, SizeDistribution::Uniform};
  const int n = 40000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double d = draw_diameter(s, rng);
    ASSERT_GE(d, s.dmin_m);
    ASSERT_LE(d, s.dmax_m);
    sum += d;
    sum2 += d * d;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  const double sd = (s.dmax_m - s.dmin_m) / std::sqrt(12.0);
  EXPECT_NEAR(mean, 0.004, 4 * sd / std::sqrt(n));  // 4 standard errors
  EXPECT_NEAR(std::sqrt(var), sd, 0.02 * sd);
}

TEST(SpecimenGeneration, LinearGradingCurveByMass) {
  // Mass fraction finer than d grows linearly from dmin to dmax: at the quartiles of the
  // diameter range it is 1/4, 1/2, 3/4 (d50 = (dmin + dmax)/2, seed 000 §3).
  std::mt19937_64 rng(3);
  const SizeSpec s{0.00125, 0.00375, SizeDistribution::Linear};
  const int n = 200000;
  std::vector<double> d(n);
  double total = 0;
  for (auto& x : d) {
    x = draw_diameter(s, rng);
    total += x * x * x;
  }
  for (const double q : {0.25, 0.5, 0.75}) {
    const double cut = s.dmin_m + q * (s.dmax_m - s.dmin_m);
    double finer = 0;
    for (const double x : d)
      if (x < cut) finer += x * x * x;
    EXPECT_NEAR(finer / total, q, 0.01) << "quartile " << q;
  }
}

TEST(SpecimenGeneration, DiameterListReachesTheSolidVolumeMinimally) {
  std::mt19937_64 rng(5);
  const SizeSpec s{0.002, 0.004, SizeDistribution::Uniform};
  const double target = 2e-6;
  const auto d = draw_diameters(s, target, rng);
  double v = 0, vmin_last = 1e300;
  for (const double x : d) {
    v += M_PI / 6 * x * x * x;
    vmin_last = std::min(vmin_last, M_PI / 6 * x * x * x);
  }
  EXPECT_GE(v, target);
  EXPECT_LT(v - M_PI / 6 * std::pow(s.dmax_m, 3), target);  // one sphere fewer falls short
  EXPECT_TRUE(std::is_sorted(d.begin(), d.end(), std::greater<>()));
}

TEST(SpecimenGeneration, RandomPackingHasNoOverlapAndStaysInTheBox) {
  std::mt19937_64 rng(11);
  const SizeSpec s{0.001, 0.003, SizeDistribution::Uniform};
  const Eigen::Vector3d lo(0, 0, 0), hi(0.02, 0.015, 0.03);
  const auto d = draw_diameters(s, 0.3 * (hi - lo).prod(), rng);
  const auto p = random_sequential_packing(d, lo, hi, rng);
  ASSERT_EQ(p.size(), d.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(p[i].id, static_cast<std::int64_t>(i));
    EXPECT_DOUBLE_EQ(2 * p[i].radius, d[i]);
    EXPECT_TRUE(((p[i].position.array() - p[i].radius) >= lo.array()).all());
    EXPECT_TRUE(((p[i].position.array() + p[i].radius) <= hi.array()).all());
    for (std::size_t j = 0; j < i; ++j)
      ASSERT_GE((p[i].position - p[j].position).norm(), p[i].radius + p[j].radius)
          << "spheres " << i << " and " << j << " overlap";
  }
  // Same seed, same packing; another seed, another packing.
  std::mt19937_64 again(11), other(12);
  const auto d2 = draw_diameters(s, 0.3 * (hi - lo).prod(), again);
  const auto p2 = random_sequential_packing(d2, lo, hi, again);
  ASSERT_EQ(p2.size(), p.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_EQ(p2[i].position, p[i].position);
  const auto d3 = draw_diameters(s, 0.3 * (hi - lo).prod(), other);
  EXPECT_NE(random_sequential_packing(d3, lo, hi, other)[0].position, p[0].position);
}

TEST(SpecimenGeneration, OverfullBoxIsAClearError) {
  std::mt19937_64 rng(1);
  const std::vector<double> d(200, 0.002);  // 0.84 solid fraction of the box below
  try {
    random_sequential_packing(d, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.01), rng,
                              200);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("found no free place"), std::string::npos);
  }
  EXPECT_THROW(random_sequential_packing({0.02}, Eigen::Vector3d::Zero(),
                                         Eigen::Vector3d::Constant(0.01), rng),
               std::invalid_argument);
}

TEST(SpecimenGeneration, BoxVoidRatioIsExactForCutSpheres) {
  // One sphere of radius r centred on a corner of the box: an eighth of it is inside.
  ParticleState p;
  p.pos = {Eigen::Vector3d::Zero()};
  p.radius = {0.5};
  const double e = box_void_ratio(p, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(2.0));
  EXPECT_NEAR(e, 8.0 / (M_PI / 6 * 0.125) - 1, 1e-12);
  // Centred on a face: half inside.
  p.pos = {Eigen::Vector3d(1, 1, 0)};
  EXPECT_NEAR(box_void_ratio(p, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(2.0)),
              8.0 / (2.0 / 3 * M_PI * 0.125) - 1, 1e-12);
}

ParticleState state_of(const std::vector<std::pair<Eigen::Vector3d, double>>& spheres) {
  ParticleState p;
  for (const auto& [x, r] : spheres) {
    p.pos.push_back(x);
    p.radius.push_back(r);
  }
  return p;
}

TEST(FlexibleMembrane, LoadsBalanceThePressureOnAFlatFace) {
  // A simple-cubic block of 5 x 4 x 6 spheres: every ray hits the outer layers, the loads sum
  // to σ·A along ±x exactly, and only the two outer layers are loaded.
  std::vector<std::pair<Eigen::Vector3d, double>> s;
  const double r = 0.001;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 6; ++k) s.push_back({Eigen::Vector3d(i, j, k) * 2 * r, r});
  const ParticleState p = state_of(s);
  MembraneSpec spec{1e5, 0.25 * r, r};
  // Span: the block's y and z extent, shrunk so every ray crosses a sphere (no gaps at the
  // lattice's corners are hit: rays through a corner between four discs would miss).
  const auto m = membrane_loads(p, -r, 7 * r, -r, 11 * r, spec);
  const double area = 8 * r * 12 * r;
  EXPECT_GT(m.missed_rays, 0u);  // rays through the gaps between discs miss
  const double hit_area =
      static_cast<double>(m.ny * m.nz - static_cast<int>(m.missed_rays)) * m.bin_area_m2;
  EXPECT_NEAR(m.ny * m.nz * m.bin_area_m2, area, 1e-18);
  EXPECT_NEAR(m.total_minus.x(), spec.pressure_Pa * hit_area, 1e-9);
  EXPECT_NEAR(m.total_plus.x(), -spec.pressure_Pa * hit_area, 1e-9);
  for (const auto& f : m.force) EXPECT_TRUE(f.allFinite());
  for (const auto i : m.particle) {
    const double x = p.pos[i].x();
    EXPECT_TRUE(std::abs(x) < 1e-12 || std::abs(x - 8 * r) < 1e-12) << "interior sphere loaded";
  }
}

TEST(FlexibleMembrane, VolumeBetweenTheFacesOfOneSphere) {
  // The rays through one sphere measure its volume: Σ 2·sqrt(r² − ρ²)·ΔyΔz → 4/3·π·r³ as the
  // rays get finer (midpoint rule, error O(bin^1.5) from the rim).
  const ParticleState p = state_of({{Eigen::Vector3d(0.3, 0.5, 0.5), 0.25}});
  double last_error = 1;
  for (const double bin : {0.05, 0.02, 0.005}) {
    const auto m = membrane_loads(p, 0, 1, 0, 1, {1.0, bin, bin});
    const double error = std::abs(m.volume_m3 / (4.0 / 3 * M_PI * std::pow(0.25, 3)) - 1);
    EXPECT_LT(error, last_error);
    last_error = error;
  }
  EXPECT_LT(last_error, 2e-3);
}

TEST(FlexibleMembrane, InclinedFaceGetsTheInclinedPressure) {
  // One small sphere on each ray, its outermost point on the plane x = x0 + s·z (x− face) and
  // x = x1 + s·z (x+ face): slopes are exact, so the loads sum to σA·(1, 0, −s) and
  // σA·(−1, 0, s).
  const double s = 0.3, bin = 0.01, r = 0.002;
  std::vector<std::pair<Eigen::Vector3d, double>> spheres;
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 6; ++j) {
      const double y = (j + 0.5) * bin, z = (k + 0.5) * bin;
      spheres.push_back({{0.0 + s * z + r, y, z}, r});
      spheres.push_back({{0.2 + s * z - r, y, z}, r});
    }
  const auto m = membrane_loads(state_of(spheres), 0, 0.06, 0, 0.1, {2e5, bin, bin});
  const double force = 2e5 * 0.06 * 0.1;
  EXPECT_EQ(m.missed_rays, 0u);
  EXPECT_NEAR(m.total_minus.x(), force, 1e-9 * force);
  EXPECT_NEAR(m.total_minus.z(), -s * force, 1e-9 * force);
  EXPECT_NEAR(m.total_minus.y(), 0.0, 1e-9 * force);
  EXPECT_NEAR(m.total_plus.x(), -force, 1e-9 * force);
  EXPECT_NEAR(m.total_plus.z(), s * force, 1e-9 * force);
  EXPECT_NEAR(m.volume_m3, 0.2 * 0.06 * 0.1, 1e-12);  // the faces are 0.2 apart on every ray
  EXPECT_NEAR(m.mean_width_m, 0.2, 1e-12);
}

TEST(ProgrammeState, RoundTripsDoublesExactly) {
  ProgrammeState a;
  a.set("x", 0.1 + 0.2);
  a.set("n", std::int64_t{-42});
  a.set("tiny", 5e-324);
  const ProgrammeState b(a.text());
  EXPECT_EQ(b.number("x"), 0.1 + 0.2);
  EXPECT_EQ(b.integer("n"), -42);
  EXPECT_EQ(b.number("tiny"), 5e-324);
  EXPECT_THROW(b.number("missing"), std::invalid_argument);
}

}  // namespace
}  // namespace gs::solver

namespace gs::solver {
namespace {

TEST(SpecimenPreparation, DepositionSettlesUnderGravityThenRestoresIt) {
  // Spheres dropped in a box of planes: deposition ends when the pile is at rest, the pile
  // settles with the test's friction, and at the end the scene's gravity (none) is restored.
  std::mt19937_64 rng(2);
  const SizeSpec sizes{0.002, 0.003, SizeDistribution::Uniform};
  const Eigen::Vector3d lo(0, 0, 0), hi(0.012, 0.012, 0.06);
  auto particles = random_sequential_packing(draw_diameters(sizes, 2.5e-7, rng), lo, hi, rng);
  SimulationConfig cfg;
  cfg.material = {1e7, 0.3, 20.0, 2600.0, 0.0, -1.0, RollingRadius::Min};
  cfg.damping = 0.3;
  cfg.dt = 0.3 * pwave_timestep({0.001}, 2600.0, 1e7);
  Simulation sim(cfg, particles, cuboid_planes(lo, hi, 20.0));
  PreparationSpec spec;
  spec.deposition = true;
  spec.pressure_Pa = 0;
  spec.stage_steps = 200;
  spec.check_every = 50;
  spec.unbalanced_force = 0.05;
  spec.kinetic_ratio = 1e-2;
  spec.max_steps = 400000;
  SpecimenPreparation prep(spec, cuboid_gauge(), 20.0);
  double z0 = 0;
  for (const auto& x : sim.particles().pos) z0 += x.z();
  prep.start(sim);
  EXPECT_EQ(prep.stage(), SpecimenPreparation::kDeposition);
  EXPECT_EQ(sim.config().gravity, Eigen::Vector3d(0, 0, -9.81));
  while (!prep.finished(sim)) {
    prep.control(sim);
    if (prep.finished(sim)) break;
    sim.step();
  }
  EXPECT_LT(sim.step_count(), spec.max_steps) << "never came to rest";
  EXPECT_EQ(sim.config().gravity, Eigen::Vector3d::Zero());
  double z1 = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) {
    z1 += sim.particles().pos[i].z();
    EXPECT_GT(sim.particles().pos[i].z(), 0.5 * sim.particles().radius[i]);  // above the floor
  }
  EXPECT_LT(z1, 0.5 * z0);  // the cloud fell: its mean height more than halved
}

}  // namespace
}  // namespace gs::solver
