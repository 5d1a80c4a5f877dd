// YADE's Law2_ScGeom6D_CohFrictPhys_CohesionMoment for non-cohesive contacts, incremental form
// (seed 000 eq 1-7; seed 004 eqs 3.1-3.18). docs/physics.md lists each convention.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "contact_geometry.hpp"
#include "dem_types.hpp"
#include "scalar_vec3.hpp"

namespace gs::solver {

/// Constant contact parameters, set when the contact is created.
struct ContactParams {
  double kn = 0, ks = 0, kr = 0, ktw = 0;
  double tan_friction = 0;
  double max_roll = -1;   // η·R_roll (m); negative: rolling moment unbounded
  double max_twist = -1;  // likewise for twisting
};

ContactParams contact_params(const Material& m, double r1, double r2, double twist_beta,
                             double twist_eta);

/// Kinematics of the two bodies at the contact.
struct BodyMotion {
  V3 pos, vel, angvel;
};

/// Loads the contact puts on the bodies, split as YADE accumulates them: body 1 receives
/// force1 and the torques arm1 − moment; body 2 receives −force1 and arm2 + moment.
struct ContactLoads {
  V3 force1, arm1, arm2, moment;
  double fn = 0;                                             // |normal force|, N
  double friction_dissipation = 0, rolling_dissipation = 0;  // J, this step
};

/// One step of the law on a contact that exists this step (penetration ≥ 0). `fresh` starts
/// the history at zero. Updates the history (normal, shear force, moments) in place. Inline:
/// it is the body of the solver's contact loop.
[[gnu::always_inline]] inline ContactLoads cohesive_frictional_step(ContactHistory& h, bool fresh,
                                             const ContactGeometry& g, const ContactParams& p,
                                             const BodyMotion& b1, const BodyMotion& b2,
                                             double dt) {
  const V3 n = g.normal;
  V3 shear, bending, twist;
  // ScGeom::precompute: rotation of the tangent plane since the last step (normal change and
  // the mean spin about the old normal), applied to the stored shear force and moments.
  V3 orth, twist_axis;
  if (!fresh) {
    shear = load3(h.shear_force);
    bending = load3(h.bending);
    twist = load3(h.twist);
    const V3 old_n = load3(h.normal);
    orth = cross(old_n, n);
    const double angle = dt * 0.5 * dot(old_n, b1.angvel + b2.angvel);
    twist_axis = angle * old_n;
  }
  n.store(h.normal);
  // Relative velocity of body 2 with respect to body 1 at the contact (seed 004 eq 3.5).
  V3 rel;
  if (g.ratchet_free) {
    const double alpha = (g.radius1 + g.radius2) / (g.radius1 + g.radius2 - g.penetration);
    rel = (b2.vel - b1.vel) * alpha + cross(b2.angvel, -g.radius2 * n) -
          cross(b1.angvel, g.radius1 * n);
  } else {
    const V3 c1x = g.point - b1.pos, c2x = g.point - b2.pos;
    rel = (b2.vel + cross(b2.angvel, c2x)) - (b1.vel + cross(b1.angvel, c1x));
  }
  rel = rel - dot(n, rel) * n;
  const V3 shear_inc = rel * dt;

  auto rotate = [&](V3& v) {
    v -= cross(v, orth);
    v -= cross(v, twist_axis);
  };
  rotate(shear);
  if (p.kr > 0) rotate(bending);
  if (p.ktw > 0) rotate(twist);

  // Elastic trial values (seed 000 eq 1-6).
  const double fn = p.kn * g.penetration;
  shear -= p.ks * shear_inc;
  const V3 rel_ang = b2.angvel - b1.angvel;
  if (p.kr > 0) {
    const V3 bend = rel_ang - dot(n, rel_ang) * n;
    bending = bending - p.kr * bend * dt;
  } else {
    bending = V3();
  }
  if (p.ktw > 0)
    twist = twist - p.ktw * (dot(n, rel_ang) * n) * dt;
  else
    twist = V3();

  ContactLoads out;
  // Coulomb limit on the shear force (seed 000 eq 4), compared on squared norms as YADE does.
  double max_fs = std::max(0.0, fn * p.tan_friction);
  const double fs2 = squared_norm(shear);
  max_fs *= max_fs;
  if (fs2 > max_fs) {
    const V3 trial = shear;
    shear = shear * std::sqrt(max_fs / fs2);
    const double d = dot((1.0 / p.ks) * (trial - shear), shear);
    if (d > 0) out.friction_dissipation = d;
  }
  // Rolling and twisting limits (seed 000 eq 7).
  if (p.kr > 0 && p.max_roll >= 0) {
    double max_roll = std::max(0.0, p.max_roll * fn);
    max_roll *= max_roll;
    const double m2 = squared_norm(bending);
    if (m2 > max_roll) {
      const V3 trial = bending;
      bending = bending * std::sqrt(max_roll / m2);
      const double d = dot((1.0 / p.kr) * (trial - bending), bending);
      if (d > 0) out.rolling_dissipation = d;
    }
  }
  if (p.ktw > 0 && p.max_twist >= 0) {
    double max_tw = std::max(0.0, p.max_twist * fn);
    max_tw *= max_tw;
    const double t2 = squared_norm(twist);
    if (t2 > max_tw) twist = twist * std::sqrt(max_tw / t2);
  }
  shear.store(h.shear_force);
  bending.store(h.bending);
  twist.store(h.twist);
  // Loads: body 2 receives Fn·n + Fs at the contact point (YADE applyForceAtContactPoint).
  const V3 f1 = -(fn * n) - shear;
  out.force1 = f1;
  out.arm1 = cross(g.point - b1.pos, f1);
  out.arm2 = -cross(g.point - b2.pos, f1);
  out.moment = twist + bending;
  out.fn = fn;
  h.fn = fn;
  h.overlap = g.penetration;
  g.point.store(h.point);
  return out;
}

}  // namespace gs::solver
