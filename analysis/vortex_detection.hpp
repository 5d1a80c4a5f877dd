// Vortex centres, sources and sinks of an HHD as strict extrema of its potentials over the
// Delaunay 1-ring (seed 000 §5, Figs 8–9; §6), and vortex tubes linking 3D vortex centres
// (seed 000 §6, Fig. 11).
//
// Conventions (seed 000 Fig. 8 and §8): a node is an extremum when its value is strictly larger
// (smaller) than at every 1-ring neighbour; excluded nodes (ghosts, Dirichlet nodes) are never
// extrema but are neighbours like any other.
//  * 2D: minima of v_z are right-handed vortex centres (clockwise seen from +z: ∇×v of a v_z
//    minimum turns clockwise), maxima left-handed (counterclockwise).
//  * 3D: strict maxima of |v|; right-handed when v·axis < 0 (clockwise about `axis`, the
//    out-of-plane direction of the specimen), left-handed otherwise.
//  * Sources (local dilatancy, ∇·ξ > 0) are minima of u, sinks (contractancy) maxima of u.
// The magnitude of an extremum is |v_z|, |v| or |u| at the node (the circle size of Figs 8–9).
// Significance: every strict extremum is found (a smooth field on 56 000 random points has ~800
// noise-level u extrema, at ≤ 4e-4 of its one source); `mark_significant` flags those that
// count (summaries, series, figures): magnitude ≥ relative × the strongest extremum of the same
// potential (v for vortices, u for sources and sinks) and ≥ an absolute floor in the
// potential's units (ξ × m).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "delaunay_mesh.hpp"
#include "hhd.hpp"

namespace gs::analysis {

enum class ExtremumKind : std::int32_t { RightVortex = 0, LeftVortex = 1, Source = 2, Sink = 3 };
/// "right_vortex", "left_vortex", "source", "sink".
const char* extremum_kind_name(ExtremumKind k);

struct Extremum {
  std::int32_t node = 0;
  ExtremumKind kind = ExtremumKind::RightVortex;
  double value = 0.0;                           // 2D vortex: v_z; 3D vortex: |v|; source/sink: u
  double magnitude = 0.0;                       // |value|
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  // vector potential at the node (2D: (0, 0, v_z))
  bool significant = true;                      // see mark_significant
};

/// Default relative significance: 5 % of the strongest extremum of the same potential. Measured
/// (docs/hhd.md): the noise extrema of a smooth field reach 3.1 % of its source at 1 500 random
/// nodes and 0.04 % at 56 000; on DEM increments (plane-strain demo) every vortex is ≥ 20 % of
/// the strongest and 75–80 % of the sources and sinks are ≥ 5 %.
inline constexpr double kSignificanceRelative = 0.05;

/// Sets Extremum::significant: magnitude ≥ max(relative × M, absolute), M the largest magnitude
/// among the vortices (for a vortex) or among the sources and sinks (for a source or sink).
/// Throws std::invalid_argument unless 0 ≤ relative ≤ 1 and absolute ≥ 0 (finite).
void mark_significant(std::vector<Extremum>& extrema, double relative, double absolute = 0.0);

/// All extrema of `r` (vortices first, then sources and sinks; each group by node index).
/// `excluded` has one flag per node (empty: none).
std::vector<Extremum> find_extrema(const HhdResult& r, const VertexRings& rings,
                                   const std::vector<std::uint8_t>& excluded,
                                   const Eigen::Vector3d& axis = Eigen::Vector3d::UnitZ());

/// One tube: the node path through a 3D vortex centre, from the end reached against v to the end
/// reached along v.
struct VortexTube {
  std::size_t extremum = 0;         // index into the extrema list
  std::vector<std::int32_t> nodes;  // at least the centre itself
};

/// Seed 000 §6: from each 3D vortex centre, repeatedly step to the 1-ring neighbour of largest |v|
/// in the half-space {(x_j − x_c)·d > 0}, d = v at the current node, while |v_j| >= (1 − δ)|v_c|;
/// then the same from the centre with d = −v. Along a path d keeps its orientation (d is ±v_c,
/// the sign making d·d_previous >= 0), so a path does not turn back where v changes sign. A path
/// stops at an excluded node, a node it already holds, or when no neighbour qualifies. 2D
/// results give no tubes.
std::vector<VortexTube> trace_vortex_tubes(const HhdMesh& mesh, const HhdResult& r,
                                           const VertexRings& rings,
                                           const std::vector<Extremum>& extrema, double delta,
                                           const std::vector<std::uint8_t>& excluded);

}  // namespace gs::analysis
