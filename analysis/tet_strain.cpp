// Delaunay simplex strain (seed 002 eq 4, Bagi 1996; 3D analogue as SPAM FfieldBagi).
#include "tet_strain.hpp"

#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template <class Vec>
void check_finite(const std::vector<Vec>& v, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].allFinite()) {
      throw std::invalid_argument(std::string("non-finite ") + what + " (point " +
                                  std::to_string(i) + ")");
    }
  }
}

// Per-particle and assembly averages over the good simplices; serial accumulation in simplex
// order, so the result does not depend on the thread count.
void average(SimplexStrain& r, std::size_t n_points, int nv) {
  r.particle_gradient.assign(n_points, Eigen::Matrix3d::Zero());
  r.particle_valid.assign(n_points, 0);
  std::vector<double> w(n_points, 0.0);
  r.mean_gradient.setZero();
  r.total_measure = 0.0;
  for (std::size_t t = 0; t < r.simplices.size(); ++t) {
    if (r.sliver[t]) continue;
    const double m = r.measure[t];
    r.mean_gradient += m * r.gradient[t];
    r.total_measure += m;
    for (int a = 0; a < nv; ++a) {
      const auto v = static_cast<std::size_t>(r.simplices[t][a]);
      r.particle_gradient[v] += m * r.gradient[t];
      w[v] += m;
    }
  }
  if (r.total_measure > 0.0) r.mean_gradient /= r.total_measure;
  for (std::size_t i = 0; i < n_points; ++i) {
    if (w[i] > 0.0) {
      r.particle_gradient[i] /= w[i];
      r.particle_valid[i] = 1;
    }
  }
}

}  // namespace

Eigen::Matrix3d tet_gradient(const std::array<Eigen::Vector3d, 4>& x,
                             const std::array<Eigen::Vector3d, 4>& u) {
  Eigen::Matrix3d dx, du;
  for (int a = 0; a < 3; ++a) {
    dx.col(a) = x[a + 1] - x[0];
    du.col(a) = u[a + 1] - u[0];
  }
  const double det = dx.determinant();
  const double scale = dx.colwise().norm().prod();
  if (!(std::abs(det) > 1e-14 * scale)) {
    throw std::invalid_argument("flat tetrahedron (volume " + std::to_string(det / 6.0) + ")");
  }
  // H dx = du  ->  H = du dx^{-1}; solve with partial-pivot LU on the transposed system.
  return dx.transpose().partialPivLu().solve(du.transpose()).transpose();
}

SimplexStrain tet_strain(const std::vector<Eigen::Vector3d>& reference,
                         const std::vector<Eigen::Vector3d>& displacement,
                         const SimplexStrainOptions& options) {
  if (reference.size() != displacement.size()) {
    throw std::invalid_argument("reference and displacement sizes differ (" +
                                std::to_string(reference.size()) + " vs " +
                                std::to_string(displacement.size()) + ")");
  }
  check_finite(displacement, "displacement");
  SimplexStrain r;
  r.dim = 3;
  auto t0 = std::chrono::steady_clock::now();
  r.simplices = options.radii.empty() ? delaunay_tetrahedra(reference)
                                      : regular_tetrahedra(reference, options.radii);
  r.seconds_delaunay = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  const auto n = static_cast<std::ptrdiff_t>(r.simplices.size());
  r.measure.assign(r.simplices.size(), 0.0);
  r.quality.assign(r.simplices.size(), 0.0);
  r.sliver.assign(r.simplices.size(), 1);
  r.gradient.assign(r.simplices.size(), Eigen::Matrix3d::Zero());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t t = 0; t < n; ++t) {
    const auto& s = r.simplices[static_cast<std::size_t>(t)];
    std::array<Eigen::Vector3d, 4> x, u;
    for (int a = 0; a < 4; ++a) {
      x[a] = reference[static_cast<std::size_t>(s[a])];
      u[a] = displacement[static_cast<std::size_t>(s[a])];
    }
    Eigen::Matrix3d dx, du;
    for (int a = 0; a < 3; ++a) {
      dx.col(a) = x[a + 1] - x[0];
      du.col(a) = u[a + 1] - u[0];
    }
    const double vol = dx.determinant() / 6.0;  // > 0: CGAL cells are positively oriented
    const auto ts = static_cast<std::size_t>(t);
    r.measure[ts] = std::abs(vol);
    r.quality[ts] = tetrahedron_quality(x, std::abs(vol));
    // A cell flat in floating point (quality ~ 0) keeps a zero gradient and is a sliver.
    if (r.quality[ts] > 1e-12) {
      r.gradient[ts] = dx.transpose().partialPivLu().solve(du.transpose()).transpose();
      r.sliver[ts] = r.quality[ts] < options.min_quality ? 1 : 0;
    }
  }
  r.seconds_gradients = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  average(r, reference.size(), 4);
  r.seconds_averaging = seconds_since(t0);
  return r;
}

