// Meshes and analytic fields shared by the HHD tests and bench/bench_hhd.cpp.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "delaunay_mesh.hpp"
#include "hhd.hpp"

namespace gs::test {

/// Jittered lattice of (n+1)^dim nodes in the unit square/cube: interior nodes moved by up to
/// ±jitter·h per coordinate (h = 1/n), nodes on the boundary moved only along it, so the hull is
/// exactly the unit box. Dirichlet nodes = the hull.
inline analysis::HhdMesh box_mesh(int dim, int n, unsigned seed, double jitter = 0.25) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-jitter / n, jitter / n);
  analysis::HhdMesh m;
  m.dim = dim;
  const int nk = dim == 3 ? n : 0;
  for (int k = 0; k <= nk; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const int ijk[3] = {i, j, k};
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (int d = 0; d < dim; ++d) {
          const bool on_face = ijk[d] == 0 || ijk[d] == n;
          p[d] = static_cast<double>(ijk[d]) / n + (on_face ? 0.0 : u(rng));
        }
        m.points.push_back(p);
      }
  analysis::DelaunayMesh d;
  if (dim == 3) {
    d = analysis::delaunay_mesh(m.points);
  } else {
    std::vector<Eigen::Vector2d> p2;
    for (const auto& p : m.points) p2.push_back(p.head<2>());
    d = analysis::delaunay_mesh(p2);
  }
  m.simplices = d.simplices;
  m.dirichlet = d.on_hull;
  return m;
}

/// Smooth test field on the unit box with an exact N-P decomposition (docs/hhd.md):
///   U = sin(πx) sin(πy) [sin(πz)]            (zero on the boundary)
///   2D: V = sin(πx) sin(2πy) (scalar v_z, zero on the boundary)
///   3D: V = ∇×(0, 0, ψ), ψ = (x(1−x) y(1−y) z(1−z))² · 64: divergence-free, zero on the boundary
///   ξ = ∇U + ∇×V + c, so u = U, v = V, h = c exactly for the continuous problem (2D; 3D with
///   the Coulomb gauge of path (b), which V satisfies).
struct AnalyticField {
  int dim = 3;
  Eigen::Vector3d c{0.3, -0.2, 0.1};
  static constexpr double pi = std::numbers::pi;

