#include "contact_stiffness.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::solver {

ContactStiffness contact_stiffness(double young_ec, double nu_c, double beta, double ra, double rb,
                                   RollingRadius rolling_radius) {
  if (!(ra > 0) || !(rb > 0) || !std::isfinite(ra) || !std::isfinite(rb))
    throw std::invalid_argument("contact_stiffness: radii must be positive, got " +
                                std::to_string(ra) + ", " + std::to_string(rb));
  if (!(young_ec > 0) || !std::isfinite(young_ec))
    throw std::invalid_argument("contact_stiffness: Ec must be positive, got " +
                                std::to_string(young_ec));
  ContactStiffness k;
  k.kn = young_ec * 2.0 * ra * rb / (ra + rb);  // seed 000 eq 2
  k.ks = nu_c * k.kn;                           // seed 000 eq 3
  k.kr = beta * k.ks * ra * rb;                 // seed 000 eq 6
  k.rolling_radius_m = rolling_radius == RollingRadius::Mean ? 0.5 * (ra + rb) : std::min(ra, rb);
  return k;
}

}  // namespace gs::solver
