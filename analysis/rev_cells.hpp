// REV (representative elementary volume) cell maps (seed 000 §3, seed 004 §4.2.3): cubic cells
// of side L (default 5 d50) moved by a step s (default 1 d50) over a 3D grid, or over a 2D grid
// inside a slab (plane, in-plane axis and thickness; the cell spans the whole thickness, seed
// 000 §3: 5 d50 x 5 d50 x slab), or squares over a 2D frame (discs). Per cell:
//   solid volume  exact sphere–box intersection volume (sphere_box_volume.hpp), summed;
//   solid fraction  V_s / V_cell; void ratio e = (V_cell - V_s) / V_s;
//   rotation      mean cumulative rotation vector, weighted by each particle's volume in the cell;
//   displacement  the same for the displacement between two frames (matched particles only);
//   coordination  mean number of particle–particle contacts per particle, weighted by the
//                 fraction of each particle's volume inside the cell;
//   particles     number of particle centres inside the cell (lo <= x < hi);
//   stress        Love–Weber, compression positive (love_weber_stress.hpp), each contact weighted
//                 by the fraction of its branch inside the cell.
// Overlapping spheres are counted twice in their overlap (as every DEM post-processor does).
//
// Speed: the planes of all cells partition space into elementary boxes. Each sphere deposits
// its exact volume in the few elementary boxes it touches (the octant values of the planes that
// cut it are computed once per sphere; a box volume is a signed sum of them), each branch its
// pieces between planes; a cell is then the sum of its elementary boxes, done axis by axis.
// Per-item work runs in parallel (OpenMP); the deposits and sums are done in a fixed order, so
// results do not depend on the number of threads.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "love_weber_stress.hpp"
#include "slab_projection.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

struct RevGridSpec {
  double cell = 0.0;         // L, m (> 0); 0 for a grid of points (make_point_grid)
  double step = 0.0;         // s, m (> 0)
  std::optional<Slab> slab;  // 2D grid in the slab (3D frames only)
  /// Box the cells must fit in (default: the extent of the spheres): 3D grid: global box; slab:
  /// in-plane local (x, y) bounds (x along axis1); 2D frame: x, y bounds.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> region;
};

struct RevGrid {
  int dim = 3;        // 3: spheres and boxes; 2: discs of a 2D frame and rectangles (x, y)
  bool slab = false;  // 2D grid in a slab of a 3D frame
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // rows: local axes
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();    // global position of local 0
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();        // local lower corner of cell (0, 0, 0)
  Eigen::Vector3d size = Eigen::Vector3d::Zero();      // local cell extents (L, L, L or thickness)
  double step = 0.0;
  std::array<int, 3> n{1, 1, 1};  // cells per local axis (x fastest in the arrays)
  /// Per axis m > 0 when L is a whole number m of steps: the upper plane of cell i is then the
  /// lower plane of cell i + m, exactly (cells share their planes).
  std::array<int, 3> cell_steps{0, 0, 0};

  std::size_t count() const {
    return static_cast<std::size_t>(n[0]) * static_cast<std::size_t>(n[1]) *
           static_cast<std::size_t>(n[2]);
  }
  std::array<int, 3> ijk(std::size_t c) const {
    const auto nx = static_cast<std::size_t>(n[0]), ny = static_cast<std::size_t>(n[1]);
    return {static_cast<int>(c % nx), static_cast<int>((c / nx) % ny),
            static_cast<int>(c / (nx * ny))};
  }
  /// Local lower corner of a cell per axis: lo + i s (a plane shared with the brute force).
  double plane_lo(int d, int i) const { return lo[d] + i * step; }
  double plane_hi(int d, int i) const {
    return cell_steps[d] > 0 ? plane_lo(d, i + cell_steps[d]) : lo[d] + i * step + size[d];
  }
  /// Local box of cell c (2D frames: z unbounded).
  void box(std::size_t c, Eigen::Vector3d& blo, Eigen::Vector3d& bhi) const;
  Eigen::Vector3d local(const Eigen::Vector3d& x) const { return axes * (x - origin); }
  Eigen::Vector3d global(const Eigen::Vector3d& u) const { return origin + axes.transpose() * u; }
  /// Global centre of cell c.
  Eigen::Vector3d centre(std::size_t c) const;
  /// Cell volume (m^3), or area (m^2) for 2D frames.
  double measure() const { return dim == 2 ? size[0] * size[1] : size.prod(); }
};

/// Grid of cells fitting the region (3D), the slab's in-plane extent of the spheres that cut
/// it, or the 2D frame's extent; the grid is centred in that extent. Throws std::invalid_argument
/// for L or s <= 0 or non-finite, a region smaller than one cell, a slab on a 2D frame, or no
/// particle in the slab.
RevGrid make_rev_grid(const Frame& frame, const RevGridSpec& spec);

/// Grid of points (cells of size 0) for kernel coarse-graining (coarse_graining.hpp), laid out
/// as make_rev_grid lays out cells; spec.cell must be 0. Same errors otherwise.
RevGrid make_point_grid(const Frame& frame, const RevGridSpec& spec);

struct RevFields {
  std::vector<double> solid_volume;           // m^3 (m^2 in 2D)
  std::vector<double> solid_fraction;         // V_s / V_cell
  std::vector<double> void_ratio;             // NaN where V_s = 0
  std::vector<double> particles;              // particle centres in the cell
  std::vector<double> coordination;           // NaN where no particle
  std::vector<Eigen::Vector3d> rotation;      // rad; NaN where no particle
  std::vector<Eigen::Vector3d> displacement;  // m; empty without motion, NaN where none matched
  std::vector<Eigen::Matrix3d> stress;        // Pa (N/m in 2D), compression positive
};

/// Optional per-particle displacement (index = frame.particles), with a flag per particle.
struct ParticleMotion {
  std::vector<Eigen::Vector3d> u;
  std::vector<std::uint8_t> matched;
};

/// REV averages on the grid (binned, parallel over cells, deterministic). Throws
/// std::invalid_argument for a grid of points (no cell volume).
RevFields rev_average(const Frame& frame, const ContactBranches& branches, const RevGrid& grid,
                      const ParticleMotion& motion = {});

/// Same fields by brute force: every cell against every particle and contact with
/// sphere_box_volume and segment_box_fraction (O(cells x items)); `cells` restricts it to some
/// cells (the others are left 0). Baseline for tests and the bench.
RevFields rev_average_brute_force(const Frame& frame, const ContactBranches& branches,
                                  const RevGrid& grid, const ParticleMotion& motion = {},
                                  const std::vector<std::size_t>& cells = {});

/// Interpolation of a cell-centred field at a global point: up to 8 (cell, weight) pairs of the
/// cells around it (trilinear; bilinear on 2D grids, the point projected onto the plane).
/// Empty when the point lies outside the cell centres.
std::vector<std::pair<std::size_t, double>> rev_interpolation(const RevGrid& grid,
                                                              const Eigen::Vector3d& x);

}  // namespace gs::analysis
