#include "cohesive_frictional_law.hpp"

#include <cmath>

#include "simd_level.hpp"

namespace gs::solver {

ContactParams contact_params(const Material& m, double r1, double r2, double twist_beta,
                             double twist_eta) {
  auto k = m.normal_stiffness_N_m > 0
               ? contact_stiffness(1.0, m.stiffness_ratio, m.rolling_beta, r1, r2, m.rolling_radius)
               : contact_stiffness(m.young_ec, m.stiffness_ratio, m.rolling_beta, r1, r2,
                                   m.rolling_radius);
  if (m.normal_stiffness_N_m > 0) {  // constant stiffness (seed 003 §2.4): Kn given, Ks = νc·Kn
    k.kn = m.normal_stiffness_N_m;
    k.ks = m.stiffness_ratio * k.kn;
    k.kr = m.rolling_beta * k.ks * r1 * r2;
  }
  ContactParams p;
  p.kn = k.kn;
  p.ks = k.ks;
  p.kr = k.kr;
  p.ktw = twist_beta * k.ks * r1 * r2;
  p.tan_friction = std::tan(m.friction_deg * M_PI / 180.0);
  p.max_roll = m.rolling_eta >= 0 ? m.rolling_eta * k.rolling_radius_m : -1;
  p.max_twist = twist_eta >= 0 ? twist_eta * k.rolling_radius_m : -1;
  return p;
}

namespace {
using Batch = ContactBatch;

inline double zero_max(double x) {
  return 0.0 < x ? x : 0.0;
}  // std::max(0.0, x)

template <bool kTwist, bool kPeriodic>
[[gnu::always_inline]] inline void law_lanes(ContactBatch& batch, int count, double dt) {
  auto in3 = [&](Batch::Field f, int j) { return batch.get3(f, j); };
  auto out3 = [&](Batch::Field f, int j, const V3& x) { batch.set3(f, j, x); };
  const double* const r1_ = batch[Batch::R1];
  const double* const r2_ = batch[Batch::R2];
  const double* const ratchet_ = batch[Batch::RATCHET];
  const double* const fresh_ = batch[Batch::FRESH];
  const double* const kn_ = batch[Batch::KN];
  const double* const ks_ = batch[Batch::KS];
  const double* const kr_ = batch[Batch::KR];
  const double* const ktw_ = batch[Batch::KTW];
  const double* const tan_ = batch[Batch::TAN_FRICTION];
  const double* const max_roll_ = batch[Batch::MAX_ROLL];
  const double* const max_twist_ = batch[Batch::MAX_TWIST];
  double* const fn_ = batch[Batch::FN];
  double* const fr_ = batch[Batch::FRICTION_DISSIPATION];
  double* const ro_ = batch[Batch::ROLLING_DISSIPATION];
  for (int j = 0; j < count; ++j) {
    const double r1 = r1_[j], r2 = r2_[j];
    const LaneGeometry g = lane_geometry(batch, j);
    const V3 n = g.n, c1 = g.c1, c2 = g.c2;
    const double pen = g.pen;
    const V3 w1 = in3(Batch::W1X, j), w2 = in3(Batch::W2X, j);
    const V3 v1 = in3(Batch::V1X, j), v2 = in3(Batch::V2X, j);
    const double kn = kn_[j], ks = ks_[j], kr = kr_[j];
    const double ktw = kTwist ? ktw_[j] : 0.0;  // (not filled in without twisting)
    const bool fresh = fresh_[j] != 0;
    // ScGeom::precompute: rotation of the tangent plane since the last step (normal change and
    // the mean spin about the old normal), applied to the stored shear force and moments. A
    // fresh contact starts from zero history and no rotation.
    const V3 zero{0, 0, 0};
    const V3 old_n = in3(Batch::ONX, j);
    V3 shear = select(fresh, zero, in3(Batch::SX, j));
    V3 bending = select(fresh, zero, in3(Batch::BX, j));
    V3 twist = kTwist ? select(fresh, zero, in3(Batch::TX, j)) : zero;
    const V3 orth = select(fresh, zero, cross(old_n, n));
    const double angle = dt * 0.5 * dot(old_n, w1 + w2);
    const V3 twist_axis = select(fresh, zero, angle * old_n);
    // Relative velocity of body 2 with respect to body 1 at the contact (seed 004 eq 3.5).
    const double alpha = (r1 + r2) / (r1 + r2 - pen);
    V3 rel_radii = (v2 - v1) * alpha + cross(w2, -r2 * n) - cross(w1, r1 * n);
    V3 rel_point = (v2 + cross(w2, c2)) - (v1 + cross(w1, c1));
    if constexpr (kPeriodic) {  // (YADE: relativeVelocity += α·shiftVel, or += shiftVel)
      const V3 sv = in3(Batch::SVX, j);
      rel_radii += alpha * sv;
      rel_point += sv;
    }
    V3 rel = select(ratchet_[j] != 0, rel_radii, rel_point);
    rel = rel - dot(n, rel) * n;
    const V3 shear_inc = rel * dt;
    auto rotate = [&](V3 x) {
      x = x - cross(x, orth);
      return x - cross(x, twist_axis);
    };
    shear = rotate(shear);
    bending = rotate(bending);  // (discarded below without a rolling stiffness)
    if constexpr (kTwist) twist = rotate(twist);
    // Elastic trial values (seed 000 eq 1-6).
    const double fn = kn * pen;
    shear = shear - ks * shear_inc;
    const V3 rel_ang = w2 - w1;
    const V3 bend = rel_ang - dot(n, rel_ang) * n;
    bending = select(kr > 0, bending - kr * bend * dt, zero);
    if constexpr (kTwist)
      twist = select(ktw > 0, twist - ktw * (dot(n, rel_ang) * n) * dt, zero);
    else
      twist = zero;
    // Coulomb limit on the shear force (seed 000 eq 4), compared on squared norms as YADE does.
    double max_fs = zero_max(fn * tan_[j]);
    max_fs *= max_fs;
    const double fs2 = dot(shear, shear);
    const bool sliding = fs2 > max_fs;
    const V3 capped = shear * std::sqrt(max_fs / fs2);
    const double d_fs = dot((1.0 / ks) * (shear - capped), capped);
    fr_[j] = (sliding & (d_fs > 0)) ? d_fs : 0.0;
    shear = select(sliding, capped, shear);
    // Rolling and twisting limits (seed 000 eq 7).
    double max_roll = zero_max(max_roll_[j] * fn);
    max_roll *= max_roll;
    const double m2 = dot(bending, bending);
    const bool rolling = (kr > 0) & (max_roll_[j] >= 0) & (m2 > max_roll);
    const V3 bending_capped = bending * std::sqrt(max_roll / m2);
    const double d_roll = dot((1.0 / kr) * (bending - bending_capped), bending_capped);
    ro_[j] = (rolling & (d_roll > 0)) ? d_roll : 0.0;
    bending = select(rolling, bending_capped, bending);
    if constexpr (kTwist) {
      double max_tw = zero_max(max_twist_[j] * fn);
      max_tw *= max_tw;
      const double t2 = dot(twist, twist);
      const bool twisting = (ktw > 0) & (max_twist_[j] >= 0) & (t2 > max_tw);
      twist = select(twisting, twist * std::sqrt(max_tw / t2), twist);
    }
    // Loads: body 2 receives Fn·n + Fs at the contact point (YADE applyForceAtContactPoint).
    const V3 f1 = -(fn * n) - shear;
    out3(Batch::SX, j, shear);
    out3(Batch::BX, j, bending);
    out3(Batch::TX, j, twist);
    out3(Batch::F1X, j, f1);
    out3(Batch::A1X, j, cross(c1, f1));
    out3(Batch::A2X, j, -cross(c2, f1));
    out3(Batch::MX, j, twist + bending);
    fn_[j] = fn;
  }
}

// The law compiled for each instruction set (docs/physics.md: the same bits from each).
[[gnu::always_inline]] inline void law_variants(ContactBatch& batch, int count, double dt,
                                                bool twist, bool periodic) {
  if (periodic) {
    if (twist)
      law_lanes<true, true>(batch, count, dt);
    else
      law_lanes<false, true>(batch, count, dt);
  } else if (twist) {
    law_lanes<true, false>(batch, count, dt);
  } else {
    law_lanes<false, false>(batch, count, dt);
  }
}

void law_generic(ContactBatch& batch, int count, double dt, bool twist, bool periodic) {
  law_variants(batch, count, dt, twist, periodic);
}

#if GS_SIMD_X86
__attribute__((target("avx2"))) void law_avx2(ContactBatch& batch, int count, double dt, bool twist,
                                              bool periodic) {
  law_variants(batch, count, dt, twist, periodic);
}

__attribute__((target("avx512f"))) void law_avx512(ContactBatch& batch, int count, double dt,
                                                   bool twist, bool periodic) {
  law_variants(batch, count, dt, twist, periodic);
}
#endif

}  // namespace

void cohesive_frictional_batch(ContactBatch& batch, int count, double dt, bool twist,
                               bool periodic) {
#if GS_SIMD_X86
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return law_avx512(batch, count, dt, twist, periodic);
    case SimdLevel::Avx2:
      return law_avx2(batch, count, dt, twist, periodic);
    case SimdLevel::Generic:
      break;
  }
#endif
  law_generic(batch, count, dt, twist, periodic);
}

}  // namespace gs::solver
