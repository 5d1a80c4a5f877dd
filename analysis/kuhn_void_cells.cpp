// Seed 002 (Kuhn): §3 sharpest-turn face traversal, Fig. 4 removals, eq 16 Euler check, eq 7
// void-cell velocity gradient with the consistent Q^m of eq 11, eq 3 assembly average, eq 18-21;
// eq 4 (Bagi) for triangles.
#include "kuhn_void_cells.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <stdexcept>
#include <string>

#include "consistent_q_matrices.hpp"

namespace gs::analysis {
namespace {

enum Kind : std::uint8_t { kActive = 0, kIsolated, kPendant, kPeninsular, kIsland };

// Doubly-connected edge list over the active edges: half-edge 2e runs a->b, 2e+1 runs b->a.
struct Dcel {
  const ParticleGraph& g;
  const std::vector<std::uint8_t>& active;
  std::vector<std::vector<std::int32_t>> out;  // per vertex, outgoing half-edges by angle (CCW)
  std::vector<std::int32_t> slot;              // position of a half-edge in its origin's list
  std::vector<std::int32_t> face;              // face of each half-edge (-1: inactive)
  std::int32_t n_faces = 0;

  std::int32_t origin(std::int32_t h) const {
    const auto& e = g.edges[static_cast<std::size_t>(h / 2)];
    return h % 2 == 0 ? e.a : e.b;
  }
  std::int32_t dest(std::int32_t h) const { return origin(h ^ 1); }
  Eigen::Vector2i shift(std::int32_t h) const {
    const auto& e = g.edges[static_cast<std::size_t>(h / 2)];
    return h % 2 == 0 ? e.shift : Eigen::Vector2i(-e.shift);
  }
  Eigen::Vector2d vec(std::int32_t h) const {
    const Eigen::Vector2d d = g.branch(static_cast<std::size_t>(h / 2));
    return h % 2 == 0 ? d : Eigen::Vector2d(-d);
  }
  // Sharpest turn at the head of h: the outgoing edge next clockwise from the twin.
  std::int32_t next(std::int32_t h) const {
    const auto& list = out[static_cast<std::size_t>(dest(h))];
    const auto k = static_cast<std::size_t>(slot[static_cast<std::size_t>(h ^ 1)]);
    return list[(k + list.size() - 1) % list.size()];
  }

