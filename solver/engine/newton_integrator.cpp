#include "newton_integrator.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "domain.hpp"
#include "periodic_cell.hpp"
#include "rigid_clump.hpp"
#include "simd_level.hpp"

#if GS_SIMD_X86
#include <immintrin.h>
#endif

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

/// Clump bodies of one batch, one array per component, for integrate_clump_lanes.
struct ClumpBatch {
  static constexpr int kLanes = 16;
  // clang-format off
  enum Field : int {
    FX, FY, FZ, MX, MY, MZ,  // load (inputs)
    VX, VY, VZ, WX, WY, WZ, LX, LY, LZ, PX, PY, PZ, QW, QX, QY, QZ,  // updated in place
    MASS, IX, IY, IZ, DAMP, NORM,
    kFields
  };
  // clang-format on

  alignas(64) double v[kFields][kLanes];
};

// YADE's NewtonIntegrator for aspherical bodies (exactAsphericalRot) on lanes [0, count),
// every expression written out in the order in which Eigen evaluates the YADE expressions it
// replaces (quoted in the comments): YADE's Eigen reduces a 3-vector as x + (y + z) and a
// 4-vector as (x + y) + (z + w) (its scalar unroller splits in halves); the old Eigen version
// of this code reduced its dot products as (x + y) + z.
[[gnu::always_inline]] inline void integrate_clump_lanes(ClumpBatch& b, int count, V3 gv,
                                                         double damping, double dt) {
  using F = ClumpBatch::Field;
  const double g[3] = {gv.x, gv.y, gv.z};
  const double half_dt = dt / 2.;
  for (int j = 0; j < count; ++j) {
    const double f[3] = {b.v[F::FX][j], b.v[F::FY][j], b.v[F::FZ][j]};
    double m[3] = {b.v[F::MX][j], b.v[F::MY][j], b.v[F::MZ][j]};
    double vel[3] = {b.v[F::VX][j], b.v[F::VY][j], b.v[F::VZ][j]};
    const double angvel[3] = {b.v[F::WX][j], b.v[F::WY][j], b.v[F::WZ][j]};
    const double mass = b.v[F::MASS][j];
    // (c.vel.cwiseAbs().dot((f + c.mass * gravity).cwiseAbs()) * damping * dt) +
    // c.angvel.cwiseAbs().dot(m.cwiseAbs()) * damping * dt
    const double d_lin = (std::abs(vel[0]) * std::abs(f[0] + mass * g[0]) +
                          std::abs(vel[1]) * std::abs(f[1] + mass * g[1])) +
                         std::abs(vel[2]) * std::abs(f[2] + mass * g[2]);
    const double d_rot =
        (std::abs(angvel[0]) * std::abs(m[0]) + std::abs(angvel[1]) * std::abs(m[1])) +
        std::abs(angvel[2]) * std::abs(m[2]);
    b.v[F::DAMP][j] = damping != 0 ? (d_lin * damping * dt) + d_rot * damping * dt : 0.0;
// Translation: as for spheres (gravity in the acceleration before damping).
#pragma GCC unroll 4
    for (int k = 0; k < 3; ++k) {
      double lin = f[k] / mass + g[k];
      lin *= cundall_factor(damping, dt, vel[k], lin);
      vel[k] += dt * lin;
    }
// Rotation: first-order Cundall damping of the torque with the stored angular velocity.
#pragma GCC unroll 4
    for (int k = 0; k < 3; ++k) {
      const double s = m[k] * angvel[k];
      m[k] *= 1 - damping * static_cast<double>(static_cast<int>(s > 0) - static_cast<int>(s < 0));
    }
    // leapfrogAsphericalRotate, expression by expression. a = c.ori.conjugate()
    // .toRotationMatrix() (global -> local): Eigen's formula on (w, -x, -y, -z).
    const double q[4] = {b.v[F::QW][j], b.v[F::QX][j], b.v[F::QY][j], b.v[F::QZ][j]};
    const double cx = -q[1], cy = -q[2], cz = -q[3], cw = q[0];
    const double tx = 2 * cx, ty = 2 * cy, tz = 2 * cz;
    const double twx = tx * cw, twy = ty * cw, twz = tz * cw;
    const double txx = tx * cx, txy = ty * cx, txz = tz * cx;
    const double tyy = ty * cy, tyz = tz * cy, tzz = tz * cz;
    const double a[3][3] = {{1 - (tyy + tzz), txy - twz, txz + twy},
                            {txy + twz, 1 - (txx + tzz), tyz - twx},
                            {txz - twy, tyz + twx, 1 - (txx + tyy)}};
    const double inertia[3] = {b.v[F::IX][j], b.v[F::IY][j], b.v[F::IZ][j]};
    const double l0[3] = {b.v[F::LX][j], b.v[F::LY][j], b.v[F::LZ][j]};
    // l_n = c.angmom + dt / 2. * m; w_b_n = (a·l_n) / inertia, a row as a0 v0 + (a1 v1 + a2 v2)
    double l_n[3], w_b_n[3], angmom[3], w[3];
#pragma GCC unroll 4
    for (int k = 0; k < 3; ++k) l_n[k] = l0[k] + half_dt * m[k];
#pragma GCC unroll 4
    for (int i = 0; i < 3; ++i)
      w_b_n[i] = (a[i][0] * l_n[0] + (a[i][1] * l_n[1] + a[i][2] * l_n[2])) / inertia[i];
    // YADE's DotQ: dQ/dt = ½·Q ⊗ (0, ω); q_half = q + dq_n·(dt/2) on the coefficients
    auto dot_q = [](const double* om, const double* p, double* d) {
      d[0] = (-p[1] * om[0] - p[2] * om[1] - p[3] * om[2]) / 2;
      d[1] = (p[0] * om[0] - p[3] * om[1] + p[2] * om[2]) / 2;
      d[2] = (p[3] * om[0] + p[0] * om[1] - p[1] * om[2]) / 2;
      d[3] = (-p[2] * om[0] + p[1] * om[1] + p[0] * om[2]) / 2;
    };
    double dq[4], q_half[4], o[4];
    dot_q(w_b_n, q, dq);
#pragma GCC unroll 4
    for (int k = 0; k < 4; ++k) q_half[k] = q[k] + dq[k] * half_dt;
#pragma GCC unroll 4
    for (int k = 0; k < 3; ++k) angmom[k] = l0[k] + dt * m[k];
#pragma GCC unroll 4
    for (int i = 0; i < 3; ++i)
      w[i] = (a[i][0] * angmom[0] + (a[i][1] * angmom[1] + a[i][2] * angmom[2])) / inertia[i];
    dot_q(w, q_half, dq);
#pragma GCC unroll 4
    for (int k = 0; k < 4; ++k) o[k] = q[k] + dq[k] * dt;  // c.ori + dq_half·dt
    // c.angvel = c.ori * w_b_half before normalising (as YADE), Eigen's _transformVector:
    // uv = 2 (v × w); w + o_w uv + v × uv
    const double vx = o[1], vy = o[2], vz = o[3];
    double u0 = vy * w[2] - vz * w[1], u1 = vz * w[0] - vx * w[2], u2 = vx * w[1] - vy * w[0];
    u0 += u0;
    u1 += u1;
    u2 += u2;
    b.v[F::WX][j] = (w[0] + o[0] * u0) + (vy * u2 - vz * u1);
    b.v[F::WY][j] = (w[1] + o[0] * u1) + (vz * u0 - vx * u2);
    b.v[F::WZ][j] = (w[2] + o[0] * u2) + (vx * u1 - vy * u0);
    // normalize: |q|² as (x² + y²) + (z² + w²); the square root and the division below
    b.v[F::NORM][j] = (o[1] * o[1] + o[2] * o[2]) + (o[3] * o[3] + o[0] * o[0]);
    b.v[F::QW][j] = o[0];
    b.v[F::QX][j] = o[1];
    b.v[F::QY][j] = o[2];
    b.v[F::QZ][j] = o[3];
#pragma GCC unroll 4
    for (int k = 0; k < 3; ++k) {
      b.v[F::LX + k][j] = angmom[k];
      b.v[F::VX + k][j] = vel[k];
      b.v[F::PX + k][j] = b.v[F::PX + k][j] + dt * vel[k];  // leapfrogTranslate
    }
  }
  // (Apart: with -frounding-math GCC does not vectorise a loop with a square root.)
  for (int j = 0; j < count; ++j) b.v[F::NORM][j] = std::sqrt(b.v[F::NORM][j]);
  for (int j = 0; j < count; ++j) {
    const double n = b.v[F::NORM][j];
    b.v[F::QW][j] = b.v[F::QW][j] / n;
    b.v[F::QX][j] = b.v[F::QX][j] / n;
    b.v[F::QY][j] = b.v[F::QY][j] / n;
    b.v[F::QZ][j] = b.v[F::QZ][j] / n;
  }
}

