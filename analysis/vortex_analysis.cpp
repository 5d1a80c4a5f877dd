// Seed 000 pipeline: mesh (+ ghosts) -> HHD -> extrema -> tubes.
#include "vortex_analysis.hpp"

#include <chrono>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

VortexAnalysis analyze_vortices(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<Eigen::Vector3d>& vectors, int dim,
                                const VortexAnalysisOptions& o) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("dimension must be 2 or 3");
  if (points.size() != vectors.size()) {
    throw std::invalid_argument("one vector per point needed (" + std::to_string(vectors.size()) +
                                " for " + std::to_string(points.size()) + ")");
  }
  for (std::size_t i = 0; i < vectors.size(); ++i) {
    if (!vectors[i].head(dim).allFinite()) {
      throw std::invalid_argument("non-finite vector (point " + std::to_string(i) + ")");
    }
  }
  VortexAnalysis a;
  a.true_nodes = points.size();
  a.mesh.dim = dim;
  a.mesh.points = points;
  std::vector<Eigen::Vector3d>& nodal = a.vectors;
  nodal = vectors;
  for (auto& p : a.mesh.points)
    if (dim == 2) p.z() = 0.0;
  for (auto& v : nodal)
    if (dim == 2) v.z() = 0.0;
  auto t0 = std::chrono::steady_clock::now();
  if (o.ghosts) {
    const auto g = ghost_nodes(a.mesh.points, nodal, dim, o.ghost);
    a.mesh.points.insert(a.mesh.points.end(), g.position.begin(), g.position.end());
    nodal.insert(nodal.end(), g.vector.begin(), g.vector.end());
  }
  a.seconds_ghosts = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  DelaunayMesh d;
  if (dim == 3) {
    d = delaunay_mesh(a.mesh.points);
  } else {
    std::vector<Eigen::Vector2d> p2;
    p2.reserve(a.mesh.points.size());
    for (const auto& p : a.mesh.points) p2.push_back(p.head<2>());
    d = delaunay_mesh(p2);
  }
  a.mesh.simplices = std::move(d.simplices);
  a.mesh.dirichlet = std::move(d.on_hull);
  a.seconds_delaunay = seconds_since(t0);
  if (o.hhd.poll) o.hhd.poll();
  a.hhd = helmholtz_hodge(a.mesh, simplex_mean(a.mesh, nodal), o.hhd);
  t0 = std::chrono::steady_clock::now();
  a.rings = vertex_rings(dim, a.mesh.simplices, a.mesh.points.size());
  a.excluded = a.mesh.dirichlet;
  for (std::size_t i = a.true_nodes; i < a.excluded.size(); ++i) a.excluded[i] = 1;
  a.extrema = find_extrema(a.hhd, a.rings, a.excluded, o.axis);
  mark_significant(a.extrema, o.significance_relative, o.significance_absolute);
  a.significance_relative = o.significance_relative;
  a.significance_absolute = o.significance_absolute;
  if (o.tubes) {
    a.tubes = trace_vortex_tubes(a.mesh, a.hhd, a.rings, a.extrema, o.tube_delta, a.excluded);
  }
  a.seconds_detection = seconds_since(t0);
  return a;
}

std::array<std::size_t, 4> count_extrema(const std::vector<Extremum>& extrema,
                                         bool significant_only) {
  std::array<std::size_t, 4> c{0, 0, 0, 0};
  for (const auto& e : extrema)
    if (e.significant || !significant_only) ++c[static_cast<std::size_t>(e.kind)];
  return c;
}

std::size_t count_significant_tubes(const std::vector<VortexTube>& tubes,
                                    const std::vector<Extremum>& extrema) {
  std::size_t n = 0;
  for (const auto& t : tubes) n += extrema.at(t.extremum).significant ? 1 : 0;
  return n;
}

}  // namespace gs::analysis
