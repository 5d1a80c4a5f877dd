// Void cells of a 2D particle graph and their average velocity gradients (seed 002, Kuhn 1999).
//  - faces by the sharpest-turn traversal of §3 over a doubly-connected edge list: every edge is
//    two directed half-edges; from half-edge u->v the face continues with the edge at v that
//    makes the sharpest turn (next clockwise from v->u), so every face lies to the left of its
//    half-edges and bounded faces come out counterclockwise;
//  - removal (Fig. 4) of isolated particles (no contact), pendant particles (chains of degree-1
//    vertices), peninsular groups (joined to the framework by one edge: an edge with the same
//    face on both sides) and islands (components other than the largest);
//  - Euler check (eq 16): L - M + N = 0 on a periodic torus, = 1 for a bounded planar graph;
//  - per cell the average velocity gradient eq 7 with the consistent Q^m (eq 11); assembly
//    average eq 3; alignment alpha eq 18-19; normalised vorticity w eq 20; relative velocity
//    eq 21.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "particle_graph.hpp"

namespace gs::analysis {

struct VoidCell {
  std::vector<std::int32_t> vertices;  // counterclockwise
  std::vector<Eigen::Vector2i> image;  // cell-vector shift of each vertex (periodic images)
  double area = 0.0;                   // > 0
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();  // may lie outside the periodic cell
};

struct VoidCellGraph {
  std::vector<VoidCell> cells;
  std::vector<std::uint8_t> vertex_active;          // per input particle: part of the framework
  std::vector<std::uint8_t> edge_active;            // per graph edge
  std::int64_t faces = 0, edges = 0, vertices = 0;  // L, M, N after removals
  std::int64_t removed_isolated = 0, removed_pendant = 0, removed_peninsular = 0,
               removed_island = 0;  // particles removed per kind (Fig. 4)
  std::int64_t euler() const { return faces - edges + vertices; }
  /// 0 on the periodic torus, 1 for a bounded graph.
  std::int64_t expected_euler = 1;
};

/// Builds the void cells. Throws std::invalid_argument when nothing remains after the removals.
/// A graph with crossing edges (not planar, e.g. from a projected slab) fails the Euler check:
/// the counts are still returned and the caller decides (the CLI reports an error).
VoidCellGraph find_void_cells(const ParticleGraph& graph);

/// Eq 7 for one polygon: vertices x (counterclockwise, unwrapped), velocities v. Throws
/// std::invalid_argument for fewer than 3 vertices or a non-positive area.
Eigen::Matrix2d void_cell_gradient(const std::vector<Eigen::Vector2d>& x,
                                   const std::vector<Eigen::Vector2d>& v);

/// Eq 4 (Bagi) for a counterclockwise triangle.
Eigen::Matrix2d bagi_triangle_gradient(const std::array<Eigen::Vector2d, 3>& x,
                                       const std::array<Eigen::Vector2d, 3>& v);

/// Eq 18-19: alignment of a local gradient with the average one; 0 where either is zero.
double alignment(const Eigen::Matrix2d& local, const Eigen::Matrix2d& mean);
/// Eq 20: normalised vorticity -(L12 - L21) / |L-bar|; 0 where |L-bar| = 0.
double normalised_vorticity(const Eigen::Matrix2d& local, const Eigen::Matrix2d& mean);

struct VoidCellDeformation {
  std::vector<Eigen::Matrix2d> gradient;           // L^i per cell (eq 7)
  Eigen::Matrix2d mean = Eigen::Matrix2d::Zero();  // L-bar (eq 3)
  std::vector<double> alpha;                       // eq 18; 0 where |L^i| = 0 or |L-bar| = 0
  std::vector<double> w;                           // eq 20; 0 where |L-bar| = 0
  std::vector<Eigen::Vector2d> relative_velocity;  // eq 21 per particle; 0 for removed ones
  double relative_velocity_scale = 0.0;  // D50 |L-bar_22|, or D50 |L-bar| when L-bar_22 = 0
};

/// Deformation of the cells for particle velocities v (or displacements). In a periodic cell
/// the image of particle b shifted by s moves with v_b + cell_rate * s (cell_rate = d(cell)/dt,
/// columns the rates of the cell vectors; zero for a fixed cell). `d50` for eq 21.
VoidCellDeformation void_cell_deformation(
    const ParticleGraph& graph, const VoidCellGraph& cells,
    const std::vector<Eigen::Vector2d>& velocity, double d50,
    const Eigen::Matrix2d& cell_rate = Eigen::Matrix2d::Zero());

}  // namespace gs::analysis