void integrate_clumps_generic(ClumpBatch& b, int count, V3 g, double damping, double dt) {
  integrate_clump_lanes(b, count, g, damping, dt);
}

#if GS_SIMD_X86
__attribute__((target("avx2"))) void integrate_clumps_avx2(ClumpBatch& b, int count, V3 g,
                                                           double damping, double dt) {
  integrate_clump_lanes(b, count, g, damping, dt);
}

__attribute__((target("avx512f"))) void integrate_clumps_avx512(ClumpBatch& b, int count, V3 g,
                                                                double damping, double dt) {
  integrate_clump_lanes(b, count, g, damping, dt);
}
#endif

void integrate_clump_batch(ClumpBatch& b, int count, V3 g, double damping, double dt) {
#if GS_SIMD_X86
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return integrate_clumps_avx512(b, count, g, damping, dt);
    case SimdLevel::Avx2:
      return integrate_clumps_avx2(b, count, g, damping, dt);
    case SimdLevel::Generic:
      break;
  }
#endif
  integrate_clumps_generic(b, count, g, damping, dt);
}

#if GS_SIMD_X86
// The batch's gather and scatter for eight consecutive particles with AVX-512 transposes: a
// particle's 3-vectors lie one after the other (x0 y0 z0 x1 …), 24 doubles in three registers,
// turned into one register per component and back by two-source permutes. Only moves: each
// lane's arithmetic (the kernel, pos + vel·dt, rot + ω·dt) is the scalar code's, so the bits are
// those of the one-particle-at-a-time gather and scatter (docs/physics.md).
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
static_assert(sizeof(Eigen::Quaterniond) == 4 * sizeof(double));

