#include "cohesive_frictional_law.hpp"

#include <cmath>

namespace gs::solver {

ContactParams contact_params(const Material& m, double r1, double r2, double twist_beta,
                             double twist_eta) {
  const auto k =
      contact_stiffness(m.young_ec, m.stiffness_ratio, m.rolling_beta, r1, r2, m.rolling_radius);
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

ContactLoads cohesive_frictional_step(ContactHistory& h, bool fresh, const ContactGeometry& g,
                                      const ContactParams& p, const BodyMotion& b1,
                                      const BodyMotion& b2, double dt) {
  const Eigen::Vector3d& n = g.normal;
  // ScGeom::precompute: rotation of the tangent plane since the last step (normal change and
  // the mean spin about the old normal), applied to the stored shear force and moments.
  Eigen::Vector3d orth = Eigen::Vector3d::Zero(), twist_axis = Eigen::Vector3d::Zero();
  if (fresh) {
    h.shear_force.setZero();
    h.bending.setZero();
    h.twist.setZero();
  } else {
    orth = h.normal.cross(n);
    const double angle = dt * 0.5 * h.normal.dot(b1.angvel + b2.angvel);
    twist_axis = angle * h.normal;
  }
  h.normal = n;
  // Relative velocity of body 2 with respect to body 1 at the contact (seed 004 eq 3.5).
  Eigen::Vector3d rel;
  if (g.ratchet_free) {
    const double alpha = (g.radius1 + g.radius2) / (g.radius1 + g.radius2 - g.penetration);
    rel = (b2.vel - b1.vel) * alpha + b2.angvel.cross(-g.radius2 * n) -
          b1.angvel.cross(g.radius1 * n);
  } else {
    const Eigen::Vector3d c1x = g.point - b1.pos, c2x = g.point - b2.pos;
    rel = (b2.vel + b2.angvel.cross(c2x)) - (b1.vel + b1.angvel.cross(c1x));
  }
  rel = rel - n.dot(rel) * n;
  const Eigen::Vector3d shear_inc = rel * dt;

  auto rotate = [&](Eigen::Vector3d& v) {
    v -= v.cross(orth);
    v -= v.cross(twist_axis);
  };
  rotate(h.shear_force);
  if (p.kr > 0) rotate(h.bending);
  if (p.ktw > 0) rotate(h.twist);

  // Elastic trial values (seed 000 eq 1-6).
  double fn = p.kn * g.penetration;
  h.shear_force -= p.ks * shear_inc;
  const Eigen::Vector3d rel_ang = b2.angvel - b1.angvel;
  if (p.kr > 0) {
    const Eigen::Vector3d bend = rel_ang - n.dot(rel_ang) * n;
    h.bending = h.bending - p.kr * bend * dt;
  } else {
    h.bending.setZero();
  }
  if (p.ktw > 0) {
    h.twist = h.twist - p.ktw * (n.dot(rel_ang) * n) * dt;
  } else {
    h.twist.setZero();
  }

  ContactLoads out;
  // Coulomb limit on the shear force (seed 000 eq 4), compared on squared norms as YADE does.
  double max_fs = std::max(0.0, fn * p.tan_friction);
  const double fs2 = h.shear_force.squaredNorm();
  max_fs *= max_fs;
  if (fs2 > max_fs) {
    const Eigen::Vector3d trial = h.shear_force;
    h.shear_force *= std::sqrt(max_fs / fs2);
    const double d = ((1.0 / p.ks) * (trial - h.shear_force)).dot(h.shear_force);
    if (d > 0) out.friction_dissipation = d;
  }
  // Rolling and twisting limits (seed 000 eq 7).
  if (p.kr > 0 && p.max_roll >= 0) {
    double max_roll = std::max(0.0, p.max_roll * fn);
    max_roll *= max_roll;
    const double m2 = h.bending.squaredNorm();
    if (m2 > max_roll) {
      const Eigen::Vector3d trial = h.bending;
      h.bending *= std::sqrt(max_roll / m2);
      const double d = ((1.0 / p.kr) * (trial - h.bending)).dot(h.bending);
      if (d > 0) out.rolling_dissipation = d;
    }
  }
  if (p.ktw > 0 && p.max_twist >= 0) {
    double max_tw = std::max(0.0, p.max_twist * fn);
    max_tw *= max_tw;
    const double t2 = h.twist.squaredNorm();
    if (t2 > max_tw) h.twist *= std::sqrt(max_tw / t2);
  }
  // Loads: body 2 receives Fn·n + Fs at the contact point (YADE applyForceAtContactPoint).
  const Eigen::Vector3d f1 = -(fn * n) - h.shear_force;
  const Eigen::Vector3d moment = h.twist + h.bending;
  out.force1 = f1;
  out.arm1 = (g.point - b1.pos).cross(f1);
  out.arm2 = -(g.point - b2.pos).cross(f1);
  out.moment = moment;
  out.fn = fn;
  h.fn = fn;
  h.overlap = g.penetration;
  h.point = g.point;
  return out;
}

}  // namespace gs::solver
