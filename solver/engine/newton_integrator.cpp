#include "newton_integrator.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "simd_level.hpp"

namespace gs::solver {

namespace {

/// Particles of one batch, one array per component (structure of arrays), so that the
/// compiler vectorises the update across particles; the divisions and square roots of the
/// update then run four at a time.
struct ParticleBatch {
  static constexpr int kLanes = 32;
  // clang-format off
  enum Field : int {
    // inputs (velocities and orientation are updated in place; positions and rotation
    // vectors are advanced by the caller from the new velocities)
    VX, VY, VZ, WX, WY, WZ, FX, FY, FZ, TX, TY, TZ,
    EX, EY, EZ,  // external force
    QW, QX, QY, QZ,
    MASS, INERTIA, FIXED, ROT_BLOCKED,
    // outputs: this particle's terms of the step's sums, the finite check of the velocity,
    // and 1 where the orientation is updated again in scalar code (a rotation too large for
    // the series, or a quaternion that was not a unit one)
    GRAVITY_POWER, EXTERNAL_POWER, DAMPING, FINITE, LARGE_ANGLE,
    kFields
  };
  // clang-format on

  alignas(64) double v[kFields][kLanes];
};

// YADE's NewtonIntegrator on lanes [0, count): Cundall damping per component, leapfrog, and
// the rotation of the orientation by |ω|·dt about ω from the half-angle series.
[[gnu::always_inline]] inline void integrate_lanes(ParticleBatch& b, int count, V3 g,
                                                   double damping, double dt) {
  using F = ParticleBatch::Field;
  auto in3 = [&](F f, int j) { return V3(b.v[f][j], b.v[f + 1][j], b.v[f + 2][j]); };
  auto out3 = [&](F f, int j, const V3& x) {
    b.v[f][j] = x.x;
    b.v[f + 1][j] = x.y;
    b.v[f + 2][j] = x.z;
  };
  for (int j = 0; j < count; ++j) {
    const bool free_lane = b.v[F::FIXED][j] == 0, spin = b.v[F::ROT_BLOCKED][j] == 0;
    const double m = b.v[F::MASS][j];
    const V3 vel0 = in3(F::VX, j), angvel0 = in3(F::WX, j);
    const V3 force = in3(F::FX, j), torque = in3(F::TX, j);
    b.v[F::GRAVITY_POWER][j] = free_lane ? m * dot(g, vel0) : 0.0;
    b.v[F::EXTERNAL_POWER][j] = free_lane ? dot(in3(F::EX, j), vel0) : 0.0;
    const double damp = dot(abs(vel0), abs(force + m * g)) * damping * dt +
                        dot(abs(angvel0), abs(torque)) * damping * dt;
    b.v[F::DAMPING][j] = free_lane & (damping != 0) ? damp : 0.0;
    V3 lin = force / m + g;
    lin = {lin.x * cundall_factor(damping, dt, vel0.x, lin.x),
           lin.y * cundall_factor(damping, dt, vel0.y, lin.y),
           lin.z * cundall_factor(damping, dt, vel0.z, lin.z)};
    const V3 vel = select(free_lane, vel0 + dt * lin, vel0);
    V3 ang = torque / b.v[F::INERTIA][j];
    ang = {ang.x * cundall_factor(damping, dt, angvel0.x, ang.x),
           ang.y * cundall_factor(damping, dt, angvel0.y, ang.y),
           ang.z * cundall_factor(damping, dt, angvel0.z, ang.z)};
    const V3 angvel = select(free_lane & spin, angvel0 + dt * ang, angvel0);
    out3(F::VX, j, vel);
    out3(F::WX, j, angvel);
    b.v[F::FINITE][j] = squared_norm(vel) < HUGE_VAL ? 1.0 : 0.0;
    // Orientation: q ← (cos h, sin h·ω/|ω|)·q with h = |ω|·dt/2 (YADE's
    // leapfrogSphericalRotate). Below h = 1e-3 rad the series is exact to double precision.
    const double a2 = squared_norm(angvel);
    const double h2 = 0.25 * dt * dt * a2;
    b.v[F::LARGE_ANGLE][j] = h2 < 1e-6 ? 0.0 : 1.0;
    const double s_over_a = 0.5 * dt * (1 - h2 * (1.0 / 6) * (1 - h2 * (1.0 / 20)));
    const double c = 1 - h2 * 0.5 * (1 - h2 * (1.0 / 12));
    const V3 u = angvel * s_over_a;
    const double qw = b.v[F::QW][j], qx = b.v[F::QX][j], qy = b.v[F::QY][j], qz = b.v[F::QZ][j];
    const bool turn = a2 != 0;
    double nw = turn ? c * qw - u.x * qx - u.y * qy - u.z * qz : qw;
    double nx = turn ? c * qx + u.x * qw + u.y * qz - u.z * qy : qx;
    double ny = turn ? c * qy + u.y * qw + u.z * qx - u.x * qz : qy;
    double nz = turn ? c * qz + u.z * qw + u.x * qy - u.y * qx : qz;
    // Renormalised by one Newton step for 1/|q| (|q|² is within 1e-8 of 1 after a step from
    // a unit quaternion; error below 1e-16); other lanes are flagged for the exact path.
    const double q2 = nw * nw + nx * nx + ny * ny + nz * nz;
    const double scale = 1.5 - 0.5 * q2;
    b.v[F::QW][j] = nw * scale;
    b.v[F::QX][j] = nx * scale;
    b.v[F::QY][j] = ny * scale;
    b.v[F::QZ][j] = nz * scale;
    if (!(std::abs(q2 - 1) < 1e-8)) b.v[F::LARGE_ANGLE][j] = 1.0;
  }
}

// The integrator compiled for each instruction set (docs/physics.md: the same bits from each).
void integrate_generic(ParticleBatch& b, int count, V3 g, double damping, double dt) {
  integrate_lanes(b, count, g, damping, dt);
}

#if GS_SIMD_X86
__attribute__((target("avx2"))) void integrate_avx2(ParticleBatch& b, int count, V3 g,
                                                    double damping, double dt) {
  integrate_lanes(b, count, g, damping, dt);
}

__attribute__((target("avx512f"))) void integrate_avx512(ParticleBatch& b, int count, V3 g,
                                                         double damping, double dt) {
  integrate_lanes(b, count, g, damping, dt);
}
#endif

void integrate_batch(ParticleBatch& b, int count, V3 g, double damping, double dt) {
#if GS_SIMD_X86
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return integrate_avx512(b, count, g, damping, dt);
    case SimdLevel::Avx2:
      return integrate_avx2(b, count, g, damping, dt);
    case SimdLevel::Generic:
      break;
  }
#endif
  integrate_generic(b, count, g, damping, dt);
}

}  // namespace

