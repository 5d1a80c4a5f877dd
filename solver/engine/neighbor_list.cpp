#include "neighbor_list.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "contact_geometry.hpp"

namespace gs::solver {

bool NeighborList::stale(const ParticleState& p, const std::vector<WallState>& walls) const {
  if (ref_pos.size() != p.size() || wall_ref.size() != walls.size()) return true;
  double dmax2 = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    dmax2 = std::max(dmax2, (p.pos[i] - ref_pos[i]).squaredNorm());
  const double dmax = std::sqrt(dmax2);
  if (2 * dmax > skin) return true;
  double wmax = 0;
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const WallState& wall = walls[w];
    double move = (wall.pos - wall_ref[w]).norm();
    if (wall.spec.shape == WallShape::Facets) {
      // A rotated mesh: its points moved at most 2·sin(θ/2)·reach more than its reference.
      move += 2 * std::abs(std::sin(0.5 * wall.ori.angularDistance(wall_ori_ref[w]))) * wall.reach;
    } else if ((wall.normal - wall_normal_ref[w]).norm() > 0) {
      return true;  // rotated plane
    }
    wmax = std::max(wmax, move);
  }
  return dmax + wmax > skin;
}

void NeighborList::build(const ParticleState& p, const std::vector<WallState>& walls) {
  const std::size_t n = p.size();
  if (n >= kWallBase) throw std::invalid_argument("too many particles for the neighbour list");
  pairs.clear();
  ref_pos = p.pos;
  wall_ref.clear();
  wall_normal_ref.clear();
  wall_ori_ref.clear();
  for (const auto& w : walls) {
    wall_ref.push_back(w.pos);
    wall_normal_ref.push_back(w.normal);
    wall_ori_ref.push_back(w.ori);
  }
  ++builds;
  if (n == 0) return;
  double rmax = 0;
  const bool removal = p.removed.size() == n;
  auto gone = [&](std::size_t i) { return removal && p.removed[i] != 0; };
  std::size_t first = 0;
  while (first < n && gone(first)) ++first;
  if (first == n) return;  // every particle has left
  Eigen::Vector3d lo = p.pos[first], hi = p.pos[first];
  for (std::size_t i = first; i < n; ++i) {
    if (gone(i)) continue;
    rmax = std::max(rmax, p.radius[i]);
    lo = lo.cwiseMin(p.pos[i]);
    hi = hi.cwiseMax(p.pos[i]);
  }
  const double cell = 2 * rmax + skin;
  const bool clumped = p.clump.size() == n;
  Eigen::Array3i dims;
  for (int k = 0; k < 3; ++k)
    dims[k] =
        std::max(1, std::min(1 << 10, static_cast<int>(std::floor((hi[k] - lo[k]) / cell)) + 1));
  const std::size_t ncells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  auto cell_of = [&](const Eigen::Vector3d& x) {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::min(dims[k] - 1, std::max(0, static_cast<int>((x[k] - lo[k]) / cell)));
    return c;
  };
  // Counting sort of particles into cells.
  std::vector<std::uint32_t> start(ncells + 1, 0), order(n);
  std::vector<std::uint32_t> cell_index(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = cell_of(p.pos[i]);
    cell_index[i] = static_cast<std::uint32_t>((c[2] * dims[1] + c[1]) * dims[0] + c[0]);
    ++start[cell_index[i] + 1];
  }
  for (std::size_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      order[fill[cell_index[i]]++] = static_cast<std::uint32_t>(i);
  }
  // Facet walls are binned into the cells their bounding box (grown by the largest reach) covers,
  // so a mesh of many facets costs what its neighbourhood costs; other walls are checked by all.
  std::vector<std::uint32_t> plain_walls, facet_start(ncells + 1, 0), facet_of;
  std::vector<Eigen::Vector3d> facet_lo(walls.size()), facet_hi(walls.size());
  {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> cell_wall;  // (cell, wall)
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const auto& wall = walls[w];
      if (!wall.active) continue;
      if (wall.spec.shape != WallShape::Facets) {
        plain_walls.push_back(static_cast<std::uint32_t>(w));
        continue;
      }
      Eigen::Vector3d lo_w = Eigen::Vector3d::Constant(HUGE_VAL), hi_w = -lo_w;
      for (const auto& f : wall.facets)
        for (const auto& v : f.vertex) {
          const Eigen::Vector3d x = wall.pos + (f.offset + v).eigen();
          lo_w = lo_w.cwiseMin(x);
          hi_w = hi_w.cwiseMax(x);
        }
      facet_lo[w] = lo_w;
      facet_hi[w] = hi_w;
      const Eigen::Vector3d grow = Eigen::Vector3d::Constant(rmax + skin);
      const auto c0 = cell_of(lo_w - grow), c1 = cell_of(hi_w + grow);
      for (int z = c0[2]; z <= c1[2]; ++z)
        for (int y = c0[1]; y <= c1[1]; ++y)
          for (int x = c0[0]; x <= c1[0]; ++x)
            cell_wall.emplace_back(static_cast<std::uint32_t>((z * dims[1] + y) * dims[0] + x),
                                   static_cast<std::uint32_t>(w));
    }
    std::sort(cell_wall.begin(), cell_wall.end());
    for (const auto& cw : cell_wall) ++facet_start[cw.first + 1];
    for (std::size_t c = 0; c < ncells; ++c) facet_start[c + 1] += facet_start[c];
    facet_of.reserve(cell_wall.size());
    for (const auto& cw : cell_wall) facet_of.push_back(cw.second);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (gone(i)) continue;
    const auto c = cell_of(p.pos[i]);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          if (cx < 0 || cy < 0 || cz < 0 || cx >= dims[0] || cy >= dims[1] || cz >= dims[2])
            continue;
          const std::size_t ci = static_cast<std::size_t>((cz * dims[1] + cy) * dims[0] + cx);
          for (std::uint32_t k = start[ci]; k < start[ci + 1]; ++k) {
            const std::uint32_t j = order[k];
            if (j <= i || gone(j)) continue;
            if (clumped && p.clump[i] >= 0 && p.clump[i] == p.clump[j]) continue;  // one clump
            const double reach = p.radius[i] + p.radius[j] + skin;
            if ((p.pos[j] - p.pos[i]).squaredNorm() < reach * reach)
              pairs.emplace_back(static_cast<std::uint32_t>(i), j);
          }
        }
    const std::size_t own = cell_index[i];
    for (std::uint32_t e = facet_start[own]; e < facet_start[own + 1]; ++e) {
      const std::uint32_t w = facet_of[e];
      const Eigen::Vector3d h = 0.5 * (facet_hi[w] - facet_lo[w]);
      if (box_distance(facet_lo[w] + h, h, p.pos[i]) < p.radius[i] + skin)
        pairs.emplace_back(static_cast<std::uint32_t>(i), kWallBase + w);
    }
    for (const std::uint32_t w : plain_walls) {
      const auto& wall = walls[w];
      const double dist = wall.spec.shape == WallShape::Box
                              ? box_distance(wall.pos, wall.spec.half_extents, p.pos[i])
                              : (p.pos[i] - wall.pos).dot(wall.normal);
      if (dist < p.radius[i] + skin)
        pairs.emplace_back(static_cast<std::uint32_t>(i),
                           kWallBase + static_cast<std::uint32_t>(w));
    }
  }
  std::sort(pairs.begin(), pairs.end());
}

}  // namespace gs::solver
