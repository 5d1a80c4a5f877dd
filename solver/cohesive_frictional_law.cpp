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

}  // namespace gs::solver
