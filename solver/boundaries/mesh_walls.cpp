#include "mesh_walls.hpp"

#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <stdexcept>

#include "triangle_facet.hpp"

namespace gs::solver {

namespace {

int find(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i)
    i = parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
  return i;
}

Eigen::Vector3d unit_normal(const std::array<Eigen::Vector3d, 3>& t) {
  return (t[1] - t[0]).cross(t[2] - t[1]).normalized();
}

}  // namespace

std::vector<int> flat_regions(const MeshTriangles& mesh, double angle_tol, double offset_tol) {
  const std::size_t n = mesh.triangles.size();
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  // Edges by their (sorted) end points.
  using Key = std::array<double, 6>;
  std::map<Key, std::vector<std::size_t>> edges;
  for (std::size_t t = 0; t < n; ++t)
    for (int e = 0; e < 3; ++e) {
      Eigen::Vector3d a = mesh.triangles[t][static_cast<std::size_t>(e)];
      Eigen::Vector3d b = mesh.triangles[t][static_cast<std::size_t>((e + 1) % 3)];
      if (std::lexicographical_compare(b.data(), b.data() + 3, a.data(), a.data() + 3))
        std::swap(a, b);
      edges[{a.x(), a.y(), a.z(), b.x(), b.y(), b.z()}].push_back(t);
    }
  for (const auto& [key, ts] : edges)
    for (std::size_t i = 1; i < ts.size(); ++i) {
      const std::size_t a = ts[0], b = ts[i];
      if (mesh.group[a] != mesh.group[b]) continue;
      const Eigen::Vector3d na = unit_normal(mesh.triangles[a]),
                            nb = unit_normal(mesh.triangles[b]);
      if (std::abs(na.dot(nb)) < std::cos(angle_tol) - 1e-15) continue;  // a crease
      // Coplanar: the far vertex of b lies in a's plane.
      double off = 0;
      for (const auto& v : mesh.triangles[b])
        off = std::max(off, std::abs(na.dot(v - mesh.triangles[a][0])));
      if (off > offset_tol) continue;
      parent[static_cast<std::size_t>(find(parent, static_cast<int>(a)))] =
          find(parent, static_cast<int>(b));
    }
  std::vector<int> region(n), id(n, -1);
  int next = 0;
  for (std::size_t t = 0; t < n; ++t) {
    const int r = find(parent, static_cast<int>(t));
    if (id[static_cast<std::size_t>(r)] < 0) id[static_cast<std::size_t>(r)] = next++;
    region[t] = id[static_cast<std::size_t>(r)];
  }
  return region;
}

std::optional<MeshContact> mesh_contact_named(const std::string& name) {
  if (name == "merged") return MeshContact::Merged;
  if (name == "yade") return MeshContact::YadeParity;
  return std::nullopt;
}

std::vector<WallSpec> mesh_walls(const MeshTriangles& mesh, MeshContact mode,
                                 const Eigen::Vector3d& velocity, double friction_deg) {
  if (mesh.group.size() != mesh.triangles.size())
    throw std::invalid_argument("mesh: one group per triangle is needed");
  auto facet = [&](std::size_t t, const Eigen::Vector3d& ref) {
    const auto& v = mesh.triangles[t];
    try {
      return make_triangle_facet(v[0], v[1], v[2], ref);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("mesh triangle " + std::to_string(t) + ": " + e.what());
    }
  };
  auto base = [&](const std::string& group, std::size_t index) {
    WallSpec w;
    w.shape = WallShape::Facets;
    w.name = group + ":" + std::to_string(index);
    w.group = group;
    w.velocity = velocity;
    w.friction_deg = friction_deg;
    return w;
  };
  std::vector<WallSpec> walls;
  if (mode == MeshContact::YadeParity) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& v = mesh.triangles[t];
      WallSpec w = base(mesh.group[t], t);
      w.center = incircle_centre(v[0], v[1], v[2]);  // YADE's body position
      w.facets.push_back(facet(t, w.center));
      walls.push_back(std::move(w));
    }
    return walls;
  }
  const std::vector<int> region = flat_regions(mesh);
  const int nr = region.empty() ? 0 : *std::max_element(region.begin(), region.end()) + 1;
  std::vector<std::vector<std::size_t>> members(static_cast<std::size_t>(nr));
  for (std::size_t t = 0; t < region.size(); ++t)
    members[static_cast<std::size_t>(region[t])].push_back(t);
  for (int r = 0; r < nr; ++r) {
    const auto& ts = members[static_cast<std::size_t>(r)];
    const auto& v = mesh.triangles[ts[0]];
    WallSpec w = base(mesh.group[ts[0]], static_cast<std::size_t>(r));
    w.center = incircle_centre(v[0], v[1], v[2]);
    w.plane_radii = true;
    for (const std::size_t t : ts) w.facets.push_back(facet(t, w.center));
    walls.push_back(std::move(w));
  }
  return walls;
}

namespace {
// Forces and torques summed over the walls, keyed by `key` (walls with an empty key skipped).
template <class Key>
std::vector<GroupForce> sum_by(const Simulation& sim, Key key) {
  std::vector<GroupForce> out;
  std::map<std::string, std::size_t> index;
  for (const auto& w : sim.walls()) {
    const std::string& k = key(w.spec);
    if (k.empty()) continue;
    auto it = index.find(k);
    if (it == index.end()) {
      it = index.emplace(k, out.size()).first;
      out.push_back({k, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0});
    }
    GroupForce& g = out[it->second];
    g.force += w.force;
    g.torque += w.torque + (w.pos - w.rot_center).cross(w.force);
    ++g.walls;
  }
  return out;
}
}  // namespace

std::vector<GroupForce> group_forces(const Simulation& sim) {
  return sum_by(sim, [](const WallSpec& s) -> const std::string& { return s.group; });
}

std::vector<GroupForce> mesh_forces(const Simulation& sim) {
  std::map<std::string, std::set<std::string>> groups;
  for (const auto& w : sim.walls())
    if (!w.spec.mesh.empty()) groups[w.spec.mesh].insert(w.spec.group);
  static const std::string none;
  return sum_by(sim, [&](const WallSpec& s) -> const std::string& {
    return !s.mesh.empty() && groups[s.mesh].size() > 1 ? s.mesh : none;
  });
}

}  // namespace gs::solver
