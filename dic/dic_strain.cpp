#include "dic_strain.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace gs::dic {

StrainField plane_fit_strain(const PoiGrid& grid, const std::vector<double>& u,
                             const std::vector<double>& v, const std::vector<std::uint8_t>& valid,
                             int m, int subset_px) {
  if (m < 1) throw std::invalid_argument("strain window radius must be >= 1 POI");
  const auto n = static_cast<std::size_t>(grid.size());
  if (u.size() != n || v.size() != n || valid.size() != n)
    throw std::invalid_argument("plane_fit_strain: field sizes differ from the grid");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  StrainField s;
  s.window_radius = m;
  s.vsg_px = 2.0 * m * grid.step + subset_px;
  for (auto* vec : {&s.ux, &s.uy, &s.vx, &s.vy, &s.exx, &s.eyy, &s.exy, &s.sxx, &s.syy, &s.sxy})
    vec->assign(n, nan);
  s.valid.assign(n, 0);
  const int need = (2 * m + 1) * (2 * m + 1) / 2;
#pragma omp parallel for schedule(static)
  for (int idx = 0; idx < grid.size(); ++idx) {
    const auto c = static_cast<std::size_t>(idx);
    if (!valid[c]) continue;
    const int i = idx % grid.nx;
    const int j = idx / grid.nx;
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d bu = Eigen::Vector3d::Zero();
    Eigen::Vector3d bv = Eigen::Vector3d::Zero();
    int count = 0;
    for (int jj = std::max(0, j - m); jj <= std::min(grid.ny - 1, j + m); ++jj)
      for (int ii = std::max(0, i - m); ii <= std::min(grid.nx - 1, i + m); ++ii) {
        const auto q = static_cast<std::size_t>(jj * grid.nx + ii);
        if (!valid[q]) continue;
        const Eigen::Vector3d r(1.0, (ii - i) * grid.step, (jj - j) * grid.step);
        A += r * r.transpose();
        bu += r * u[q];
        bv += r * v[q];
        ++count;
      }
    if (count < need) continue;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) continue;
    const Eigen::Vector3d cu = ldlt.solve(bu);
    const Eigen::Vector3d cv = ldlt.solve(bv);
    const double ux = cu[1], uy = cu[2], vx = cv[1], vy = cv[2];
    s.ux[c] = ux;
    s.uy[c] = uy;
    s.vx[c] = vx;
    s.vy[c] = vy;
    s.exx[c] = ux + 0.5 * (ux * ux + vx * vx);
    s.eyy[c] = vy + 0.5 * (uy * uy + vy * vy);
    s.exy[c] = 0.5 * (uy + vx) + 0.5 * (ux * uy + vx * vy);
    s.sxx[c] = ux;
    s.syy[c] = vy;
    s.sxy[c] = 0.5 * (uy + vx);
    s.valid[c] = 1;
  }
  return s;
}

}  // namespace gs::dic
