// Gaussian coarse-graining: conservation of mass, volume and the contact tensor on the grid,
// uniform fields on a uniform lattice, velocity and kinetic stress of a rigid translation,
// 2D frames and slab (depth-averaged) grids, thread-count independence.
#include <gtest/gtest.h>
#include <omp.h>

#include <numbers>

#include "coarse_graining.hpp"
#include "packing_util.hpp"

namespace ga = gs::analysis;

namespace {

constexpr double kPi = std::numbers::pi;

TEST(CoarseGraining, ConservesMassVolumeAndContactTensor) {
  const double sp = 1e-3;
  const gs::Frame f = gs::test::random_packing(8, sp, 9);
  const auto b = ga::contact_branches(f);
  ga::RevGridSpec spec;
  spec.cell = 0.0;
  spec.step = 0.45 * sp;
  const double w = 0.6 * sp, margin = 4 * w + 2 * sp;  // the grid covers every stencil
  spec.region = {Eigen::Vector3d::Constant(-margin), Eigen::Vector3d::Constant(8 * sp + margin)};
  const auto g = ga::make_point_grid(f, spec);
  const auto cf = ga::coarse_grain(f, b, g, {w, 2650.0});
  double mass = 0.0, vol = 0.0;
  Eigen::Matrix3d lf = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mom = Eigen::Vector3d::Zero();
  for (const auto& p : f.particles) {
    mass += p.mass;
    vol += 4.0 / 3.0 * kPi * std::pow(p.radius, 3);
    mom += p.mass * p.velocity;
  }
  for (const auto& br : b.branches) lf += br.branch * br.force.transpose();
  const double cell = std::pow(g.step, 3);
  double m = 0.0, v = 0.0;
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::size_t q = 0; q < g.count(); ++q) {
    m += cf.density[q] * cell;
    v += cf.solid_fraction[q] * cell;
    s += cf.contact_stress[q] * cell;
    if (cf.density[q] > 0) p += cf.density[q] * cf.velocity[q] * cell;
  }
  EXPECT_NEAR(m, mass, 1e-12 * mass);
  EXPECT_NEAR(v, vol, 1e-12 * vol);
  EXPECT_NEAR((s - lf).norm(), 0.0, 1e-12 * lf.norm());
  EXPECT_NEAR((p - mom).norm(), 0.0, 1e-12 * mass);
}

TEST(CoarseGraining, UniformLatticeGivesUniformFields) {
  // Simple-cubic lattice (spacing a = 2r), isotropic contact forces F, all spheres moving with
  // the same velocity. Far from the lattice edges (> 4 w + a) every point must see
  // rho = m / a^3, nu = pi / 6, V = v0, kinetic stress 0 and contact stress F / a^2 I. The
  // only departure from uniformity is the ripple of the lattice sum of the kernel, cut off at
  // 4 w: O(phi(4) (a / 2 pi w)^2) ~ 1e-4 for w = a (the untruncated Gaussian's e^(-2 pi^2) is
  // negligible).
  const double r = 0.5e-3, a = 2 * r, force = 2.0;
  gs::Frame f = gs::test::cubic_lattice(20, r, force, false);
  const Eigen::Vector3d v0(0.1, -0.2, 0.05);
  for (auto& p : f.particles) {
    p.mass = 1e-6;
    p.velocity = v0;
  }
  const auto b = ga::contact_branches(f);
  ga::RevGridSpec spec;
  spec.cell = 0.0;
  spec.step = 0.7 * a;
  const double w = a;
  spec.region = {Eigen::Vector3d::Constant(7.1 * a), Eigen::Vector3d::Constant(11.9 * a)};
  const auto g = ga::make_point_grid(f, spec);
  const auto cf = ga::coarse_grain(f, b, g, {w, 2650.0});
  const double rho = 1e-6 / (a * a * a), p = force / (a * a);
  double worst = 0.0;
  for (std::size_t q = 0; q < g.count(); ++q) {
    worst = std::max(worst, std::abs(cf.density[q] / rho - 1.0));
    EXPECT_NEAR(cf.density[q], rho, 2e-4 * rho) << q;
    EXPECT_NEAR(cf.solid_fraction[q], kPi / 6, 2e-4 * kPi / 6) << q;
    EXPECT_NEAR((cf.velocity[q] - v0).norm(), 0.0, 1e-14 * v0.norm()) << q;  // round-off
    EXPECT_NEAR(cf.kinetic_stress[q].norm(), 0.0, 1e-12 * rho * v0.squaredNorm()) << q;
    EXPECT_NEAR((cf.contact_stress[q] - p * Eigen::Matrix3d::Identity()).norm(), 0.0, 2e-4 * p)
        << q;
  }
  RecordProperty("max_relative_density_ripple", std::to_string(worst));
  std::printf("uniform lattice: largest relative density ripple %.2e\n", worst);
}

