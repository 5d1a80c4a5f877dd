// Verlet neighbour list on a uniform cell grid: candidate sphere pairs closer than the sum of
// radii plus a skin, and candidate sphere–wall pairs; rebuilt only when the largest particle
// displacement (plus wall displacement) could have brought a new pair into contact.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "dem_types.hpp"

namespace gs::solver {

struct NeighborList {
  double skin = 0;
  /// Candidate pairs sorted by (a, b); b ≥ kWallBase encodes a wall. Sphere pairs have a < b;
  /// members of one clump are never paired.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::vector<Eigen::Vector3d> ref_pos;   // particle positions at the last build
  std::vector<Eigen::Vector3d> wall_ref;  // wall positions at the last build
  std::vector<Eigen::Vector3d> wall_normal_ref;
  std::vector<Eigen::Quaterniond> wall_ori_ref;  // facet walls' rotations at the last build
  std::int64_t builds = 0;
  /// Set by stale(): a bound on how far any particle and any wall point have moved since the
  /// last build (m), i.e. on how much any pair's gap can have closed.
  mutable double moved = 0;

  /// True when some pair may have come within contact since the last build.
  bool stale(const ParticleState& p, const std::vector<WallState>& walls) const;
  void build(const ParticleState& p, const std::vector<WallState>& walls);

 private:
  // Scratch of build(), kept between builds (no allocations once sized).
  struct Slot {
    double x, y, z, r;
    std::uint32_t index;
    std::int32_t clump;
  };
  struct FacetEntry {
    std::uint32_t wall, facet;
  };
  std::vector<std::uint32_t> cell_start_, cell_fill_, cell_of_particle_;
  std::vector<Slot> slots_;
  std::vector<std::uint32_t> facet_start_, facet_cell_;
  std::vector<FacetEntry> facet_entries_, facet_sorted_;
  std::vector<std::uint32_t> plain_walls_;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> found_;
  std::vector<std::uint32_t> first_start_;
};

}  // namespace gs::solver