  Dcel(const ParticleGraph& graph, const std::vector<std::uint8_t>& edge_active)
      : g(graph), active(edge_active) {
    const std::size_t nh = 2 * g.edges.size();
    out.assign(g.position.size(), {});
    slot.assign(nh, -1);
    face.assign(nh, -1);
    std::vector<double> angle(nh, 0.0);
    for (std::size_t e = 0; e < g.edges.size(); ++e) {
      if (!active[e]) continue;
      for (int s = 0; s < 2; ++s) {
        const auto h = static_cast<std::int32_t>(2 * e + static_cast<std::size_t>(s));
        const Eigen::Vector2d d = vec(h);
        angle[static_cast<std::size_t>(h)] = std::atan2(d.y(), d.x());
        out[static_cast<std::size_t>(origin(h))].push_back(h);
      }
    }
    for (auto& list : out) {
      std::sort(list.begin(), list.end(), [&](std::int32_t x, std::int32_t y) {
        const double ax = angle[static_cast<std::size_t>(x)];
        const double ay = angle[static_cast<std::size_t>(y)];
        return ax != ay ? ax < ay : x < y;
      });
      for (std::size_t k = 0; k < list.size(); ++k)
        slot[static_cast<std::size_t>(list[k])] = static_cast<std::int32_t>(k);
    }
    // Faces, scanning the particles in order (each particle the root of its circuits).
    for (const auto& list : out) {
      for (const auto h0 : list) {
        if (face[static_cast<std::size_t>(h0)] >= 0) continue;
        std::int32_t h = h0;
        do {
          face[static_cast<std::size_t>(h)] = n_faces;
          h = next(h);
        } while (h != h0);
        ++n_faces;
      }
    }
  }
};

std::vector<std::int32_t> degrees(const ParticleGraph& g, const std::vector<std::uint8_t>& act) {
  std::vector<std::int32_t> deg(g.position.size(), 0);
  for (std::size_t e = 0; e < g.edges.size(); ++e) {
    if (!act[e]) continue;
    ++deg[static_cast<std::size_t>(g.edges[e].a)];
    ++deg[static_cast<std::size_t>(g.edges[e].b)];
  }
  return deg;
}

}  // namespace

VoidCellGraph find_void_cells(const ParticleGraph& g) {
  const std::size_t n = g.position.size(), m = g.edges.size();
  VoidCellGraph r;
  r.expected_euler = g.periodic ? 0 : 1;
  r.edge_active.assign(m, 1);
  std::vector<std::uint8_t> kind(n, kActive);
  std::vector<std::uint8_t> bridge_end(n, 0);
  std::vector<std::vector<std::int32_t>> incident(n);
  for (std::size_t e = 0; e < m; ++e) {
    incident[static_cast<std::size_t>(g.edges[e].a)].push_back(static_cast<std::int32_t>(e));
    incident[static_cast<std::size_t>(g.edges[e].b)].push_back(static_cast<std::int32_t>(e));
  }
  auto deg = degrees(g, r.edge_active);
  for (std::size_t v = 0; v < n; ++v)
    if (deg[v] == 0) kind[v] = kIsolated;

  for (;;) {
    // Pendants: strip degree-1 vertices until none is left.
    std::queue<std::size_t> q;
    for (std::size_t v = 0; v < n; ++v)
      if (deg[v] == 1) q.push(v);
    while (!q.empty()) {
      const std::size_t v = q.front();
      q.pop();
      if (deg[v] != 1) continue;
      for (const auto e : incident[v]) {
        if (!r.edge_active[static_cast<std::size_t>(e)]) continue;
        r.edge_active[static_cast<std::size_t>(e)] = 0;
        const auto& ed = g.edges[static_cast<std::size_t>(e)];
        const auto u = static_cast<std::size_t>(ed.a == static_cast<std::int32_t>(v) ? ed.b : ed.a);
        --deg[v];
        --deg[u];
        if (deg[u] == 1) q.push(u);
        if (deg[u] == 0 && kind[u] == kActive) kind[u] = bridge_end[u] ? kPeninsular : kPendant;
      }
      if (kind[v] == kActive) kind[v] = bridge_end[v] ? kPeninsular : kPendant;
    }
    // Peninsular connections: an edge with the same face on both sides.
    const Dcel d(g, r.edge_active);
    bool removed = false;
    for (std::size_t e = 0; e < m; ++e) {
      if (!r.edge_active[e] || d.face[2 * e] != d.face[2 * e + 1]) continue;
      r.edge_active[e] = 0;
      removed = true;
      for (const auto v : {g.edges[e].a, g.edges[e].b}) {
        const auto vs = static_cast<std::size_t>(v);
        bridge_end[vs] = 1;
        if (--deg[vs] == 0 && kind[vs] == kActive) kind[vs] = kPeninsular;
      }
    }
    if (!removed) break;
  }

  // Islands: keep the largest connected component (ties: the one with the lowest vertex).
  std::vector<std::int32_t> comp(n, -1);
  std::vector<std::int64_t> comp_size;
  for (std::size_t s = 0; s < n; ++s) {
    if (kind[s] != kActive || comp[s] >= 0) continue;
    const auto c = static_cast<std::int32_t>(comp_size.size());
    comp_size.push_back(0);
    std::vector<std::size_t> stack{s};
    comp[s] = c;
    while (!stack.empty()) {
      const auto v = stack.back();
      stack.pop_back();
      ++comp_size.back();
      for (const auto e : incident[v]) {
        if (!r.edge_active[static_cast<std::size_t>(e)]) continue;
        const auto& ed = g.edges[static_cast<std::size_t>(e)];
        const auto u = static_cast<std::size_t>(ed.a == static_cast<std::int32_t>(v) ? ed.b : ed.a);
        if (comp[u] < 0) {
          comp[u] = c;
          stack.push_back(u);
        }
      }
    }
  }
  if (comp_size.empty()) {
    throw std::invalid_argument(
        "no void cells: every particle was removed (isolated, pendant, "
        "peninsular or island)");
  }
  const auto keep = static_cast<std::int32_t>(std::max_element(comp_size.begin(), comp_size.end()) -
                                              comp_size.begin());
  std::vector<std::uint8_t> comp_bridge(comp_size.size(), 0);
  for (std::size_t v = 0; v < n; ++v)
    if (comp[v] >= 0 && bridge_end[v]) comp_bridge[static_cast<std::size_t>(comp[v])] = 1;
  for (std::size_t v = 0; v < n; ++v) {
    if (comp[v] < 0 || comp[v] == keep) continue;
    kind[v] = comp_bridge[static_cast<std::size_t>(comp[v])] ? kPeninsular : kIsland;
  }
  for (std::size_t e = 0; e < m; ++e) {
    if (r.edge_active[e] && comp[static_cast<std::size_t>(g.edges[e].a)] != keep) {
      r.edge_active[e] = 0;
    }
  }

  r.vertex_active.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    switch (kind[v]) {
      case kActive:
        r.vertex_active[v] = 1;
        ++r.vertices;
        break;
      case kIsolated:
        ++r.removed_isolated;
        break;
      case kPendant:
        ++r.removed_pendant;
        break;
      case kPeninsular:
        ++r.removed_peninsular;
        break;
      default:
        ++r.removed_island;
        break;
    }
  }
  for (std::size_t e = 0; e < m; ++e) r.edges += r.edge_active[e];