TEST(CoarseGraining, KineticStressOfRandomVelocities) {
  // Two spheres at the same place with velocities +u and -u: V = 0 and the kinetic stress is
  // phi * 2 m u u (compression positive).
  gs::Frame f;
  for (int s = 0; s < 2; ++s) {
    gs::Particle p;
    p.id = s;
    p.radius = 1e-3;
    p.mass = 2e-3;
    p.position = Eigen::Vector3d(5e-3, 5e-3, 5e-3);
    p.velocity = (s ? -1.0 : 1.0) * Eigen::Vector3d(0.3, 0.1, -0.2);
    f.particles.push_back(p);
  }
  ga::RevGridSpec spec;
  spec.cell = 0.0;
  spec.step = 1e-3;
  spec.region = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(10e-3)};
  const auto g = ga::make_point_grid(f, spec);
  const auto cf = ga::coarse_grain(f, ga::contact_branches(f), g, {1e-3, 2650.0});
  const Eigen::Vector3d u(0.3, 0.1, -0.2);
  for (std::size_t q = 0; q < g.count(); ++q) {
    if (cf.density[q] == 0) continue;
    EXPECT_NEAR(cf.velocity[q].norm(), 0.0, 1e-15);
    const Eigen::Matrix3d expect = cf.density[q] * u * u.transpose();  // rho = phi 2 m
    EXPECT_NEAR((cf.kinetic_stress[q] - expect).norm(), 0.0, 1e-12 * expect.norm() + 1e-30);
  }
}

TEST(CoarseGraining, TwoDFrameAndSlabConserve) {
  const double sp = 1e-3, w = 0.5 * sp, t = 3 * sp;
  gs::Frame f = gs::test::random_packing(8, sp, 4);
  // Slab y = 4 mm +- 1.5 mm, depth-averaged fields: the areal sum times T is the mass weighted
  // by the part of each kernel inside the slab, Phi((T/2 - z)/w) - Phi((-T/2 - z)/w).
  const auto b = ga::contact_branches(f);
  ga::RevGridSpec spec;
  spec.cell = 0.0;
  spec.step = 0.5 * sp;
  spec.slab = ga::Slab{Eigen::Vector3d(4, 4, 4) * sp, Eigen::Vector3d::UnitY(),
                       Eigen::Vector3d::UnitX(), t};
  spec.region = {Eigen::Vector3d::Constant(-7 * sp), Eigen::Vector3d::Constant(7 * sp)};
  const auto g = ga::make_point_grid(f, spec);
  const auto cf = ga::coarse_grain(f, b, g, {w, 2650.0});
  double m = 0.0, expect = 0.0;
  for (std::size_t q = 0; q < g.count(); ++q) m += cf.density[q] * g.step * g.step * t;
  auto cdf = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  for (const auto& p : f.particles) {
    const double z = g.local(p.position).z();
    if (std::abs(z) > 0.5 * t + 4 * w) continue;
    expect += p.mass * (cdf((0.5 * t - z) / w) - cdf((-0.5 * t - z) / w));
  }
  EXPECT_NEAR(m, expect, 1e-12 * expect);
  // 2D frame: areal density; the grid covers every stencil, so the disc masses are conserved.
  f.two_d = true;
  for (auto& p : f.particles) p.position.z() = 0.0;
  spec.slab.reset();
  spec.region = {Eigen::Vector3d::Constant(-3 * sp), Eigen::Vector3d::Constant(11 * sp)};
  const auto g2 = ga::make_point_grid(f, spec);
  const auto c2 = ga::coarse_grain(f, ga::contact_branches(f), g2, {w, 2650.0});
  double m2 = 0.0, mass = 0.0;
  for (std::size_t q = 0; q < g2.count(); ++q) m2 += c2.density[q] * g2.step * g2.step;
  for (const auto& p : f.particles) mass += p.mass;
  EXPECT_NEAR(m2, mass, 1e-12 * mass);
}

TEST(CoarseGraining, ThreadCountIndependentAndRejectsBadWidth) {
  const gs::Frame f = gs::test::random_packing(7, 1e-3, 2);
  const auto b = ga::contact_branches(f);
  ga::RevGridSpec spec;
  spec.cell = 0.0;
  spec.step = 0.3e-3;
  const auto g = ga::make_point_grid(f, spec);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto one = ga::coarse_grain(f, b, g, {0.5e-3, 2650.0});
  omp_set_num_threads(3);
  const auto three = ga::coarse_grain(f, b, g, {0.5e-3, 2650.0});
  omp_set_num_threads(threads);
  for (std::size_t q = 0; q < g.count(); ++q) {
    EXPECT_EQ(one.density[q], three.density[q]);
    EXPECT_EQ(one.contact_stress[q], three.contact_stress[q]);
  }
  EXPECT_THROW(ga::coarse_grain(f, b, g, {0.0, 2650.0}), std::invalid_argument);
  EXPECT_THROW(ga::coarse_grain(f, b, g, {std::nan(""), 2650.0}), std::invalid_argument);
  EXPECT_THROW(ga::coarse_grain(f, b, g, {1.0, 2650.0}), std::invalid_argument);  // too wide
}

}  // namespace