IntegrationSums integrate_particles(ParticleState& p, std::size_t begin, std::size_t end,
                                    const Eigen::Vector3d& gravity, double damping, double dt) {
  using F = ParticleBatch::Field;
  IntegrationSums sums;
  ParticleBatch b;
  for (std::size_t i0 = begin; i0 < end; i0 += ParticleBatch::kLanes) {
    const int count = static_cast<int>(std::min<std::size_t>(ParticleBatch::kLanes, end - i0));
    auto put = [&](F f, int j, const Eigen::Vector3d& x) {
      b.v[f][j] = x[0];
      b.v[f + 1][j] = x[1];
      b.v[f + 2][j] = x[2];
    };
    for (int j = 0; j < count; ++j) {
      const std::size_t i = i0 + static_cast<std::size_t>(j);
      put(F::VX, j, p.vel[i]);
      put(F::WX, j, p.angvel[i]);
      put(F::FX, j, p.force[i]);
      put(F::TX, j, p.torque[i]);
      put(F::EX, j, p.external_force[i]);
      b.v[F::QW][j] = p.ori[i].w();
      b.v[F::QX][j] = p.ori[i].x();
      b.v[F::QY][j] = p.ori[i].y();
      b.v[F::QZ][j] = p.ori[i].z();
      b.v[F::MASS][j] = p.mass[i];
      b.v[F::INERTIA][j] = p.inertia[i];
      b.v[F::FIXED][j] = p.fixed[i];
      b.v[F::ROT_BLOCKED][j] = p.rot_blocked[i];
    }
    integrate_batch(b, count, V3(gravity), damping, dt);
    auto get = [&](F f, int j) { return V3(b.v[f][j], b.v[f + 1][j], b.v[f + 2][j]); };
    for (int j = 0; j < count; ++j) {
      const std::size_t i = i0 + static_cast<std::size_t>(j);
      sums.gravity_power += b.v[F::GRAVITY_POWER][j];
      sums.external_power += b.v[F::EXTERNAL_POWER][j];
      sums.damping += b.v[F::DAMPING][j];
      const V3 vel = get(F::VX, j), angvel = get(F::WX, j);
      vel.store(p.vel[i]);
      angvel.store(p.angvel[i]);
      // Position and rotation vector here rather than through the batch (fewer copies).
      const V3 pos = V3(p.pos[i]) + vel * dt;
      pos.store(p.pos[i]);
      add_to(p.rot[i], angvel * dt);
      sums.finite = sums.finite && b.v[F::FINITE][j] != 0 && squared_norm(pos) < HUGE_VAL;
      if (b.v[F::LARGE_ANGLE][j] == 0) {
        p.ori[i] = Eigen::Quaterniond(b.v[F::QW][j], b.v[F::QX][j], b.v[F::QY][j], b.v[F::QZ][j]);
        continue;
      }
      // A large rotation in one step, or an orientation that was not a unit quaternion.
      const Eigen::Vector3d w = p.angvel[i];
      const double a = w.norm();
      if (a > 0) p.ori[i] = Eigen::Quaterniond(Eigen::AngleAxisd(a * dt, w / a)) * p.ori[i];
      p.ori[i].normalize();
    }
  }
  return sums;
}

}  // namespace gs::solver
