// The field `granoscope analyze hhd | vortices` decompose (and Python's granoscope.hhd /
// granoscope.vortices): the motion of a frame's particles in 3D, in 2D, or on a slab projected
// onto its plane (seed 000 §5, the "2D slice"), with the options of the decomposition (solver,
// ghost nodes of §4.2, handedness axis, tube threshold δ and significance of §6). One
// implementation for both faces.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "frame_motion.hpp"
#include "selection.hpp"
#include "slab_projection.hpp"
#include "vortex_analysis.hpp"

namespace gs::analysis {

/// The options as given (the CLI's names; unset = default).
struct VortexFieldSpec {
  ProjectionSlabSpec slab;
  bool slice = false;  // a slab 5 d50 thick at mid-depth unless `slab` says otherwise
  bool ghosts = false;
  double ghost_spacing = 0.0, ghost_min_distance = -1.0, ghost_extent = 0.0, ghost_radius = 0.0;
  double d50 = 0.0;  // m, for the ghost defaults; 0: the frame's
  std::string solver = "auto";
  std::optional<double> tolerance;  // unset: the solver's default
  int max_iterations = 10000;
  std::vector<double> axis;  // 3 values when given
  double delta = 0.05;
  double significance = kSignificanceRelative;
  double significance_abs = 0.0;
  std::function<void()> poll;  // HhdOptions::poll (Python's Ctrl-C); changes no result
  bool projected() const { return slice || slab.any(); }
};

/// One field to decompose: positions and vectors of the nodes (2D: in-plane coordinates).
struct VortexField {
  int dim = 3;
  std::vector<Eigen::Vector3d> x, u;
  std::vector<std::int64_t> id;
  double d50 = 0.0;  // 0: unknown (points without radii)
  bool slab = false;
  Slab plane;
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
};

/// The field of motion `m` (3D, 2D, or projected on the slab). Throws InputError (naming file).
VortexField vortex_field(const FrameMotion& m, const VortexFieldSpec& spec,
                         const std::string& file);

/// The decomposition's options for `field`; throws InputError for a bad option.
VortexAnalysisOptions vortex_analysis_options(const VortexFieldSpec& spec, const VortexField& field,
                                              const std::string& file);

/// HHD, extrema and tubes of `field` (degenerate input: InputError naming `file`).
VortexAnalysis analyze_field(const VortexField& field, const VortexAnalysisOptions& options,
                             const std::string& file);

/// The extrema and tubes of an analysis as columns: the datasets of `analyze hhd`'s /extrema and
/// /tubes and Python's arrays. kind: 0 right vortex, 1 left vortex, 2 source, 3 sink; tube t
/// holds nodes[offsets[t]:offsets[t + 1]] from extremum extremum[t].
struct ExtremaColumns {
  std::vector<std::int32_t> node, kind;
  std::vector<double> value, magnitude;
  std::vector<std::uint8_t> significant;
  std::vector<Eigen::Vector3d> position, v;
};
ExtremaColumns extrema_columns(const VortexAnalysis& r);

struct TubeColumns {
  std::vector<std::int64_t> offsets{0};
  std::vector<std::int32_t> nodes, extremum;
};
TubeColumns tube_columns(const VortexAnalysis& r);

}  // namespace gs::analysis
