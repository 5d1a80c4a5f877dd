#include "neighbor_list.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "contact_geometry.hpp"
#include "thread_team.hpp"

namespace gs::solver {

bool NeighborList::stale(const ParticleState& p, const std::vector<WallState>& walls,
                         const PeriodicCell* cell,
                         const std::vector<std::uint32_t>* walls_to_check) const {
  if (ref_pos.size() != p.size() || wall_ref.size() != walls.size()) return true;
  // The largest of d2(i) over the particles; on the build's threads past 20 000 particles (a
  // maximum: the same for any split).
  auto max_over = [&](auto&& d2) {
    const std::size_t n = p.size();
    double m = 0;
    if (threads > 1 && n >= 20000) {
#pragma omp parallel for num_threads(threads) schedule(static) reduction(max : m)
      for (std::size_t i = 0; i < n; ++i) m = std::max(m, d2(i));
    } else {
      for (std::size_t i = 0; i < n; ++i) m = std::max(m, d2(i));
    }
    return m;
  };
  if (cell) {
    // Branch vectors change by the particles' non-affine displacements and by M·(branch at the
    // build), M = ΔH·H_ref⁻¹ (|M|₂ ≤ |M|_F): a pair farther than r_a + r_b + skin at the
    // build stays apart while 2·max|u| + |M|·(2 r_max + skin) < skin.
    moved = HUGE_VAL;  // (no facet walls in a periodic cell)
    // (a domain's absent particles are not moved here: their affine part is not theirs)
    const std::uint8_t* out = absent && absent->size() == p.size() ? absent->data() : nullptr;
    if (cell->hsize == h_ref) {
      const double d2 = max_over([&](std::size_t i) {
        return out && out[i] ? 0.0 : (p.pos[i] - ref_pos[i]).squaredNorm();
      });
      return 2 * std::sqrt(d2) > skin;
    }
    const Eigen::Matrix3d m = (cell->hsize - h_ref) * h_ref.inverse();
    const double d2 = max_over([&](std::size_t i) {
      return out && out[i] ? 0.0 : (p.pos[i] - ref_pos[i] - m * ref_pos[i]).squaredNorm();
    });
    return 2 * std::sqrt(d2) + m.norm() * (2 * max_radius + skin) > skin;
  }
  const double dmax =
      std::sqrt(max_over([&](std::size_t i) { return (p.pos[i] - ref_pos[i]).squaredNorm(); }));
  moved = walls_moved = HUGE_VAL;  // (until known: a rebuild follows every early return)
  if (2 * dmax > skin) return true;
  double wmax = 0;
  const std::size_t nw = walls_to_check ? walls_to_check->size() : walls.size();
  for (std::size_t i = 0; i < nw; ++i) {
    const std::size_t w = walls_to_check ? (*walls_to_check)[i] : i;
    const WallState& wall = walls[w];
    double move = wall.pos == wall_ref[w] ? 0.0 : (wall.pos - wall_ref[w]).norm();
    if (wall.spec.shape == WallShape::Facets) {
      // A rotated mesh: its points moved at most 2·sin(θ/2)·reach more than its reference
      // (nothing when it has not turned: a still mesh of many walls costs no trigonometry).
      if (wall.ori.coeffs() != wall_ori_ref[w].coeffs())
        move +=
            2 * std::abs(std::sin(0.5 * wall.ori.angularDistance(wall_ori_ref[w]))) * wall.reach;
    } else if ((wall.normal - wall_normal_ref[w]).norm() > 0) {
      return true;  // rotated plane
    }
    wmax = std::max(wmax, move);
  }
  moved = dmax + wmax;
  walls_moved = wmax;
  return dmax + wmax > skin;
}

namespace {

/// Whether some point of facet f (of the wall at wpos) may lie closer than `reach` to x: the
/// distance to the facet's plane and to the farthest edge line it is outside of bound the
/// distance to the triangle from below (with a relative margin for the rounding).
bool facet_near(const TriangleFacet& f, const Eigen::Vector3d& wpos, const Eigen::Vector3d& x,
                double reach) {
  const Eigen::Vector3d cl = x - (wpos + f.offset.eigen());
  const Eigen::Vector3d nrm = f.normal.eigen();
  const double l = nrm.dot(cl);
  const Eigen::Vector3d cp = cl - l * nrm;
  double out = 0;
  for (int i = 0; i < 3; ++i)
    out = std::max(out, f.edge_normal[i].eigen().dot(cp) - f.incircle_radius);
  const double tol = 1e-9 * (reach + cl.cwiseAbs().sum());
  return l * l + out * out < (reach + tol) * (reach + tol);
}

// The 13 forward neighbours of a cell (the other 13 see it as theirs).
constexpr int kForward[13][3] = {{1, 0, 0},  {-1, 1, 0}, {0, 1, 0},  {1, 1, 0}, {-1, -1, 1},
                                 {0, -1, 1}, {1, -1, 1}, {-1, 0, 1}, {0, 0, 1}, {1, 0, 1},
                                 {-1, 1, 1}, {0, 1, 1},  {1, 1, 1}};

/// Calls test(s, t, shift) for every pair of slots (cell ranges of `start`) in one cell or in a
/// cell and one of its forward neighbours, each pair once; a neighbour across a face of a
/// direction that wraps is taken from the other side, `shift` the periods crossed (else such
/// neighbours do not exist).
/// Only the cells of layers z in [z0, z1) (z1 < 0: all) are taken as the first cell.
template <class Test>
void for_each_slot_pair(const Eigen::Array3i& dims, const bool (&wraps)[3],
                        const std::vector<std::uint32_t>& start, Test&& test, int z0 = 0,
                        int z1 = -1) {
  auto index_of = [&](int x, int y, int z) {
    return static_cast<std::uint32_t>((z * dims[1] + y) * dims[0] + x);
  };
  const Eigen::Vector3i none = Eigen::Vector3i::Zero();
  for (int cz = z0; cz < (z1 < 0 ? dims[2] : z1); ++cz)
    for (int cy = 0; cy < dims[1]; ++cy)
      for (int cx = 0; cx < dims[0]; ++cx) {
        const std::uint32_t ci = index_of(cx, cy, cz);
        const std::uint32_t s0 = start[ci], s1 = start[ci + 1];
        if (s0 == s1) continue;
        for (std::uint32_t s = s0; s < s1; ++s)
          for (std::uint32_t t = s + 1; t < s1; ++t) test(s, t, none);
        for (const auto& o : kForward) {
          int nc[3] = {cx + o[0], cy + o[1], cz + o[2]};
          Eigen::Vector3i shift = none;
          bool inside = true;
          for (int k = 0; k < 3 && inside; ++k) {
            if (nc[k] >= 0 && nc[k] < dims[k]) continue;
            inside = wraps[k];
            shift[k] = nc[k] < 0 ? -1 : 1;
            nc[k] -= shift[k] * dims[k];
          }
          if (!inside) continue;
          const std::uint32_t cj = index_of(nc[0], nc[1], nc[2]);
          const std::uint32_t t0 = start[cj], t1 = start[cj + 1];
          for (std::uint32_t s = s0; s < s1; ++s)
            for (std::uint32_t t = t0; t < t1; ++t) test(s, t, shift);
        }
      }
}

}  // namespace

void NeighborList::build(const ParticleState& p, const std::vector<WallState>& walls,
                         const PeriodicCell* periodic_cell, bool planar_z) {
  const std::size_t n = p.size();
  if (n >= kWallBase) throw std::invalid_argument("too many particles for the neighbour list");
  pairs.clear();
  cell_dist.clear();
  ref_pos = p.pos;
  moved = 0;
  walls_moved = 0;
  wall_ref.resize(walls.size());
  wall_normal_ref.resize(walls.size());
  wall_ori_ref.resize(walls.size());
  for (std::size_t w = 0; w < walls.size(); ++w) {
    wall_ref[w] = walls[w].pos;
    wall_normal_ref[w] = walls[w].normal;
    wall_ori_ref[w] = walls[w].ori;
  }
  ++builds;
  if (n == 0) return;
  if (periodic_cell) return build_periodic(p, *periodic_cell, planar_z);
  double rmax = 0;
  const bool removal = p.removed.size() == n;
  const bool masked = absent && absent->size() == n;
  auto gone = [&](std::size_t i) {
    return (removal && p.removed[i] != 0) || (masked && (*absent)[i] != 0);
  };
  std::size_t first = 0;
  while (first < n && gone(first)) ++first;
  if (first == n) return;  // every particle has left
  Eigen::Vector3d lo = p.pos[first], hi = p.pos[first];
  double rmin = HUGE_VAL;
  std::size_t active = 0;
  for (std::size_t i = first; i < n; ++i) {
    if (gone(i)) continue;
    rmax = std::max(rmax, p.radius[i]);
    rmin = std::min(rmin, p.radius[i]);
    lo = lo.cwiseMin(p.pos[i]);
    hi = hi.cwiseMax(p.pos[i]);
    ++active;
  }
  // Mixed sizes: particles larger than twice the 99th percentile of the radii, if they are at
  // most 1 % of all, stay out of the grid (`big_`), whose cells are sized for the others. (Only
  // looked for when the sizes span more than a factor 2: 2·r_99 ≥ 2·r_min.)
  big_.clear();
  is_big_.assign(n, 0);
  double rgrid = rmax;
  if (active >= 200 && rmax > 2 * rmin) {
    radius_scratch_.clear();
    for (std::size_t i = first; i < n; ++i)
      if (!gone(i)) radius_scratch_.push_back(p.radius[i]);
    const std::size_t q = (active - 1) * 99 / 100;
    std::nth_element(radius_scratch_.begin(), radius_scratch_.begin() + static_cast<long>(q),
                     radius_scratch_.end());
    const double limit = 2 * radius_scratch_[q];
    if (rmax > limit) {
      double rest = 0;
      for (std::size_t i = first; i < n; ++i) {
        if (gone(i)) continue;
        if (p.radius[i] > limit) {
          big_.push_back(static_cast<std::uint32_t>(i));
          is_big_[i] = 1;
        } else {
          rest = std::max(rest, p.radius[i]);
        }
      }
      if (big_.size() <= active / 100) {
        rgrid = rest;
      } else {
        big_.clear();
        is_big_.assign(n, 0);
      }
    }
  }
  double cell = 2 * rgrid + skin;
  const bool clumped = p.clump.size() == n;
  Eigen::Array3i dims;
  auto size_grid = [&] {
    for (int k = 0; k < 3; ++k)
      dims[k] =
          std::max(1, std::min(1 << 10, static_cast<int>(std::floor((hi[k] - lo[k]) / cell)) + 1));
  };
  size_grid();
  // (Cells for small particles spread thin: no more than a few cells per particle.)
  while (!big_.empty() && static_cast<double>(dims[0]) * dims[1] * dims[2] >
                              4.0 * static_cast<double>(active) + 4096) {
    cell *= 1.25;
    size_grid();
  }
  const std::size_t ncells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  auto cell_of = [&](const Eigen::Vector3d& x) {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::min(dims[k] - 1, std::max(0, static_cast<int>((x[k] - lo[k]) / cell)));
    return c;
  };
  auto index_of = [&](int x, int y, int z) {
    return static_cast<std::uint32_t>((z * dims[1] + y) * dims[0] + x);
  };
  // Counting sort of the particles in the scene into cells, copied in cell order.
  cell_start_.assign(ncells + 1, 0);
  cell_of_particle_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (gone(i)) continue;
    const auto c = cell_of(p.pos[i]);
    cell_of_particle_[i] = index_of(c[0], c[1], c[2]);
    if (!is_big_[i]) ++cell_start_[cell_of_particle_[i] + 1];
  }
  for (std::size_t c = 0; c < ncells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  slots_.resize(cell_start_[ncells]);
  for (std::size_t i = 0; i < n; ++i) {
    if (gone(i) || is_big_[i]) continue;
    const Eigen::Vector3d& x = p.pos[i];
    slots_[cell_fill_[cell_of_particle_[i]]++] = {
        x[0], x[1], x[2], p.radius[i], static_cast<std::uint32_t>(i), clumped ? p.clump[i] : -1};
  }
  // Whether spheres with squared centre distance d2 are candidates: d < r_a + r_b + skin, with a
  // relative hair of slack (more candidates are harmless; fewer are not).
  auto candidates = [&](double d2, double ra, double rb) {
    const double reach = ra + rb + skin;
    return d2 < reach * reach * (1 + 1e-12);
  };
  // Sphere pairs, each found once: a cell with itself and with its forward neighbours.
  // With threads, each takes layers of cells holding a share of the particles; the pairs are
  // sorted below, so the order they are found in does not matter.
  found_.clear();
  const bool no_wrap[3] = {false, false, false};
  auto sphere_pairs = [&](std::vector<std::pair<std::uint32_t, std::uint32_t>>& out, int z0,
                          int z1) {
    for_each_slot_pair(
        dims, no_wrap, cell_start_,
        [&](std::uint32_t s, std::uint32_t t, const Eigen::Vector3i&) {
          const Slot &a = slots_[s], &b = slots_[t];
          if (a.clump >= 0 && a.clump == b.clump) return;  // one clump
          const double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
          if (candidates(dx * dx + dy * dy + dz * dz, a.r, b.r))
            out.emplace_back(std::min(a.index, b.index), std::max(a.index, b.index));
        },
        z0, z1);
  };
  const int nt = threads > 1 && active >= 20000 && dims[2] >= 2 * threads ? threads : 1;
  // The large particles: with each other, and with the slots of the cells their reach covers.
  auto same_clump = [&](std::uint32_t a, std::uint32_t b) {
    return clumped && p.clump[a] >= 0 && p.clump[a] == p.clump[b];
  };
  for (std::size_t k = 0; k < big_.size(); ++k) {
    const std::uint32_t a = big_[k];
    const Eigen::Vector3d& xa = p.pos[a];
    for (std::size_t l = k + 1; l < big_.size(); ++l) {
      const std::uint32_t b = big_[l];
      if (!same_clump(a, b) && candidates((p.pos[b] - xa).squaredNorm(), p.radius[a], p.radius[b]))
        found_.emplace_back(std::min(a, b), std::max(a, b));
    }
    const Eigen::Vector3d span = Eigen::Vector3d::Constant(p.radius[a] + rgrid + skin);
    const auto c0 = cell_of(xa - span), c1 = cell_of(xa + span);
    for (int z = c0[2]; z <= c1[2]; ++z)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int x = c0[0]; x <= c1[0]; ++x) {
          const std::uint32_t ci = index_of(x, y, z);
          for (std::uint32_t t = cell_start_[ci]; t < cell_start_[ci + 1]; ++t) {
            const Slot& b = slots_[t];
            if (same_clump(a, b.index)) continue;
            const double dx = b.x - xa[0], dy = b.y - xa[1], dz = b.z - xa[2];
            if (candidates(dx * dx + dy * dy + dz * dz, p.radius[a], b.r))
              found_.emplace_back(std::min(a, b.index), std::max(a, b.index));
          }
        }
  }
  // Facets are binned, each on its own, into the cells their bounding box (grown by the
  // largest reach of the grid's particles) covers, in (wall, facet) order within a cell; other
  // walls are checked by all.
  plain_walls_.clear();
  facet_cell_.clear();
  facet_entries_.clear();
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const auto& wall = walls[w];
    if (!wall.active) continue;
    if (wall.spec.shape != WallShape::Facets) {
      plain_walls_.push_back(static_cast<std::uint32_t>(w));
      continue;
    }
    for (std::size_t k = 0; k < wall.facets.size(); ++k) {
      const auto& f = wall.facets[k];
      Eigen::Vector3d lo_f = Eigen::Vector3d::Constant(HUGE_VAL), hi_f = -lo_f;
      for (const auto& v : f.vertex) {
        const Eigen::Vector3d x = wall.pos + (f.offset + v).eigen();
        lo_f = lo_f.cwiseMin(x);
        hi_f = hi_f.cwiseMax(x);
      }
      const Eigen::Vector3d grow = Eigen::Vector3d::Constant(rgrid + skin);
      const auto c0 = cell_of(lo_f - grow), c1 = cell_of(hi_f + grow);
      for (int z = c0[2]; z <= c1[2]; ++z)
        for (int y = c0[1]; y <= c1[1]; ++y)
          for (int x = c0[0]; x <= c1[0]; ++x) {
            facet_cell_.push_back(index_of(x, y, z));
            facet_entries_.push_back(
                {static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(k)});
          }
    }
  }
  facet_start_.assign(ncells + 1, 0);
  for (const std::uint32_t c : facet_cell_) ++facet_start_[c + 1];
  for (std::size_t c = 0; c < ncells; ++c) facet_start_[c + 1] += facet_start_[c];
  cell_fill_.assign(facet_start_.begin(), facet_start_.end() - 1);
  facet_sorted_.resize(facet_entries_.size());
  for (std::size_t e = 0; e < facet_entries_.size(); ++e)
    facet_sorted_[cell_fill_[facet_cell_[e]]++] = facet_entries_[e];
  // The walls within reach of particle i, appended to out (seen: scratch).
  auto wall_pairs = [&](std::size_t i, std::vector<std::pair<std::uint32_t, std::uint32_t>>& out,
                        std::vector<std::uint32_t>& seen) {
    const std::uint32_t own = cell_of_particle_[i];
    const double reach = p.radius[i] + skin;
    if (is_big_[i]) {
      // A large particle: the facets of every cell its reach covers, each wall paired once.
      seen.clear();
      const Eigen::Vector3d span = Eigen::Vector3d::Constant(reach);
      const auto c0 = cell_of(p.pos[i] - span), c1 = cell_of(p.pos[i] + span);
      for (int z = c0[2]; z <= c1[2]; ++z)
        for (int y = c0[1]; y <= c1[1]; ++y)
          for (int x = c0[0]; x <= c1[0]; ++x) {
            const std::uint32_t ci = index_of(x, y, z);
            for (std::uint32_t e = facet_start_[ci]; e < facet_start_[ci + 1]; ++e) {
              const FacetEntry fe = facet_sorted_[e];
              if (std::find(seen.begin(), seen.end(), fe.wall) != seen.end()) continue;
              const auto& wall = walls[fe.wall];
              if (facet_near(wall.facets[fe.facet], wall.pos, p.pos[i], reach)) {
                out.emplace_back(static_cast<std::uint32_t>(i), kWallBase + fe.wall);
                seen.push_back(fe.wall);
              }
            }
          }
    }
    std::uint32_t last = kWallBase;  // the wall last paired with i
    for (std::uint32_t e = is_big_[i] ? 0 : facet_start_[own];
         e < (is_big_[i] ? 0 : facet_start_[own + 1]); ++e) {
      const FacetEntry fe = facet_sorted_[e];
      if (fe.wall == last) continue;
      const auto& wall = walls[fe.wall];
      if (facet_near(wall.facets[fe.facet], wall.pos, p.pos[i], reach)) {
        out.emplace_back(static_cast<std::uint32_t>(i), kWallBase + fe.wall);
        last = fe.wall;
      }
    }
    for (const std::uint32_t w : plain_walls_) {
      const auto& wall = walls[w];
      const double dist = wall.spec.shape == WallShape::Box
                              ? box_distance(wall.pos, wall.spec.half_extents, p.pos[i])
                              : (p.pos[i] - wall.pos).dot(wall.normal);
      if (dist < p.radius[i] + skin) out.emplace_back(static_cast<std::uint32_t>(i), kWallBase + w);
    }
  };
  // Sorted by (a, b): a counting sort on a, then each particle's few partners in order (the
  // pairs being distinct, the order they were found in does not matter).
  auto sort_partners = [&] {
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      auto* b = pairs.data() + first_start_[i];
      auto* e = pairs.data() + first_start_[i + 1];
      for (auto* x = b + 1; x < e; ++x) {  // insertion sort (a handful of partners)
        const auto v = *x;
        auto* y = x;
        for (; y > b && (y - 1)->second > v.second; --y) *y = *(y - 1);
        *y = v;
      }
    }
  };
  // Each thread finds the sphere pairs of layers of cells holding a share of the particles and
  // the wall pairs of a share of the particles, counts its pairs per body 1, and places them
  // (the first thread the large particles' too) from offsets formed per particle in thread order.
  // (One thread runs the block without a team: run_on_team.)
  found_by_thread_.resize(static_cast<std::size_t>(nt));
  const std::size_t layer = static_cast<std::size_t>(dims[0]) * dims[1];
  const std::uint32_t slots = cell_start_[ncells];
  run_on_team(nt, [&] {
    const int t = omp_get_thread_num(), n_t = omp_get_num_threads();
    // The layers from the first whose particles reach this share's start.
    auto first_layer = [&](int k) {
      if (k == n_t) return dims[2];
      const std::uint64_t target = static_cast<std::uint64_t>(slots) * k / n_t;
      int z = 0;
      while (z < dims[2] && cell_start_[static_cast<std::size_t>(z + 1) * layer] <= target) ++z;
      return k == 0 ? 0 : z;
    };
    ThreadPairs& mine = found_by_thread_[static_cast<std::size_t>(t)];
    mine.pairs.clear();
    sphere_pairs(mine.pairs, first_layer(t), first_layer(t + 1));
    const std::size_t i0 = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(n_t);
    const std::size_t i1 = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(n_t);
    for (std::size_t i = i0; i < i1; ++i)
      if (!gone(i)) wall_pairs(i, mine.pairs, mine.seen);
    mine.counts.assign(n, 0);
    if (t == 0)
      for (const auto& pr : found_) ++mine.counts[pr.first];
    for (const auto& pr : mine.pairs) ++mine.counts[pr.first];
#pragma omp barrier
#pragma omp single
    {
      first_start_.resize(n + 1);
      std::uint32_t at = 0;
      for (std::size_t i = 0; i < n; ++i) {
        first_start_[i] = at;
        for (auto& part : found_by_thread_) {
          const std::uint32_t c = part.counts[i];
          part.counts[i] = at;  // (this thread's first place for body 1 = i)
          at += c;
        }
      }
      first_start_[n] = at;
      with_room(pairs, at);
      pairs.resize(at);
    }
    if (t == 0)
      for (const auto& pr : found_) pairs[mine.counts[pr.first]++] = pr;
    for (const auto& pr : mine.pairs) pairs[mine.counts[pr.first]++] = pr;
#pragma omp barrier
    sort_partners();
  });
}