struct Aos3 {
  __m512d a, b, c;  // (x0 y0 z0 x1 y1 z1 x2 y2), (z2 x3 y3 z3 x4 y4 z4 x5), (y5 z5 x6 … z7)
};

__attribute__((target("avx512f"))) inline void aos_to_soa(const double* src, double* x, double* y,
                                                          double* z) {
  const __m512d a = _mm512_loadu_pd(src), b = _mm512_loadu_pd(src + 8),
                c = _mm512_loadu_pd(src + 16);
  // (_mm512_set_epi64 lists the lanes from the highest down)
  const __m512d tx = _mm512_permutex2var_pd(a, _mm512_set_epi64(0, 0, 15, 12, 9, 6, 3, 0), b);
  const __m512d ty = _mm512_permutex2var_pd(a, _mm512_set_epi64(0, 0, 0, 13, 10, 7, 4, 1), b);
  const __m512d tz = _mm512_permutex2var_pd(a, _mm512_set_epi64(0, 0, 0, 14, 11, 8, 5, 2), b);
  _mm512_store_pd(x, _mm512_permutex2var_pd(tx, _mm512_set_epi64(13, 10, 5, 4, 3, 2, 1, 0), c));
  _mm512_store_pd(y, _mm512_permutex2var_pd(ty, _mm512_set_epi64(14, 11, 8, 4, 3, 2, 1, 0), c));
  _mm512_store_pd(z, _mm512_permutex2var_pd(tz, _mm512_set_epi64(15, 12, 9, 4, 3, 2, 1, 0), c));
}

