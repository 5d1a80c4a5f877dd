// Verlet neighbour list on a uniform cell grid: candidate sphere pairs closer than the sum of
// radii plus a skin, and candidate sphere–wall pairs; rebuilt only when the largest particle
// displacement (plus wall displacement) could have brought a new pair into contact. With mixed
// sizes (a few particles more than twice the 99th percentile of the radii, as DEM8's impactor
// among its grains), the grid's cells are sized for the rest and the few large particles search
// the cells their reach covers: the same candidate pairs, without cells sized for the largest.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem_types.hpp"
#include "periodic_cell.hpp"

namespace gs::solver {

/// A periodic cell too small for the neighbour search (or for one image per pair).
class PeriodicTooSmall : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

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
  /// Periodic cell (build with a cell): the period of body b's image relative to body a, per
  /// pair (YADE's Interaction.cellDist: the branch vector is x_b + H·cell_dist − x_a).
  std::vector<Eigen::Vector3i> cell_dist;
  Eigen::Matrix3d h_ref = Eigen::Matrix3d::Identity();  // the cell at the last build
  double max_radius = 0;                                // of the particles at the last build
  /// Set by stale(): a bound on how far any particle and any wall point have moved since the
  /// last build (m), i.e. on how much any pair's gap can have closed.
  mutable double moved = 0;
  mutable double walls_moved = 0;  // the same for the walls alone (m)
  /// Particles the build leaves out (1), as it does removed ones, and a cell's staleness test
  /// ignores: those of other processes (Simulation::set_roles). nullptr or empty: none.
  const std::vector<std::uint8_t>* absent = nullptr;
  /// Threads the build may use (the pairs are the same for any number).
  int threads = 1;

  /// True when some pair may have come within contact since the last build.
  /// With a cell, the gap of a pair also closes by the cell's deformation since the build:
  /// with M = (H − H_ref)·H_ref⁻¹, by at most |M|·(2 r_max + skin) beyond twice the largest
  /// non-affine displacement x − x_ref − M·x_ref.
  /// `walls_to_check`: only these walls can have moved or turned since the build (the others
  /// are where they were then; Simulation keeps the list), so only they are looked at.
  bool stale(const ParticleState& p, const std::vector<WallState>& walls,
             const PeriodicCell* cell = nullptr,
             const std::vector<std::uint32_t>* walls_to_check = nullptr) const;
  /// With a cell: pairs between images across its faces too (each periodic direction must be
  /// at least 3 search cells of 2 r_max + skin wide; PeriodicTooSmall otherwise). `planar_z`:
  /// all centres lie in one plane z = const and the cell is thicker in z than 2 r_max + skin, so
  /// no z-image can be within reach and z is not searched periodically.
  void build(const ParticleState& p, const std::vector<WallState>& walls,
             const PeriodicCell* cell = nullptr, bool planar_z = false);
  /// The smallest cell width (m) build() accepts in a periodic direction.
  double min_periodic_width(double max_radius) const { return 3 * (2 * max_radius + skin); }

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
  // (each thread's pairs on a cache line of its own: the vectors' ends side by side, written at
  // every pair found, made the two threads' search slower than one thread's)
  struct alignas(64) ThreadPairs {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    std::vector<std::uint32_t> counts;  // pairs per body 1, then their first places
    std::vector<std::uint32_t> seen;    // walls already paired with a large particle
  };
  std::vector<ThreadPairs> found_by_thread_;
  std::vector<std::uint32_t> first_start_;
  std::vector<std::uint32_t> big_;  // particles kept out of the grid (mixed sizes)
  std::vector<char> is_big_;
  std::vector<double> radius_scratch_;
  struct PeriodicPair {
    std::uint32_t a, b;
    Eigen::Vector3i cd;
  };
  std::vector<PeriodicPair> found_periodic_;
  std::vector<Eigen::Vector3i> period_;   // floor(H⁻¹·x) of each particle at the build
  std::vector<Eigen::Vector3d> wrapped_;  // positions wrapped into the cell at the build
  void build_periodic(const ParticleState& p, const PeriodicCell& cell, bool planar_z);
};

}  // namespace gs::solver
