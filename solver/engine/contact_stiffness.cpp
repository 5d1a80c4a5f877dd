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
  // Written as YADE's Ip2_CohFrictMat_CohFrictMat_CohFrictPhys evaluates them (harmonic means
  // of the two bodies' values, here equal), so that every contact rounds as YADE's does.
  const double e = young_ec, v = nu_c;
  k.kn = 2.0 * e * ra * e * rb / (e * ra + e * rb);  // seed 000 eq 2: Ec·2RaRb/(Ra+Rb)
  k.ks = v != 0 ? 2.0 * e * ra * v * e * rb * v / (e * ra * v + e * rb * v) : 0.0;  // eq 3: νc·Kn
  const double alpha = beta != 0 ? 2.0 * beta * beta / (beta + beta) : 0.0;
  k.kr = ra * rb * k.ks * alpha;  // seed 000 eq 6: β·Ks·Ra·Rb
  k.rolling_radius_m = rolling_radius == RollingRadius::Mean ? 0.5 * (ra + rb) : std::min(ra, rb);
  return k;
}

}  // namespace gs::solver