__attribute__((target("avx512f"))) inline Aos3 soa_to_aos(__m512d x, __m512d y, __m512d z) {
  const __m512d ta = _mm512_permutex2var_pd(x, _mm512_set_epi64(10, 2, 0, 9, 1, 0, 8, 0), y);
  const __m512d tb = _mm512_permutex2var_pd(x, _mm512_set_epi64(5, 0, 12, 4, 0, 11, 3, 0), y);
  const __m512d tc = _mm512_permutex2var_pd(x, _mm512_set_epi64(0, 15, 7, 0, 14, 6, 0, 13), y);
  return {_mm512_permutex2var_pd(ta, _mm512_set_epi64(7, 6, 9, 4, 3, 8, 1, 0), z),
          _mm512_permutex2var_pd(tb, _mm512_set_epi64(7, 12, 5, 4, 11, 2, 1, 10), z),
          _mm512_permutex2var_pd(tc, _mm512_set_epi64(15, 6, 5, 14, 3, 2, 13, 0), z)};
}

__attribute__((target("avx512f"))) inline void store_aos(double* dst, const Aos3& v) {
  _mm512_storeu_pd(dst, v.a);
  _mm512_storeu_pd(dst + 8, v.b);
  _mm512_storeu_pd(dst + 16, v.c);
}

/// The index vectors of the quaternion transposes. Two quaternions (x y z w x y z w) per
/// register: `xy` takes x0..x3 | y0..y3 and `zw` z0..z3 | w0..w3 from two registers (and, the
/// other way, puts them back); `low` and `high` join the halves of particles 0-3 and 4-7.
struct QuatIndex {
  __m512i xy, zw, low, high;
};

__attribute__((target("avx512f"))) inline QuatIndex quat_index() {
  return {_mm512_set_epi64(13, 9, 5, 1, 12, 8, 4, 0), _mm512_set_epi64(15, 11, 7, 3, 14, 10, 6, 2),
          _mm512_set_epi64(11, 10, 9, 8, 3, 2, 1, 0), _mm512_set_epi64(15, 14, 13, 12, 7, 6, 5, 4)};
}

/// The batch's lanes [j, j + 8) from particles i … i + 7 (the fields integrate_range puts).
__attribute__((target("avx512f"))) void gather8_avx512(const ParticleState& p, std::size_t i,
                                                       ParticleBatch& b, int j) {
  using F = ParticleBatch::Field;
  auto put3 = [&](F f, const std::vector<Eigen::Vector3d>& v) {
    aos_to_soa(v[i].data(), &b.v[f][j], &b.v[f + 1][j], &b.v[f + 2][j]);
  };
  put3(F::VX, p.vel);
  put3(F::WX, p.angvel);
  put3(F::FX, p.force);
  put3(F::TX, p.torque);
  put3(F::EX, p.external_force);
  // Quaternions (x y z w each) → one register per coefficient.
  const QuatIndex ix = quat_index();
  const double* q = p.ori[i].coeffs().data();
  const __m512d q0 = _mm512_loadu_pd(q), q1 = _mm512_loadu_pd(q + 8), q2 = _mm512_loadu_pd(q + 16),
                q3 = _mm512_loadu_pd(q + 24);
  const __m512d xy03 = _mm512_permutex2var_pd(q0, ix.xy, q1),
                zw03 = _mm512_permutex2var_pd(q0, ix.zw, q1);
  const __m512d xy47 = _mm512_permutex2var_pd(q2, ix.xy, q3),
                zw47 = _mm512_permutex2var_pd(q2, ix.zw, q3);
  _mm512_store_pd(&b.v[F::QX][j], _mm512_permutex2var_pd(xy03, ix.low, xy47));
  _mm512_store_pd(&b.v[F::QY][j], _mm512_permutex2var_pd(xy03, ix.high, xy47));
  _mm512_store_pd(&b.v[F::QZ][j], _mm512_permutex2var_pd(zw03, ix.low, zw47));
  _mm512_store_pd(&b.v[F::QW][j], _mm512_permutex2var_pd(zw03, ix.high, zw47));
  _mm512_store_pd(&b.v[F::MASS][j], _mm512_loadu_pd(&p.mass[i]));
  _mm512_store_pd(&b.v[F::INERTIA][j], _mm512_loadu_pd(&p.inertia[i]));
  for (int k = 0; k < 8; ++k) {
    b.v[F::FIXED][j + k] = p.fixed[i + static_cast<std::size_t>(k)];
    b.v[F::ROT_BLOCKED][j + k] = p.rot_blocked[i + static_cast<std::size_t>(k)];
  }
}

