// Ghost ("extra") nodes outside the specimen that weaken the N-P boundary conditions of the HHD
// (seed 000 §4.2, Fig. 6): a regular lattice of spacing h_g (triangular in 2D, tetrahedral = fcc
// in 3D) outside the box of the particle centres up to a distance D, each ghost at least d_min
// from every centre, its vector the Gaussian average (radius R) of the true nodes.
//
// Lattice nodes are shifted by a fixed pseudo-random amount of at most 1e-3 h_g per coordinate
// (breaks the Delaunay degeneracy of a regular lattice).
//
// Paper (d50 = 2.5 mm, specimen width b = 40 mm): h_g = 4.5 mm, d_min = 4 mm, D = 50 mm,
// R = 80 mm = 2 b. The defaults scale these: h_g = 1.8 d50, d_min = 1.6 d50, D = 1.25 b, R = 2 b.
//
// Gaussian average: w(r) = exp(−r²/R²) (R the 1/e radius), over all true nodes. It is evaluated
// on the true nodes binned into cubes (squares) of side R/8, each cube acting as its node count
// at its node centroid with its summed vector; for a vector field linear within a cube the first
// order terms cancel, and the relative deviation from the node-by-node sum is O((side/R)²)
// (measured < 1e-3 in tests/analysis/test_vortex.cpp). Constant fields are reproduced exactly.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace gs::analysis {

struct GhostOptions {
  double spacing = 0.0;       // h_g (m), > 0
  double min_distance = 0.0;  // d_min (m), >= 0
  double extent = 0.0;        // D (m), > 0: ghosts up to this distance from the box of centres
  double radius = 0.0;        // R (m), > 0: Gaussian averaging radius
};

/// Seed 000 §4.2 values scaled by d50 and the specimen width b (smallest extent of the box of
/// the centres in the analysed dimensions).
GhostOptions paper_ghost_options(double d50, double width);

struct GhostNodes {
  std::vector<Eigen::Vector3d> position;  // 2D: z = 0
  std::vector<Eigen::Vector3d> vector;    // Gaussian average of the true nodes' vectors
};

/// Ghosts around `points` (dim 2: x, y used; z of the output 0). Throws std::invalid_argument
/// for options out of range, sizes that differ, or a lattice of more than 10^7 nodes.
GhostNodes ghost_nodes(const std::vector<Eigen::Vector3d>& points,
                       const std::vector<Eigen::Vector3d>& vectors, int dim,
                       const GhostOptions& options);

/// The Gaussian average of `vectors` at `at`, node by node (the reference of the binned sum).
Eigen::Vector3d gaussian_average(const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<Eigen::Vector3d>& vectors,
                                 const Eigen::Vector3d& at, double radius, int dim);

}  // namespace gs::analysis