  // Final faces: unwrapped polygons; the bounded graph's outer face (most negative area) and
  // any non-contractible or flat face on the torus are not void cells.
  const Dcel d(g, r.edge_active);
  std::vector<VoidCell> faces(static_cast<std::size_t>(d.n_faces));
  std::vector<std::uint8_t> closed(faces.size(), 0);
  std::vector<std::uint8_t> done(2 * m, 0);
  for (std::size_t h0 = 0; h0 < 2 * m; ++h0) {
    if (d.face[h0] < 0 || done[h0]) continue;
    auto& f = faces[static_cast<std::size_t>(d.face[h0])];
    Eigen::Vector2i s = Eigen::Vector2i::Zero();
    auto h = static_cast<std::int32_t>(h0);
    do {
      done[static_cast<std::size_t>(h)] = 1;
      f.vertices.push_back(d.origin(h));
      f.image.push_back(s);
      s += d.shift(h);
      h = d.next(h);
    } while (h != static_cast<std::int32_t>(h0));
    closed[static_cast<std::size_t>(d.face[h0])] = s.isZero() ? 1 : 0;
    double a2 = 0.0;
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    const std::size_t k = f.vertices.size();
    std::vector<Eigen::Vector2d> x(k);
    for (std::size_t i = 0; i < k; ++i) {
      x[i] =
          g.position[static_cast<std::size_t>(f.vertices[i])] + g.cell * f.image[i].cast<double>();
    }
    for (std::size_t i = 0; i < k; ++i) {  // shoelace relative to vertex 0
      const Eigen::Vector2d p = x[i] - x[0];
      const Eigen::Vector2d q2 = x[(i + 1) % k] - x[0];
      const double cr = p.x() * q2.y() - p.y() * q2.x();
      a2 += cr;
      c += cr * (p + q2);
    }
    f.area = 0.5 * a2;
    f.centroid = x[0] + (a2 != 0.0 ? Eigen::Vector2d(c / (3.0 * a2)) : Eigen::Vector2d::Zero());
  }
  std::size_t outer = faces.size();
  if (!g.periodic) {
    double amin = 0.0;
    for (std::size_t i = 0; i < faces.size(); ++i) {
      if (faces[i].area < amin) {
        amin = faces[i].area;
        outer = i;
      }
    }
  }
  r.faces = d.n_faces - (g.periodic ? 0 : 1);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (i == outer || !closed[i] || !(faces[i].area > 0.0)) continue;
    r.cells.push_back(std::move(faces[i]));
  }
  return r;
}

Eigen::Matrix2d void_cell_gradient(const std::vector<Eigen::Vector2d>& x,
                                   const std::vector<Eigen::Vector2d>& v) {
  const std::size_t m = x.size();
  if (m < 3 || v.size() != m) {
    throw std::invalid_argument("void cell needs >= 3 vertices and one velocity each (" +
                                std::to_string(m) + ", " + std::to_string(v.size()) + ")");
  }
  thread_local std::map<std::size_t, std::vector<double>> q_cache;
  auto it = q_cache.find(m);
  if (it == q_cache.end()) {
    it = q_cache.emplace(m, consistent_q_separations(static_cast<int>(m))).first;
  }
  const auto& q = it->second;
  std::vector<Eigen::Vector2d> vhat(m), b(m);
  double a2 = 0.0;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t j1 = (j + 1) % m;
    vhat[j] = v[j1] - v[j];  // eq 5
    const Eigen::Vector2d e = x[j1] - x[j];
    b[j] = Eigen::Vector2d(e.y(), -e.x());  // outward normal x length (CCW polygon)
    // Shoelace relative to vertex 0: no cancellation of large absolute coordinates.
    const Eigen::Vector2d p = x[j] - x[0], q2 = x[j1] - x[0];
    a2 += p.x() * q2.y() - p.y() * q2.x();
  }
  if (!(a2 > 0.0)) {
    throw std::invalid_argument("void cell with non-positive area (" + std::to_string(0.5 * a2) +
                                ")");
  }
  Eigen::Matrix2d l = Eigen::Matrix2d::Zero();
  for (std::size_t j1 = 0; j1 < m; ++j1) {
    for (std::size_t j2 = 0; j2 < m; ++j2) {
      const double qv = q[(j2 + m - j1) % m];
      if (qv != 0.0) l += qv * vhat[j1] * b[j2].transpose();
    }
  }
  return l / (3.0 * a2);  // 1 / (6 A)
}