/// Writes lanes [j, j + 8) back to particles i … i + 7: velocities, positions (pos + vel·dt),
/// rotation vectors (rot + ω·dt) and, unless a lane needs the exact rotation (then `large` is
/// set and the caller writes the eight orientations), orientations. Clears `finite` when a
/// position or velocity is not finite.
__attribute__((target("avx512f"))) void scatter8_avx512(ParticleState& p, std::size_t i,
                                                        const ParticleBatch& b, int j, double dt,
                                                        bool& finite, bool& large) {
  using F = ParticleBatch::Field;
  const __m512d vdt = _mm512_set1_pd(dt);
  const __m512d vx = _mm512_load_pd(&b.v[F::VX][j]), vy = _mm512_load_pd(&b.v[F::VY][j]),
                vz = _mm512_load_pd(&b.v[F::VZ][j]);
  const __m512d wx = _mm512_load_pd(&b.v[F::WX][j]), wy = _mm512_load_pd(&b.v[F::WY][j]),
                wz = _mm512_load_pd(&b.v[F::WZ][j]);
  store_aos(p.vel[i].data(), soa_to_aos(vx, vy, vz));
  const Aos3 w = soa_to_aos(wx, wy, wz);
  store_aos(p.angvel[i].data(), w);
  // pos + vel·dt per component, and its squared norm x² + (y² + z²) for the finite check
  alignas(64) double px[8], py[8], pz[8];
  aos_to_soa(p.pos[i].data(), px, py, pz);
  const __m512d nx = _mm512_add_pd(_mm512_load_pd(px), _mm512_mul_pd(vx, vdt));
  const __m512d ny = _mm512_add_pd(_mm512_load_pd(py), _mm512_mul_pd(vy, vdt));
  const __m512d nz = _mm512_add_pd(_mm512_load_pd(pz), _mm512_mul_pd(vz, vdt));
  store_aos(p.pos[i].data(), soa_to_aos(nx, ny, nz));
  const __m512d n2 = _mm512_add_pd(_mm512_mul_pd(nx, nx),
                                   _mm512_add_pd(_mm512_mul_pd(ny, ny), _mm512_mul_pd(nz, nz)));
  const __mmask8 pos_ok = _mm512_cmp_pd_mask(n2, _mm512_set1_pd(HUGE_VAL), _CMP_LT_OQ);
  const __mmask8 vel_ok =
      _mm512_cmp_pd_mask(_mm512_load_pd(&b.v[F::FINITE][j]), _mm512_setzero_pd(), _CMP_NEQ_UQ);
  finite = finite && (pos_ok & vel_ok) == 0xff;
  // rot + ω·dt, on the interleaved components directly
  double* r = p.rot[i].data();
  _mm512_storeu_pd(r, _mm512_add_pd(_mm512_loadu_pd(r), _mm512_mul_pd(w.a, vdt)));
  _mm512_storeu_pd(r + 8, _mm512_add_pd(_mm512_loadu_pd(r + 8), _mm512_mul_pd(w.b, vdt)));
  _mm512_storeu_pd(r + 16, _mm512_add_pd(_mm512_loadu_pd(r + 16), _mm512_mul_pd(w.c, vdt)));
  large = _mm512_cmp_pd_mask(_mm512_load_pd(&b.v[F::LARGE_ANGLE][j]), _mm512_setzero_pd(),
                             _CMP_NEQ_UQ) != 0;
  if (large) return;  // (the caller updates this block's orientations one by one)
  const __m512d qx = _mm512_load_pd(&b.v[F::QX][j]), qy = _mm512_load_pd(&b.v[F::QY][j]),
                qz = _mm512_load_pd(&b.v[F::QZ][j]), qw = _mm512_load_pd(&b.v[F::QW][j]);
  const QuatIndex ix = quat_index();
  const __m512d xy03 = _mm512_permutex2var_pd(qx, ix.low, qy),
                xy47 = _mm512_permutex2var_pd(qx, ix.high, qy);
  const __m512d zw03 = _mm512_permutex2var_pd(qz, ix.low, qw),
                zw47 = _mm512_permutex2var_pd(qz, ix.high, qw);
  double* q = p.ori[i].coeffs().data();
  _mm512_storeu_pd(q, _mm512_permutex2var_pd(xy03, ix.xy, zw03));
  _mm512_storeu_pd(q + 8, _mm512_permutex2var_pd(xy03, ix.zw, zw03));
  _mm512_storeu_pd(q + 16, _mm512_permutex2var_pd(xy47, ix.xy, zw47));
  _mm512_storeu_pd(q + 24, _mm512_permutex2var_pd(xy47, ix.zw, zw47));
}
#endif

