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
  // The normal equations of each window, A = sum w r r^T, bu = sum w r u, bv = sum w r v with
  // r = (1, dx, dy) (px) and w = valid, are separable sums: first along x over the row (the
  // moments 0, 1, 2 of w and 0, 1 of w u, w v in dx), then along y (times 1, dy, dy^2). The
  // window coordinates stay local and exact: no running sums, no cancellation.
  const int nx = grid.nx, ny = grid.ny;
  const double h = grid.step;
  enum { W0, W1, W2, U0, U1, V0, V1, kRow };
  std::vector<double> rows(static_cast<std::size_t>(kRow) * n);
  const auto at = [&](int k, std::size_t c) -> double& {
    return rows[static_cast<std::size_t>(k) * n + c];
  };
#pragma omp parallel for schedule(static)
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      double t[kRow] = {};
      for (int ii = std::max(0, i - m); ii <= std::min(nx - 1, i + m); ++ii) {
        const auto q = static_cast<std::size_t>(j * nx + ii);
        if (!valid[q]) continue;
        const double dx = (ii - i) * h;
        t[W0] += 1.0;
        t[W1] += dx;
        t[W2] += dx * dx;
        t[U0] += u[q];
        t[U1] += dx * u[q];
        t[V0] += v[q];
        t[V1] += dx * v[q];
      }
      for (int k = 0; k < kRow; ++k) at(k, static_cast<std::size_t>(j * nx + i)) = t[k];
    }
#pragma omp parallel for schedule(static)
  for (int idx = 0; idx < grid.size(); ++idx) {
    const auto c = static_cast<std::size_t>(idx);
    if (!valid[c]) continue;
    const int i = idx % nx;
    const int j = idx / nx;
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d bu = Eigen::Vector3d::Zero();
    Eigen::Vector3d bv = Eigen::Vector3d::Zero();
    double w = 0.0;
    for (int jj = std::max(0, j - m); jj <= std::min(ny - 1, j + m); ++jj) {
      const auto q = static_cast<std::size_t>(jj * nx + i);
      const double dy = (jj - j) * h;
      w += at(W0, q);
      A(0, 1) += at(W1, q);
      A(0, 2) += dy * at(W0, q);
      A(1, 1) += at(W2, q);
      A(1, 2) += dy * at(W1, q);
      A(2, 2) += dy * dy * at(W0, q);
      bu[0] += at(U0, q);
      bu[1] += at(U1, q);
      bu[2] += dy * at(U0, q);
      bv[0] += at(V0, q);
      bv[1] += at(V1, q);
      bv[2] += dy * at(V0, q);
    }
    A(0, 0) = w;
    A(1, 0) = A(0, 1);
    A(2, 0) = A(0, 2);
    A(2, 1) = A(1, 2);
    const auto count = static_cast<int>(w);
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