  double U(const Eigen::Vector3d& x) const {
    double s = std::sin(pi * x.x()) * std::sin(pi * x.y());
    return dim == 3 ? s * std::sin(pi * x.z()) : s;
  }
  Eigen::Vector3d grad_U(const Eigen::Vector3d& x) const {
    const double sx = std::sin(pi * x.x()), sy = std::sin(pi * x.y());
    const double cx = std::cos(pi * x.x()), cy = std::cos(pi * x.y());
    if (dim == 2) return pi * Eigen::Vector3d(cx * sy, sx * cy, 0.0);
    const double sz = std::sin(pi * x.z()), cz = std::cos(pi * x.z());
    return pi * Eigen::Vector3d(cx * sy * sz, sx * cy * sz, sx * sy * cz);
  }
  // 3D: ψ = 64 q², q = x(1−x) y(1−y) z(1−z); V = (∂_y ψ, −∂_x ψ, 0).
  static double q1(double t) { return t * (1 - t); }
  static double dq1(double t) { return 1 - 2 * t; }
  static double ddq1() { return -2.0; }
  /// Vector potential (3D: 3 components; 2D: v_z in x()).
  Eigen::Vector3d V(const Eigen::Vector3d& x) const {
    if (dim == 2) return Eigen::Vector3d(std::sin(pi * x.x()) * std::sin(2 * pi * x.y()), 0, 0);
    const double q = q1(x.x()) * q1(x.y()) * q1(x.z());
    const double qx = dq1(x.x()) * q1(x.y()) * q1(x.z());
    const double qy = q1(x.x()) * dq1(x.y()) * q1(x.z());
    return 128.0 * q * Eigen::Vector3d(qy, -qx, 0.0);
  }
  Eigen::Vector3d curl_V(const Eigen::Vector3d& x) const {
    if (dim == 2) {
      // (∂_y v, −∂_x v)
      return Eigen::Vector3d(2 * pi * std::sin(pi * x.x()) * std::cos(2 * pi * x.y()),
                             -pi * std::cos(pi * x.x()) * std::sin(2 * pi * x.y()), 0.0);
    }
    // V = ∇×(0,0,ψ) => ∇×V = ∇(∂_z ψ) − Δψ e_z... computed from ψ = 64 q²:
    // ∇×V = (∂_x ∂_z ψ, ∂_y ∂_z ψ, −∂_xx ψ − ∂_yy ψ).
    const double a = q1(x.x()), b = q1(x.y()), cz = q1(x.z());
    const double da = dq1(x.x()), db = dq1(x.y()), dc = dq1(x.z());
    const double q = a * b * cz;
    const double qx = da * b * cz, qy = a * db * cz, qz = a * b * dc;
    const double qxz = da * b * dc, qyz = a * db * dc;
    const double qxx = ddq1() * b * cz, qyy = a * ddq1() * cz;
    // ψ = 64 q²: ψ_ij = 128 (q_i q_j + q q_ij)
    const double pxz = 128 * (qx * qz + q * qxz), pyz = 128 * (qy * qz + q * qyz);
    const double pxx = 128 * (qx * qx + q * qxx), pyy = 128 * (qy * qy + q * qyy);
    return Eigen::Vector3d(pxz, pyz, -pxx - pyy);
  }
  Eigen::Vector3d xi(const Eigen::Vector3d& x) const {
    Eigen::Vector3d c2 = c;
    if (dim == 2) c2.z() = 0.0;
    return grad_U(x) + curl_V(x) + c2;
  }
};

/// N uniformly random points in the unit cube (seeded), their Delaunay mesh, Dirichlet = hull:
/// an irregular mesh with slivers, as DEM centres and users' point clouds give.
inline analysis::HhdMesh random_cube_mesh(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  analysis::HhdMesh m;
  m.dim = 3;
  for (std::size_t i = 0; i < n; ++i) m.points.emplace_back(u(rng), u(rng), u(rng));
  const auto d = analysis::delaunay_mesh(m.points);
  m.simplices = d.simplices;
  m.dirichlet = d.on_hull;
  return m;
}

/// The field a new user tries first (issue 20's table): a Lamb–Oseen vortex along z through
/// (0.5, 0.5) (circulation 1, core radius 0.1), a Gaussian source at (0.3, 0.6, 0.4) (width 0.1)
/// and a uniform translation (0.2, 0.1, 0). Its vortex crosses the hull, so its N-P vector
/// potential is not divergence-free: paths (a) and (b) differ on it.
inline Eigen::Vector3d vortex_source_translation(const Eigen::Vector3d& p) {
  const double rc = 0.1, circulation = 1.0, s = 0.1;
  const Eigen::Vector3d d(p.x() - 0.5, p.y() - 0.5, 0.0);
  const double r2 = d.squaredNorm();
  Eigen::Vector3d vortex = Eigen::Vector3d::Zero();
  if (r2 > 0.0) {
    vortex = circulation / (2.0 * std::numbers::pi * r2) * (1.0 - std::exp(-r2 / (rc * rc))) *
             Eigen::Vector3d(-d.y(), d.x(), 0.0);
  }
  const Eigen::Vector3d e = p - Eigen::Vector3d(0.3, 0.6, 0.4);
  const Eigen::Vector3d source = 0.5 * e * std::exp(-e.squaredNorm() / (2 * s * s)) / (s * s);
  return vortex + source + Eigen::Vector3d(0.2, 0.1, 0.0);
}

}  // namespace gs::test