template <bool kMembers, bool kRoles = false>
IntegrationSums integrate_range(ParticleState& p, std::size_t begin, std::size_t end,
                                const Eigen::Vector3d& gravity, double damping, double dt,
                                const std::uint8_t* roles = nullptr) {
  using F = ParticleBatch::Field;
  IntegrationSums sums;
  ParticleBatch b;
  std::size_t lane_index[ParticleBatch::kLanes];
#if GS_SIMD_X86
  [[maybe_unused]] const bool wide = simd_level() == SimdLevel::Avx512;  // (8 lanes at a time)
#endif
  // Of a clump member the clump update overwrites the position and orientation, so only the
  // rotation vector and the finite check are left (true: it was one).
  auto member = [&](std::size_t i) {
    if constexpr (kMembers) {
      if (p.clump[i] >= 0 && p.fixed[i]) {
        const V3 vel(p.vel[i]), angvel(p.angvel[i]);
        add_to(p.rot[i], angvel * dt);
        sums.finite = sums.finite && squared_norm(vel) < HUGE_VAL &&
                      squared_norm(V3(p.pos[i]) + vel * dt) < HUGE_VAL;
        return true;
      }
    }
    return false;
  };
  for (std::size_t next = begin; next < end;) {
    const std::size_t i0 = next;
    int count = 0;
    if constexpr (kRoles) {
      // A domain's part: the owned particles in order (each lane's arithmetic is its own, so
      // a particle gets the same bits in whatever batch it is), clump members apart.
      for (; next < end && count < ParticleBatch::kLanes; ++next)
        if (roles[next] == kOwned && !member(next)) lane_index[count++] = next;
      if (count == 0) continue;
    } else if constexpr (kMembers) {
      // The next lanes: the particles in order, fixed clump members apart. A fixed lane keeps
      // its velocities and adds +0 to the sums.
      for (; next < end && count < ParticleBatch::kLanes; ++next)
        if (!member(next)) lane_index[count++] = next;
      if (count == 0) continue;
    } else {
      count = static_cast<int>(std::min<std::size_t>(ParticleBatch::kLanes, end - next));
      next += static_cast<std::size_t>(count);
    }
    auto lane = [&](int j) {
      if constexpr (kMembers || kRoles) return lane_index[j];
      return i0 + static_cast<std::size_t>(j);
    };
    auto put = [&](F f, int j, const Eigen::Vector3d& x) {
      b.v[f][j] = x[0];
      b.v[f + 1][j] = x[1];
      b.v[f + 2][j] = x[2];
    };
    int j0 = 0;  // (the lanes below j0 gathered eight at a time)
#if GS_SIMD_X86
    if constexpr (!kMembers && !kRoles) {
      if (wide)
        for (; j0 + 8 <= count; j0 += 8)
          gather8_avx512(p, i0 + static_cast<std::size_t>(j0), b, j0);
    }
#endif
    for (int j = j0; j < count; ++j) {
      const std::size_t i = lane(j);
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
      sums.gravity_power += b.v[F::GRAVITY_POWER][j];
      sums.external_power += b.v[F::EXTERNAL_POWER][j];
      sums.damping += b.v[F::DAMPING][j];
    }
    // A large rotation in one step, or an orientation that was not a unit quaternion.
    auto exact_rotation = [&](std::size_t i) {
      const Eigen::Vector3d w = p.angvel[i];
      const double a = w.norm();
      if (a > 0) p.ori[i] = Eigen::Quaterniond(Eigen::AngleAxisd(a * dt, w / a)) * p.ori[i];
      p.ori[i].normalize();
    };
#if GS_SIMD_X86
    if constexpr (!kMembers && !kRoles) {
      for (int j = 0; j < j0; j += 8) {
        bool large = false;
        const std::size_t i = i0 + static_cast<std::size_t>(j);
        scatter8_avx512(p, i, b, j, dt, sums.finite, large);
        if (!large) continue;
        for (int k = j; k < j + 8; ++k) {
          const std::size_t ik = i0 + static_cast<std::size_t>(k);
          if (b.v[F::LARGE_ANGLE][k] == 0)
            p.ori[ik] =
                Eigen::Quaterniond(b.v[F::QW][k], b.v[F::QX][k], b.v[F::QY][k], b.v[F::QZ][k]);
          else
            exact_rotation(ik);
        }
      }
    }
#endif
    for (int j = j0; j < count; ++j) {
      const std::size_t i = lane(j);
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
      exact_rotation(i);
    }
  }
  return sums;
}

}  // namespace

