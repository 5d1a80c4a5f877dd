// The whole seed 000 pipeline on one displacement-increment field: Delaunay mesh of the particle
// centres (plus optional ghost nodes, §4.2), ξ_k = mean of the vertex vectors, HHD (eq 9–18),
// vortex centres, sources and sinks (§5–6) and, in 3D, vortex tubes (§6). Used by
// `granoscope analyze hhd`, `analyze vortices` and bench/bench_hhd.cpp.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "delaunay_mesh.hpp"
#include "ghost_nodes.hpp"
#include "hhd.hpp"
#include "vortex_detection.hpp"

namespace gs::analysis {

struct VortexAnalysisOptions {
  HhdOptions hhd;
  bool ghosts = false;
  GhostOptions ghost;  // used when ghosts is on; see paper_ghost_options()
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // 3D handedness axis
  double tube_delta = 0.05;                         // δ of §6
  bool tubes = true;
  double significance_relative = kSignificanceRelative;  // see mark_significant
  double significance_absolute = 0.0;                    // in the potentials' units (ξ × m)
};

struct VortexAnalysis {
  HhdMesh mesh;  // the true nodes first (input order), then the ghosts
  std::size_t true_nodes = 0;
  std::vector<Eigen::Vector3d> vectors;  // nodal vectors (true, then ghost averages; 2D z = 0)
  std::vector<std::uint8_t> excluded;    // ghosts and Dirichlet nodes
  VertexRings rings;
  HhdResult hhd;
  std::vector<Extremum> extrema;
  std::vector<VortexTube> tubes;
  double significance_relative = 0.0, significance_absolute = 0.0;  // as applied
  double seconds_ghosts = 0.0, seconds_delaunay = 0.0, seconds_detection = 0.0;
};

/// `points` and `vectors` (same size; dim 2 uses x, y). Throws std::invalid_argument for
/// degenerate input (delaunay_mesh's errors: too few, coplanar/collinear, duplicate or non-finite
/// points) and non-finite vectors.
VortexAnalysis analyze_vortices(const std::vector<Eigen::Vector3d>& points,
                                const std::vector<Eigen::Vector3d>& vectors, int dim,
                                const VortexAnalysisOptions& options = {});

/// Counts of each extremum kind among `extrema` (only the significant ones when
/// `significant_only`), indexed by ExtremumKind.
std::array<std::size_t, 4> count_extrema(const std::vector<Extremum>& extrema,
                                         bool significant_only);
/// Tubes whose vortex centre is significant.
std::size_t count_significant_tubes(const std::vector<VortexTube>& tubes,
                                    const std::vector<Extremum>& extrema);

}  // namespace gs::analysis