Eigen::Matrix2d bagi_triangle_gradient(const std::array<Eigen::Vector2d, 3>& x,
                                       const std::array<Eigen::Vector2d, 3>& v) {
  std::array<Eigen::Vector2d, 3> b;
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector2d e =
        x[static_cast<std::size_t>((j + 2) % 3)] - x[static_cast<std::size_t>((j + 1) % 3)];
    b[static_cast<std::size_t>(j)] = Eigen::Vector2d(e.y(), -e.x());
  }
  const Eigen::Vector2d e1 = x[1] - x[0], e2 = x[2] - x[0];
  const double area = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  if (!(area > 0.0)) {
    throw std::invalid_argument("triangle not counterclockwise or flat (area " +
                                std::to_string(area) + ")");
  }
  Eigen::Matrix2d l = Eigen::Matrix2d::Zero();
  for (std::size_t j1 = 0; j1 < 3; ++j1)
    for (std::size_t j2 = j1 + 1; j2 < 3; ++j2) l += (v[j1] - v[j2]) * (b[j1] - b[j2]).transpose();
  // Eq 4 as printed, with b the OUTWARD normals, gives -L (check: x = (0,0), (1,0), (0,1),
  // v = x gives -I); the sign here reproduces every affine field exactly (docs/strain.md).
  return -l / (6.0 * area);
}

double alignment(const Eigen::Matrix2d& local, const Eigen::Matrix2d& mean) {
  const double a = local.norm(), b = mean.norm();                                    // eq 19
  return a > 0.0 && b > 0.0 ? (local.array() * mean.array()).sum() / (a * b) : 0.0;  // eq 18
}

double normalised_vorticity(const Eigen::Matrix2d& local, const Eigen::Matrix2d& mean) {
  const double b = mean.norm();
  return b > 0.0 ? -(local(0, 1) - local(1, 0)) / b : 0.0;  // eq 20
}

VoidCellDeformation void_cell_deformation(const ParticleGraph& g, const VoidCellGraph& cells,
                                          const std::vector<Eigen::Vector2d>& velocity, double d50,
                                          const Eigen::Matrix2d& cell_rate) {
  if (velocity.size() != g.position.size()) {
    throw std::invalid_argument("one velocity per particle needed (" +
                                std::to_string(velocity.size()) + " for " +
                                std::to_string(g.position.size()) + ")");
  }
  for (std::size_t i = 0; i < velocity.size(); ++i) {
    if (!velocity[i].allFinite()) {
      throw std::invalid_argument("non-finite velocity (index " + std::to_string(i) + ")");
    }
  }
  if (!(d50 > 0.0)) throw std::invalid_argument("d50 must be > 0 (" + std::to_string(d50) + ")");
  VoidCellDeformation r;
  const auto nc = static_cast<std::ptrdiff_t>(cells.cells.size());
  r.gradient.assign(cells.cells.size(), Eigen::Matrix2d::Zero());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < nc; ++i) {
    const auto& c = cells.cells[static_cast<std::size_t>(i)];
    std::vector<Eigen::Vector2d> x(c.vertices.size()), v(c.vertices.size());
    for (std::size_t k = 0; k < x.size(); ++k) {
      const auto p = static_cast<std::size_t>(c.vertices[k]);
      const Eigen::Vector2d s = c.image[k].cast<double>();
      x[k] = g.position[p] + g.cell * s;
      v[k] = velocity[p] + cell_rate * s;
    }
    r.gradient[static_cast<std::size_t>(i)] = void_cell_gradient(x, v);
  }
  double area = 0.0;
  for (std::size_t i = 0; i < cells.cells.size(); ++i) {  // eq 3, serial: deterministic
    r.mean += cells.cells[i].area * r.gradient[i];
    area += cells.cells[i].area;
  }
  if (area > 0.0) r.mean /= area;
  const double norm = r.mean.norm();  // eq 19
  r.alpha.assign(cells.cells.size(), 0.0);
  r.w.assign(cells.cells.size(), 0.0);
  for (std::size_t i = 0; i < cells.cells.size(); ++i) {
    r.alpha[i] = alignment(r.gradient[i], r.mean);
    r.w[i] = normalised_vorticity(r.gradient[i], r.mean);
  }
  r.relative_velocity_scale = d50 * std::abs(r.mean(1, 1));
  if (!(r.relative_velocity_scale > 0.0)) r.relative_velocity_scale = d50 * norm;
  r.relative_velocity.assign(g.position.size(), Eigen::Vector2d::Zero());
  if (r.relative_velocity_scale > 0.0) {
    for (std::size_t k = 0; k < g.position.size(); ++k) {
      if (!cells.vertex_active[k]) continue;
      r.relative_velocity[k] =
          (velocity[k] - r.mean * g.position[k]) / r.relative_velocity_scale;  // eq 21
    }
  }
  return r;
}

}  // namespace gs::analysis