IntegrationSums integrate_particles(ParticleState& p, std::size_t begin, std::size_t end,
                                    const Eigen::Vector3d& gravity, double damping, double dt,
                                    bool clump_members, const std::uint8_t* roles) {
  const bool members = clump_members && p.clump.size() == p.size();
  if (roles)
    return members ? integrate_range<true, true>(p, begin, end, gravity, damping, dt, roles)
                   : integrate_range<false, true>(p, begin, end, gravity, damping, dt, roles);
  return members ? integrate_range<true>(p, begin, end, gravity, damping, dt)
                 : integrate_range<false>(p, begin, end, gravity, damping, dt);
}

void integrate_clump_bodies(ClumpBody* clumps, const ClumpLoad* loads, std::size_t count,
                            const Eigen::Vector3d& gravity, double damping, double dt,
                            double* damp) {
  using F = ClumpBatch::Field;
  ClumpBatch b;
  for (std::size_t k0 = 0; k0 < count; k0 += ClumpBatch::kLanes) {
    const int n = static_cast<int>(std::min<std::size_t>(ClumpBatch::kLanes, count - k0));
    auto put = [&](F f, int j, const Eigen::Vector3d& x) {
      b.v[f][j] = x[0];
      b.v[f + 1][j] = x[1];
      b.v[f + 2][j] = x[2];
    };
    for (int j = 0; j < n; ++j) {
      const ClumpBody& c = clumps[k0 + static_cast<std::size_t>(j)];
      const ClumpLoad& l = loads[k0 + static_cast<std::size_t>(j)];
      put(F::FX, j, l.force);
      put(F::MX, j, l.torque);
      put(F::VX, j, c.vel);
      put(F::WX, j, c.angvel);
      put(F::LX, j, c.angmom);
      put(F::PX, j, c.pos);
      put(F::IX, j, c.inertia);
      b.v[F::QW][j] = c.ori.w();
      b.v[F::QX][j] = c.ori.x();
      b.v[F::QY][j] = c.ori.y();
      b.v[F::QZ][j] = c.ori.z();
      b.v[F::MASS][j] = c.mass;
    }
    integrate_clump_batch(b, n, V3(gravity), damping, dt);
    auto get = [&](F f, int j) { return Eigen::Vector3d(b.v[f][j], b.v[f + 1][j], b.v[f + 2][j]); };
    for (int j = 0; j < n; ++j) {
      ClumpBody& c = clumps[k0 + static_cast<std::size_t>(j)];
      c.vel = get(F::VX, j);
      c.angvel = get(F::WX, j);
      c.angmom = get(F::LX, j);
      c.pos = get(F::PX, j);
      c.ori = Eigen::Quaterniond(b.v[F::QW][j], b.v[F::QX][j], b.v[F::QY][j], b.v[F::QZ][j]);
      damp[k0 + static_cast<std::size_t>(j)] = b.v[F::DAMP][j];
    }
  }
}

