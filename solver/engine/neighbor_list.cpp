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
    wmax = std::max(wmax, (walls[w].pos - wall_ref[w]).norm());
    if ((walls[w].normal - wall_normal_ref[w]).norm() > 0) return true;  // rotated plane
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
  for (const auto& w : walls) {
    wall_ref.push_back(w.pos);
    wall_normal_ref.push_back(w.normal);
  }
  ++builds;
  if (n == 0) return;
  double rmax = 0;
  Eigen::Vector3d lo = p.pos[0], hi = p.pos[0];
  for (std::size_t i = 0; i < n; ++i) {
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
  for (std::size_t i = 0; i < n; ++i) {
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
            if (j <= i) continue;
            if (clumped && p.clump[i] >= 0 && p.clump[i] == p.clump[j]) continue;  // one clump
            const double reach = p.radius[i] + p.radius[j] + skin;
            if ((p.pos[j] - p.pos[i]).squaredNorm() < reach * reach)
              pairs.emplace_back(static_cast<std::uint32_t>(i), j);
          }
        }
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const auto& wall = walls[w];
      if (!wall.active) continue;
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
