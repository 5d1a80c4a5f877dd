// Seed 003's stress servo (§2.2.2, Eqs 14-16) on a packing inside the n = 8 tangential
// polyhedron: it reaches and holds an isotropic p and then a deviatoric state with σ1 turned in
// the x-z plane (label slow: 48 000 steps of 1 300 spheres, about 30 s).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <vector>

#include "simulation.hpp"
#include "tangential_polyhedron.hpp"

using gs::solver::TangentialPolyhedron;

TEST(TangentialPolyhedron, StressServoHoldsMeanStressDeviatorAndDirections) {
  // About 1 300 spheres (r = 0.48 mm, jittered cubic sites 1 mm apart) in the n = 8 polyhedron
  // of R = 6.6 mm, frictional, strongly damped (seed 003's quasi-static 0.7); the servo of
  // Eqs 15-16 with ν = 0.25 first to p = 100 kPa isotropic, then to η = 0.5, b = 0.5 with σ1 at
  // 30° from x in the x-z plane: it reaches and holds them (the stress of Eq 14 from the walls).
  const double R = 6.6e-3, r = 0.48e-3, a = 0.98e-3;
  const TangentialPolyhedron P = gs::solver::tangential_polyhedron(8, R);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(-0.02e-3, 0.02e-3);
  std::vector<gs::Particle> ps;
  for (int i = -8; i <= 8; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -8; k <= 8; ++k) {
        const Eigen::Vector3d x =
            a * Eigen::Vector3d(i, j, k) + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
        if (!gs::solver::inside_polyhedron(P, x, 1.05 * r)) continue;
        gs::Particle q;
        q.id = static_cast<std::int64_t>(ps.size());
        q.position = x;
        q.radius = r;
        ps.push_back(q);
      }
  ASSERT_GT(ps.size(), 1000u);
  gs::solver::SimulationConfig cfg;
  cfg.material.young_ec = 1e8;
  cfg.material.stiffness_ratio = 0.3;
  cfg.material.friction_deg = 30;
  cfg.material.density = 2700;
  cfg.damping = 0.7;
  cfg.dt = 4e-7;
  gs::solver::Simulation sim(cfg, ps, gs::solver::polyhedron_walls(P));
  gs::solver::PolyhedronServo servo;
  servo.E = gs::solver::servo_modulus(cfg.material.young_ec * r, r, 1.1589 * R);
  servo.max_strain_step = 1e-5;
  const auto run_to = [&](const Eigen::Matrix3d& target, int steps) {
    for (int s = 0; s < steps; ++s) {
      gs::solver::servo_step(sim, 0, P, target, servo, cfg.dt);
      sim.step();
      if (std::getenv("GS_SERVO_TRACE") && s % 1000 == 0) {
        const Eigen::Matrix3d st = gs::solver::polyhedron_stress(sim, 0, P);
        std::printf("%d: %g %g %g %g (%zu contacts)\n", s, st(0, 0), st(1, 1), st(2, 2), st(0, 2),
                    sim.contact_count());
      }
    }
    return gs::solver::polyhedron_stress(sim, 0, P);
  };
  const double p0 = 1e5;
  const Eigen::Matrix3d iso = p0 * Eigen::Matrix3d::Identity();
  Eigen::Matrix3d s = run_to(iso, 20000);
  EXPECT_LT((s - iso).norm() / p0, 0.02) << s;
  const Eigen::Matrix3d target =
      gs::solver::principal_stress_state(p0, 0.5, 0.5, 30 * std::numbers::pi / 180);
  s = run_to(target, 20000);
  const double reached = (s - target).norm() / p0;
  EXPECT_LT(reached, 0.03) << s << "\n" << target;
  // Held: another 8 000 steps stay there and close in further (the packing creeps a little under
  // the new deviator, and the servo follows).
  s = run_to(target, 8000);
  EXPECT_LT((s - target).norm() / p0, 0.02) << s;
  EXPECT_LT((s - target).norm() / p0, reached);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(0.5 * (s + s.transpose()));
  const Eigen::Vector3d major = e.eigenvectors().col(2);
  const double angle = std::atan2(major.z(), major.x()) * 180 / std::numbers::pi;
  EXPECT_NEAR(std::remainder(angle - 30.0, 180.0), 0.0, 2.0);
  EXPECT_NEAR(std::abs(e.eigenvectors().col(1).y()), 1.0, 1e-3);  // σ2 along y
}