IntegrationSums integrate_particles_homogeneous(ParticleState& p, std::size_t begin,
                                                std::size_t end, const Eigen::Vector3d& gravity,
                                                double damping, double dt,
                                                const HomogeneousField& field,
                                                const std::uint8_t* roles) {
  IntegrationSums sums;
  const V3 g(gravity);
  const bool planar = field.planar;
  const V3 d_spin(field.d_spin);
  for (std::size_t i = begin; i < end; ++i) {
    if (roles && roles[i] != kOwned) continue;  // (another process's to move)
    const V3 pos0(p.pos[i]);
    V3 vel(p.vel[i]), angvel(p.angvel[i]);
    if (!p.fixed[i]) {
      const double m = p.mass[i];
      const V3 force(p.force[i]), torque(p.torque[i]);
      const V3 fluct = vel - mat_vec(field.prev_vel_grad, pos0);  // Cell::bodyFluctuationVel
      sums.gravity_power += m * dot(g, vel);
      sums.external_power += dot(V3(p.external_force[i]), vel);
      if (damping != 0)
        sums.damping += dot(abs(fluct), abs(force + m * g)) * damping * dt +
                        dot(abs(angvel), abs(torque)) * damping * dt;
      V3 lin = force / m + g;  // computeAccel (blocked components: 0)
      if (planar) lin.z = 0;
      lin = {lin.x * cundall_factor(damping, dt, fluct.x, lin.x),
             lin.y * cundall_factor(damping, dt, fluct.y, lin.y),
             lin.z * cundall_factor(damping, dt, fluct.z, lin.z)};
      lin += mat_vec(field.prev_vel_grad, vel);  // convective term (homoDeform = 2)
      vel = vel + dt * lin;
      if (!p.rot_blocked[i]) {
        V3 ang = torque / p.inertia[i];
        if (planar) ang.x = ang.y = 0;
        ang = {ang.x * cundall_factor(damping, dt, angvel.x, ang.x),
               ang.y * cundall_factor(damping, dt, angvel.y, ang.y),
               ang.z * cundall_factor(damping, dt, angvel.z, ang.z)};
        angvel = angvel + dt * ang;
      }
    } else {
      vel += mat_vec(dt * field.prev_vel_grad, vel);  // (YADE: fully blocked bodies)
    }
    vel += mat_vec(field.d_vel_grad, pos0);  // leapfrogTranslate: the change of the mean field
    const V3 pos = pos0 + vel * dt;
    angvel += d_spin;  // leapfrogSphericalRotate (YADE adds it always)
    vel.store(p.vel[i]);
    angvel.store(p.angvel[i]);
    pos.store(p.pos[i]);
    add_to(p.rot[i], angvel * dt);
    const double a2 = squared_norm(angvel);
    if (a2 != 0) {
      const double a = std::sqrt(a2);
      p.ori[i] = Eigen::Quaterniond(Eigen::AngleAxisd(a * dt, p.angvel[i] / a)) * p.ori[i];
    }
    p.ori[i].normalize();
    sums.finite = sums.finite && squared_norm(vel) < HUGE_VAL && squared_norm(pos) < HUGE_VAL;
  }
  return sums;
}

}  // namespace gs::solver
