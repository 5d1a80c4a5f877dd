#include "silo_theory.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::analysis {

double drescher_lateral_ratio(double phi_i_deg, double phi_w_deg) {
  if (!(phi_w_deg > 0) || !(phi_w_deg <= phi_i_deg) || !(phi_i_deg < 90))
    throw std::invalid_argument("Eq 5.2 needs 0 < phi_w <= phi_i < 90 deg (phi_i " +
                                std::to_string(phi_i_deg) + ", phi_w " + std::to_string(phi_w_deg) +
                                ")");
  const double rad = M_PI / 180.0;
  const double si = std::sin(phi_i_deg * rad), w = phi_w_deg * rad;
  const double a = std::asin(std::sin(w) / si) + w;  // seed 004 Eq 5.2
  return si * std::sin(a) / (1 - si * std::cos(a)) / std::tan(w);
}

double janssen_vertical_stress(double gamma, double K, double mu, double R, double h) {
  if (!(gamma > 0) || !(K > 0) || !(mu > 0) || !(R > 0) || !(h >= 0) || !std::isfinite(h))
    throw std::invalid_argument("Eq 5.1 needs positive gamma, K, mu, R and a depth >= 0");
  const double z0 = R / (K * mu);            // Janssen's characteristic depth
  return gamma * z0 * -std::expm1(-h / z0);  // seed 004 Eq 5.1: γR/(Kμ)·(1 − e^(−Kμh/R))
}

}  // namespace gs::analysis
