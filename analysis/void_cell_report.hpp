// Kuhn void cells of a 2D frame's motion as `granoscope analyze voidcells` computes them (and
// Python's granoscope.voidcells; seed 002): the cells of the contact graph after the removals of
// Fig. 4, each cell's velocity (or displacement) gradient (eq 7), alignment alpha (eqs 18-19),
// vorticity w (eq 20), and the particles' relative velocities (eq 21). One implementation for
// both faces.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "frame_motion.hpp"
#include "kuhn_void_cells.hpp"
#include "particle_graph.hpp"

namespace gs::analysis {

struct VoidCellSpec {
  double d50 = 0.0;  // m, for eq 21; 0: the frame's
  /// Periodic cell, velocities: the cell's velocity gradient (1/s; default the frame's).
  std::optional<Eigen::Matrix2d> cell_velocity_gradient;
};

struct VoidCellReport {
  double d50 = 0.0;
  ParticleGraph graph;
  VoidCellGraph cells;
  VoidCellDeformation deformation;
  std::vector<std::int64_t> id;  // every particle of the frame, in order
  // The cells' polygons: vertices (particle indices) and their points (periodic images
  // unwrapped), cell c from offsets[c] to offsets[c + 1].
  std::vector<std::int64_t> offsets;
  std::vector<std::int32_t> vertices;
  std::vector<Eigen::Vector2d> polygon;
};

/// Void cells of `m` (a 2D frame's velocities, or its displacement to frame `to`, which a
/// periodic cell needs for the change of the cell).
/// Particles without a match in `to` are left out with their contacts. Throws InputError for a
/// 3D frame, a non-planar graph (Euler check) or nothing left after the removals.
VoidCellReport void_cell_report(const std::string& file, const FrameMotion& m, const Frame* to,
                                const VoidCellSpec& spec);

}  // namespace gs::analysis
