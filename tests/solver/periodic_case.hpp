// The material of the shared YADE periodic cases (../shared/reference/yade/periodic{,2d}/
// case.json: CohFrictMat young 3e7, poisson 0.3, 25°, 2550 kg/m³, alphaKr 0.5, etaRoll 0.3),
// shared by the reference test and the exact periodic tests.
#pragma once

#include "simulation.hpp"

namespace gs::test {

inline solver::Material periodic_material() {
  solver::Material m;
  m.young_ec = 3.0e7;
  m.stiffness_ratio = 0.3;
  m.friction_deg = 25.0;
  m.density = 2550.0;
  m.rolling_beta = 0.5;
  m.rolling_eta = 0.3;
  m.rolling_radius = solver::RollingRadius::Min;
  return m;
}

}  // namespace gs::test
