#include "periodic_cell.hpp"

#include <cmath>

namespace gs::solver {

Eigen::Vector3d PeriodicCell::wrap(const Eigen::Vector3d& x) const {
  Eigen::Vector3d s = hsize.inverse() * x;
  for (int k = 0; k < 3; ++k) s[k] -= std::floor(s[k]);
  return hsize * s;
}

Eigen::Vector3d PeriodicCell::widths() const {
  // The faces s_k = 0 and s_k = 1 are 1/|row k of H⁻¹| apart.
  const Eigen::Matrix3d inv = hsize.inverse();
  return {1 / inv.row(0).norm(), 1 / inv.row(1).norm(), 1 / inv.row(2).norm()};
}

}  // namespace gs::solver