SimplexStrain triangle_strain(const std::vector<Eigen::Vector2d>& reference,
                              const std::vector<Eigen::Vector2d>& displacement,
                              const SimplexStrainOptions& options) {
  if (reference.size() != displacement.size()) {
    throw std::invalid_argument("reference and displacement sizes differ (" +
                                std::to_string(reference.size()) + " vs " +
                                std::to_string(displacement.size()) + ")");
  }
  check_finite(displacement, "displacement");
  SimplexStrain r;
  r.dim = 2;
  auto t0 = std::chrono::steady_clock::now();
  const auto tris = delaunay_triangles(reference);
  r.seconds_delaunay = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  r.simplices.resize(tris.size());
  r.measure.assign(tris.size(), 0.0);
  r.quality.assign(tris.size(), 0.0);
  r.sliver.assign(tris.size(), 1);
  r.gradient.assign(tris.size(), Eigen::Matrix3d::Zero());
  const auto n = static_cast<std::ptrdiff_t>(tris.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t t = 0; t < n; ++t) {
    const auto ts = static_cast<std::size_t>(t);
    const auto& s = tris[ts];
    r.simplices[ts] = {s[0], s[1], s[2], -1};
    std::array<Eigen::Vector2d, 3> x, v;
    for (int a = 0; a < 3; ++a) {
      x[a] = reference[static_cast<std::size_t>(s[a])];
      v[a] = displacement[static_cast<std::size_t>(s[a])];
    }
    const Eigen::Vector2d e1 = x[1] - x[0], e2 = x[2] - x[0];
    const double area = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());  // > 0: CGAL faces are CCW
    r.measure[ts] = std::abs(area);
    r.quality[ts] = triangle_quality(x, std::abs(area));
    if (r.quality[ts] > 1e-12) {
      // Seed 002 eq 4: L_pq = 1/(6A) sum_{j1<j2} (v^{j1} - v^{j2})_p (b^{j1} - b^{j2})_q with
      // b^j the outward normal of the edge opposite vertex j, scaled by its length.
      std::array<Eigen::Vector2d, 3> b;
      for (int j = 0; j < 3; ++j) {
        const Eigen::Vector2d e = x[(j + 2) % 3] - x[(j + 1) % 3];  // CCW edge opposite j
        b[j] = Eigen::Vector2d(e.y(), -e.x());                      // outward for CCW
      }
      Eigen::Matrix2d l = Eigen::Matrix2d::Zero();
      for (int j1 = 0; j1 < 3; ++j1)
        for (int j2 = j1 + 1; j2 < 3; ++j2) l += (v[j1] - v[j2]) * (b[j1] - b[j2]).transpose();
      // Printed eq 4 with outward b gives -L (see kuhn_void_cells.cpp); sign corrected here.
      r.gradient[ts].topLeftCorner<2, 2>() = -l / (6.0 * area);
      r.sliver[ts] = r.quality[ts] < options.min_quality ? 1 : 0;
    }
  }
  r.seconds_gradients = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  average(r, reference.size(), 3);
  r.seconds_averaging = seconds_since(t0);
  return r;
}

StrainMeasures strain_measures(const Eigen::Matrix3d& h, int dim) {
  StrainMeasures m;
  m.strain = 0.5 * (h + h.transpose());
  m.rotation = 0.5 * (h - h.transpose());
  m.volumetric = m.strain.trace();
  Eigen::Matrix3d e = m.strain;
  if (dim == 2) {
    e.topLeftCorner<2, 2>() -= 0.5 * m.volumetric * Eigen::Matrix2d::Identity();
    m.equivalent_shear = std::sqrt(0.5 * e.squaredNorm());
  } else {
    e -= m.volumetric / 3.0 * Eigen::Matrix3d::Identity();
    m.equivalent_shear = std::sqrt(2.0 / 3.0 * e.squaredNorm());
  }
  return m;
}

}  // namespace gs::analysis