void NeighborList::build_periodic(const ParticleState& p, const PeriodicCell& cell, bool planar_z) {
  // Particles are binned by their wrapped fractional coordinates w = s − floor(s), s = H⁻¹·x,
  // into cells at least 2 r_max + skin wide (measured between the faces of the sheared cell),
  // and a cell's neighbours wrap around the faces; a pair found between particle i and the
  // image of j shifted by n periods (n ∈ {−1, 0, 1}³) has cellDist n + floor(s_i) − floor(s_j)
  // in the unwrapped positions YADE keeps.
  const std::size_t n = p.size();
  const bool removal = p.removed.size() == n;
  auto gone = [&](std::size_t i) { return removal && p.removed[i] != 0; };
  // (a domain's absent particles are not binned, but count in r_max: the bins, and the
  // staleness bound from it, are then those of every process and of one process alone)
  const bool masked = absent && absent->size() == n;
  auto skipped = [&](std::size_t i) { return gone(i) || (masked && (*absent)[i] != 0); };
  h_ref = cell.hsize;
  double rmax = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!gone(i)) rmax = std::max(rmax, p.radius[i]);
  max_radius = rmax;
  const double reach_max = 2 * rmax + skin;
  const Eigen::Vector3d width = cell.widths();
  Eigen::Array3i dims;
  bool wraps[3];
  for (int k = 0; k < 3; ++k) {
    wraps[k] = !(k == 2 && planar_z);
    if (!wraps[k]) {
      if (!(width[k] > reach_max))
        throw PeriodicTooSmall("periodic cell thinner in z (" + std::to_string(width[k]) +
                               " m) than 2 r_max + skin (" + std::to_string(reach_max) + " m)");
      dims[k] = 1;
      continue;
    }
    dims[k] = static_cast<int>(std::min(1024.0, std::floor(width[k] / reach_max)));
    if (!(dims[k] >= 3))
      throw PeriodicTooSmall(
          "periodic cell width " + std::to_string(width[k]) + " m along base " + std::to_string(k) +
          " is below 3 (2 r_max + skin) = " + std::to_string(3 * reach_max) + " m");
  }
  const std::size_t ncells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  auto index_of = [&](int x, int y, int z) {
    return static_cast<std::uint32_t>((z * dims[1] + y) * dims[0] + x);
  };
  const Eigen::Matrix3d inv = cell.hsize.inverse();
  period_.resize(n);
  cell_of_particle_.resize(n);
  cell_start_.assign(ncells + 1, 0);
  wrapped_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (skipped(i)) continue;
    Eigen::Vector3d s = inv * p.pos[i];
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k) {
      const double fl = wraps[k] ? std::floor(s[k]) : 0.0;
      period_[i][k] = static_cast<int>(fl);
      s[k] -= fl;
      c[k] = std::min(dims[k] - 1, std::max(0, static_cast<int>(std::floor(s[k] * dims[k]))));
    }
    wrapped_[i] = cell.hsize * s;
    cell_of_particle_[i] = index_of(c[0], c[1], c[2]);
    ++cell_start_[cell_of_particle_[i] + 1];
  }
  for (std::size_t c = 0; c < ncells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  slots_.resize(cell_start_[ncells]);
  const bool clumped = p.clump.size() == n;
  for (std::size_t i = 0; i < n; ++i) {
    if (skipped(i)) continue;
    const Eigen::Vector3d& x = wrapped_[i];
    slots_[cell_fill_[cell_of_particle_[i]]++] = {
        x[0], x[1], x[2], p.radius[i], static_cast<std::uint32_t>(i), clumped ? p.clump[i] : -1};
  }
  found_periodic_.clear();
  Eigen::Vector3i last_shift = Eigen::Vector3i::Zero();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  for_each_slot_pair(
      dims, wraps, cell_start_,
      [&](std::uint32_t s, std::uint32_t t, const Eigen::Vector3i& shift) {
        const Slot &a = slots_[s], &b = slots_[t];
        if (a.clump >= 0 && a.clump == b.clump) return;
        if (shift != last_shift) {  // (the stencil visits a neighbour cell's slots in a row)
          last_shift = shift;
          offset = cell.hsize * shift.cast<double>();
        }
        const double reach = a.r + b.r + skin;
        const double dx = b.x + offset[0] - a.x, dy = b.y + offset[1] - a.y,
                     dz = b.z + offset[2] - a.z;
        if (!(dx * dx + dy * dy + dz * dz < reach * reach * (1 + 1e-12))) return;
        const Eigen::Vector3i cd = shift + period_[a.index] - period_[b.index];
        if (a.index < b.index)
          found_periodic_.push_back({a.index, b.index, cd});
        else
          found_periodic_.push_back({b.index, a.index, -cd});
      });
  std::sort(found_periodic_.begin(), found_periodic_.end(),
            [](const auto& x, const auto& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  with_room(pairs, found_periodic_.size());
  with_room(cell_dist, found_periodic_.size());
  pairs.resize(found_periodic_.size());
  cell_dist.resize(found_periodic_.size());
  for (std::size_t k = 0; k < found_periodic_.size(); ++k) {
    pairs[k] = {found_periodic_[k].a, found_periodic_[k].b};
    cell_dist[k] = found_periodic_[k].cd;
  }
}

}  // namespace gs::solver
