#include "hertz_mindlin_law.hpp"

#include <cmath>
#include <stdexcept>

#include "glibc_powers.hpp"
#include "simd_level.hpp"

namespace gs::solver {

double thornton_damping_ratio(double en) {
  if (!(en > 0 && en <= 1)) throw std::invalid_argument("coefficient of restitution not in (0, 1]");
  if (en == 1.0) return 0;
  // Thornton, Cummins & Cleary (2013) Table 2 / Eq B7: α(en) as a polynomial, then Eq B6.
  const double h[10] = {-6.918798, -16.41105, 146.8049,  -796.4559, 2928.711,
                        -7206.864, 11494.29,  -11342.18, 6276.757,  -1489.915};
  double a = h[9];
  for (int i = 8; i >= 0; --i) a = h[i] + en * a;  // (YADE's nesting, innermost first)
  a = en * a;
  return std::sqrt(1.0 / (1.0 - std::pow(1.0 + en, 2) * std::exp(a)) - 1.0);
}

ContactParams hertz_mindlin_params(const HertzMaterial& a, const HertzMaterial& b, double ra,
                                   double rb, double ma, double mb, double restitution,
                                   double tan_friction) {
  if (!(ra > 0) || !(rb > 0)) throw std::invalid_argument("radii must be positive");
  const double ga = a.young / (2 * (1 + a.poisson));
  const double gb = b.young / (2 * (1 + b.poisson));
  const double g = 1.0 / ((2 - a.poisson) / ga + (2 - b.poisson) / gb);
  const double e =
      a.young * b.young /
      ((1. - std::pow(a.poisson, 2)) * b.young + (1. - std::pow(b.poisson, 2)) * a.young);
  const double r = ra * rb / (ra + rb);
  ContactParams p;
  p.kn = 4. / 3. * e * std::sqrt(r);
  p.ks = 8 * std::sqrt(r) * g;
  p.kr = p.ktw = thornton_damping_ratio(restitution);
  p.max_roll = ma > 0 && mb > 0 ? ma * mb / (ma + mb) : (ma > 0 ? ma : mb);
  p.max_twist = -1;
  p.tan_friction = tan_friction;
  return p;
}

double rayleigh_timestep(const std::vector<double>& radii, double density, double young,
                         double poisson) {
  double rmin = HUGE_VAL;
  for (const double r : radii) rmin = std::min(rmin, r);
  const double g = young / (2 * (1 + poisson));
  return M_PI * rmin * std::sqrt(density / g) / (0.1631 * poisson + 0.8766);
}

namespace {
using Batch = ContactBatch;

template <bool kPeriodic>
[[gnu::always_inline]] inline void hm_lanes(ContactBatch& batch, int count, double dt) {
  auto in3 = [&](Batch::Field f, int j) { return batch.get3(f, j); };
  auto out3 = [&](Batch::Field f, int j, const V3& x) { batch.set3(f, j, x); };
  // Three passes, so that the two without calls vectorise: the geometry (its normal,
  // penetration and contact point go to NX, PEN, PTX, the arms to C1X, C2X), the powers of the
  // penetration (glibc's pow, as YADE calls it: computed where certain, glibc_powers.hpp, and
  // called for the other lanes), then the law. Each lane's operations and their order are those
  // of one scalar pass: the same bits.
  for (int j = 0; j < count; ++j) {
    const LaneGeometry g = lane_geometry(batch, j);
    out3(Batch::C1X, j, g.c1);
    out3(Batch::C2X, j, g.c2);
  }
  double pow15[ContactBatch::kLanes], pow05[ContactBatch::kLanes];
  bool certain15[ContactBatch::kLanes], certain05[ContactBatch::kLanes];
  for (int j = 0; j < count; ++j) {
    const CertainPower a = glibc_pow_three_halves(batch.v[Batch::PEN][j]);
    const CertainPower b = glibc_pow_half(batch.v[Batch::PEN][j]);
    pow15[j] = a.value;
    pow05[j] = b.value;
    certain15[j] = a.certain;
    certain05[j] = b.certain;
  }
  for (int j = 0; j < count; ++j) {
    if (!certain15[j]) pow15[j] = std::pow(batch.v[Batch::PEN][j], 1.5);
    if (!certain05[j]) pow05[j] = std::pow(batch.v[Batch::PEN][j], 0.5);
  }
  for (int j = 0; j < count; ++j) {
    const double r1 = batch.v[Batch::R1][j], r2 = batch.v[Batch::R2][j];
    LaneGeometry g;
    g.n = in3(Batch::NX, j);
    g.c1 = in3(Batch::C1X, j);
    g.c2 = in3(Batch::C2X, j);
    const V3 n = g.n;
    const double un = batch.v[Batch::PEN][j];
    const V3 zero{0, 0, 0};
    const double kno = batch.v[Batch::KN][j], kso = batch.v[Batch::KS][j];
    const double betan = batch.v[Batch::KR][j], betas = batch.v[Batch::KTW][j];
    const double mbar = batch.v[Batch::MAX_ROLL][j];
    const bool damped = (betan != 0.) | (betas != 0.);
    const bool fresh = batch.v[Batch::FRESH][j] != 0;
    const V3 w1 = in3(Batch::W1X, j), w2 = in3(Batch::W2X, j);
    const V3 v1 = in3(Batch::V1X, j), v2 = in3(Batch::V2X, j);
    // Normal force and the tangent stiffnesses (seed 004 eq 3.2's Hertzian counterpart).
    const double fn_el = kno * pow15[j];
    const double kn = 3. / 2. * kno * pow05[j];
    const double ks = kso * pow05[j];
    const double cn = 2. * std::sqrt(mbar * kn) * betan;
    const double cs = 2. * std::sqrt(mbar * ks) * betas;
    // The stored elastic shear force, rotated into the current tangent plane (ScGeom::rotate).
    const V3 old_n = in3(Batch::ONX, j);
    V3 shear = select(fresh, zero, in3(Batch::SX, j));
    const V3 orth = select(fresh, zero, cross(old_n, n));
    const double angle = dt * 0.5 * dot(old_n, w1 + w2);
    const V3 twist_axis = select(fresh, zero, angle * old_n);
    shear = shear - cross(shear, orth);
    shear = shear - cross(shear, twist_axis);
    // The shear increment as ScGeom's (granular ratcheting avoided where RATCHET says so).
    const double alpha = (r1 + r2) / (r1 + r2 - un);
    V3 rel_radii = (v2 - v1) * alpha + cross(w2, -r2 * n) - cross(w1, r1 * n);
    V3 rel_point = (v2 + cross(w2, g.c2)) - (v1 + cross(w1, g.c1));
    if constexpr (kPeriodic) {
      const V3 sv = in3(Batch::SVX, j);
      rel_radii += alpha * sv;
      rel_point += sv;
    }
    V3 rel = select(batch.v[Batch::RATCHET][j] != 0, rel_radii, rel_point);
    rel = rel - dot(n, rel) * n;
    const V3 shear_inc = rel * dt;
    const V3 vs = shear_inc / dt;  // (YADE: incidentVs = shearIncrement()/dt)
    shear = shear - ks * (vs * dt);
    // Normal viscous force from the incident velocity at the contact point (no ratcheting
    // correction); the normal force never pulls.
    const V3 vn = dot(n, rel_point) * n;
    V3 normal = fn_el * n;
    V3 normal_visc = cn * vn;
    const V3 trial = normal - normal_visc;
    const bool pulls = dot(trial, n) < 0.0;
    normal_visc = select(damped & pulls, normal_visc + trial, normal_visc);
    normal = select(damped, select(pulls, zero, trial), normal);
    normal_visc = select(damped, normal_visc, zero);
    // Coulomb's limit on the elastic shear force.
    const double fn = std::sqrt(squared_norm(normal));
    const double max_fs = fn * batch.v[Batch::TAN_FRICTION][j];
    const double fs2 = squared_norm(shear);
    const bool sliding = fs2 > max_fs * max_fs;
    const double ratio = max_fs / std::sqrt(fs2);
    const V3 capped = shear * ratio;
    const double d_fs = dot((1.0 / ks) * (shear - capped), capped);
    batch.v[Batch::FRICTION_DISSIPATION][j] =
        (sliding & (d_fs > 0) & (d_fs < HUGE_VAL)) ? d_fs : 0.0;
    shear = select(sliding, capped, shear);
    const V3 shear_visc = select(damped & !sliding, cs * vs, zero);
    const V3 shear_force = shear - shear_visc;
    batch.v[Batch::ROLLING_DISSIPATION][j] = dot(normal_visc, vn * dt) + dot(shear_visc, vs * dt);
    // Loads: body 2 receives normal + shear at the contact point.
    const V3 f1 = -normal - shear_force;
    out3(Batch::SX, j, shear);
    out3(Batch::BX, j, zero);
    out3(Batch::TX, j, zero);
    out3(Batch::F1X, j, f1);
    out3(Batch::A1X, j, cross(g.c1, f1));
    out3(Batch::A2X, j, -cross(g.c2, f1));
    out3(Batch::MX, j, zero);
    batch.v[Batch::FN][j] = fn;
  }
}

[[gnu::always_inline]] inline void hm_variants(ContactBatch& batch, int count, double dt,
                                               bool periodic) {
  if (periodic)
    hm_lanes<true>(batch, count, dt);
  else
    hm_lanes<false>(batch, count, dt);
}

void hm_generic(ContactBatch& batch, int count, double dt, bool periodic) {
  hm_variants(batch, count, dt, periodic);
}

#if GS_SIMD_X86
__attribute__((target("avx2"))) void hm_avx2(ContactBatch& batch, int count, double dt,
                                             bool periodic) {
  hm_variants(batch, count, dt, periodic);
}

__attribute__((target("avx512f"))) void hm_avx512(ContactBatch& batch, int count, double dt,
                                                  bool periodic) {
  hm_variants(batch, count, dt, periodic);
}
#endif

}  // namespace

void hertz_mindlin_batch(ContactBatch& batch, int count, double dt, bool periodic) {
#if GS_SIMD_X86
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return hm_avx512(batch, count, dt, periodic);
    case SimdLevel::Avx2:
      return hm_avx2(batch, count, dt, periodic);
    case SimdLevel::Generic:
      break;
  }
#endif
  hm_generic(batch, count, dt, periodic);
}

}  // namespace gs::solver
