// Ghost nodes of seed 000 §4.2.
#include "ghost_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

void check(const GhostOptions& o) {
  const auto bad = [](double x) { return !(x > 0.0) || !std::isfinite(x); };
  if (bad(o.spacing) || bad(o.extent) || bad(o.radius) || !(o.min_distance >= 0.0) ||
      !std::isfinite(o.min_distance)) {
    throw std::invalid_argument(
        "ghost options need spacing, extent, radius > 0 and min distance >= 0 (" +
        std::to_string(o.spacing) + ", " + std::to_string(o.extent) + ", " +
        std::to_string(o.radius) + ", " + std::to_string(o.min_distance) + ")");
  }
}

// Integer cell of a point on a grid of side `s` from origin `lo`.
Eigen::Vector3i cell_of(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, double s, int dim) {
  Eigen::Vector3i c = ((p - lo) / s).array().floor().cast<int>();
  if (dim == 2) c.z() = 0;
  return c;
}

struct CellKey {
  bool operator()(const Eigen::Vector3i& a, const Eigen::Vector3i& b) const {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  }
};

}  // namespace

GhostOptions paper_ghost_options(double d50, double width) {
  // Paper: 4.5 mm, 4 mm for d50 = 2.5 mm; 50 mm, 80 mm for b = 40 mm.
  return {1.8 * d50, 1.6 * d50, 1.25 * width, 2.0 * width};
}

Eigen::Vector3d gaussian_average(const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<Eigen::Vector3d>& vectors,
                                 const Eigen::Vector3d& at, double radius, int dim) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  double w = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector3d d = points[i] - at;
    if (dim == 2) d.z() = 0.0;
    const double wi = std::exp(-d.squaredNorm() / (radius * radius));
    s += wi * vectors[i];
    w += wi;
  }
  return w > 0.0 ? Eigen::Vector3d(s / w) : Eigen::Vector3d::Zero();
}

GhostNodes ghost_nodes(const std::vector<Eigen::Vector3d>& points,
                       const std::vector<Eigen::Vector3d>& vectors, int dim,
                       const GhostOptions& o) {
  check(o);
  if (points.size() != vectors.size() || points.empty()) {
    throw std::invalid_argument("ghost nodes need one vector per point (" +
                                std::to_string(vectors.size()) + " for " +
                                std::to_string(points.size()) + ")");
  }
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (dim == 2) lo.z() = hi.z() = 0.0;
  // Lattice: 2D triangular (rows h√3/2 apart, odd rows shifted h/2); 3D fcc with nearest
  // neighbour distance h (cubic cell a = h√2, 4 nodes per cell).
  const double h = o.spacing;
  std::vector<Eigen::Vector3d> basis;
  Eigen::Vector3d cell;
  if (dim == 2) {
    cell = Eigen::Vector3d(h, h * std::sqrt(3.0), 1.0);
    basis = {{0, 0, 0}, {0.5 * h, 0.5 * h * std::sqrt(3.0), 0}};
  } else {
    const double a = h * std::sqrt(2.0);
    cell = Eigen::Vector3d(a, a, a);
    basis = {{0, 0, 0}, {a / 2, a / 2, 0}, {a / 2, 0, a / 2}, {0, a / 2, a / 2}};
  }
  const Eigen::Vector3d glo = lo - Eigen::Vector3d::Constant(o.extent);
  const Eigen::Vector3d ghi = hi + Eigen::Vector3d::Constant(o.extent);
  Eigen::Vector3i count = ((ghi - glo).cwiseQuotient(cell)).array().ceil().cast<int>() + 1;
  if (dim == 2) count.z() = 1;
  const double total =
      static_cast<double>(count.x()) * count.y() * count.z() * static_cast<double>(basis.size());
  if (total > 1e7) {
    throw std::invalid_argument("ghost lattice too large (" + std::to_string(total) +
                                " nodes): increase the spacing or reduce the extent");
  }
  // Centres near the box surface, binned by d_min, for the distance test.
  const double bin = std::max(o.min_distance, 1e-12 * (hi - lo).norm());
  std::map<Eigen::Vector3i, std::vector<std::size_t>, CellKey> near;
  if (o.min_distance > 0.0) {
    for (std::size_t i = 0; i < points.size(); ++i)
      near[cell_of(points[i], glo, bin, dim)].push_back(i);
  }
  // A regular lattice is maximally degenerate for Delaunay (cospherical fcc / cocircular
  // triangular nodes): CGAL then leaves its fast filtered predicates for exact arithmetic (4 s
  // instead of 1 s for 2.7e5 nodes). A fixed pseudo-random shift of at most 1e-3 h per coordinate,
  // applied before the tests below, removes the degeneracy without changing the lattice in any
  // way that matters.
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> jitter(-1e-3 * h, 1e-3 * h);
  GhostNodes g;
  for (int k = 0; k < count.z(); ++k)
    for (int j = 0; j < count.y(); ++j)
      for (int i = 0; i < count.x(); ++i)
        for (const auto& b : basis) {
          Eigen::Vector3d p = glo + Eigen::Vector3d(i * cell.x(), j * cell.y(), k * cell.z()) + b +
                              Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
          if (dim == 2) p.z() = 0.0;
          // Outside the box of the centres, within D of it.
          const Eigen::Vector3d out = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
          const double dist = out.norm();
          if (!(dist > 0.0) || dist > o.extent) continue;
          if (dist < o.min_distance) {
            bool close = false;
            const Eigen::Vector3i c = cell_of(p, glo, bin, dim);
            for (int dz = (dim == 3 ? -1 : 0); dz <= (dim == 3 ? 1 : 0) && !close; ++dz)
              for (int dy = -1; dy <= 1 && !close; ++dy)
                for (int dx = -1; dx <= 1 && !close; ++dx) {
                  const auto it = near.find(c + Eigen::Vector3i(dx, dy, dz));
                  if (it == near.end()) continue;
                  for (const auto q : it->second) {
                    Eigen::Vector3d d = points[q] - p;
                    if (dim == 2) d.z() = 0.0;
                    if (d.norm() < o.min_distance) {
                      close = true;
                      break;
                    }
                  }
                }
            if (close) continue;
          }
          g.position.push_back(p);
        }
  // Gaussian average over binned true nodes (header comment).
  const double side = o.radius / 8.0;
  struct Bin {
    double n = 0.0;
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
  };
  std::map<Eigen::Vector3i, Bin, CellKey> bins;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Bin& b = bins[cell_of(points[i], lo, side, dim)];
    b.n += 1.0;
    b.x += points[i];
    b.v += vectors[i];
  }
  std::vector<Bin> list;
  list.reserve(bins.size());
  for (auto& [key, b] : bins) {
    b.x /= b.n;
    if (dim == 2) b.x.z() = 0.0;
    list.push_back(b);
  }
  g.vector.assign(g.position.size(), Eigen::Vector3d::Zero());
  const auto ng = static_cast<std::ptrdiff_t>(g.position.size());
  const double r2 = o.radius * o.radius;
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t q = 0; q < ng; ++q) {
    const Eigen::Vector3d& p = g.position[static_cast<std::size_t>(q)];
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    double w = 0.0;
    for (const auto& b : list) {
      const double wb = std::exp(-(b.x - p).squaredNorm() / r2);
      s += wb * b.v;
      w += wb * b.n;
    }
    g.vector[static_cast<std::size_t>(q)] =
        w > 0.0 ? Eigen::Vector3d(s / w) : Eigen::Vector3d::Zero();
  }
  return g;
}

}  // namespace gs::analysis
