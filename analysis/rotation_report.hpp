// Seed 003's measures of a principal stress rotation run (§3-4; granoscope's stress_rotation
// test, docs/rotation.md), from the run's curve.csv and its trajectory frames:
//  - the strains of the rotation, counted from its start (Figs 6, 7, 9);
//  - the normalised strain increments over windows of Δα (§3.2): Δε^R_ij = Δε_ij / Δα (rad),
//    (Δε)^R_v = Δε^R_xx + Δε^R_zz, (Δε)^R_q = sqrt((Δε^R_xx − Δε^R_zz)²/4 + (Δε^R_xz)²), and the
//    direction of the major principal strain increment in the x-z plane from z,
//    α^R_Δε = atan2(2 Δε^R_xz, Δε^R_zz − Δε^R_xx)/2 (the paper writes atan: its quadrant is lost
//    once the increment's direction passes 45°), and the non-coaxiality α^R_Δε − α (Fig 10);
//  - per frame, the contact fabric D_ij of Kanatani (Eqs 18-21; the contacts between bodies,
//    walls left out), its major direction in the x-z plane from z, α_F, and α − α_F (Figs 14-16),
//    and the particle-orientation fabric D^p of the clumps' long axes (Fig 17);
//  - per cycle of 180°: εv and εyy at its end, the mean non-coaxiality, and the size and centre
//    of the fabric loop (D_xz against (D_xx − D_zz)/2).
// α is the angle of σ1 from z, as the paper measures it; strains are Biot, compression positive.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "fabric.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

/// One row of a stress_rotation run's curve.csv.
struct RotationState {
  std::int64_t step = 0;
  int stage = 0;  // 0 deposition … 4 rotation, 5 done
  double alpha_deg = 0.0;
  double p = 0.0, q = 0.0, b = 0.0, alpha_sigma_deg = 0.0;
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();  // Pa, compression positive
  Eigen::Matrix3d eps = Eigen::Matrix3d::Zero();    // Biot strain ε = 1 − F (Eq 2)
  double eps_v = 0.0, void_ratio = 0.0;             // 1 − det F (Eq 11)
};

/// Reads a stress_rotation curve.csv. Throws InputError naming the file: a missing column, a
/// row that is not numbers.
std::vector<RotationState> read_rotation_curve(const std::filesystem::path& path);

/// The rotation's rows (stage 4 and 5, from the first at α = 0), strains and εv counted from its
/// start. Throws InputError naming `source` when the run has no rotation.
std::vector<RotationState> rotation_rows(const std::vector<RotationState>& curve,
                                         const std::string& source);

struct StrainIncrement {
  double alpha_deg = 0.0;  // the window's middle
  double cycle = 0.0;      // α / 180°
  double d_eps_v_R = 0.0, d_eps_q_R = 0.0, d_eps_yy_R = 0.0;
  double alpha_d_eps_deg = 0.0;     // α^R_Δε, in (−90, 90]
  double non_coaxiality_deg = 0.0;  // α^R_Δε − α folded into (−90, 90]
};

/// Normalised strain increments over consecutive windows of `window_deg` of α (rows of
/// rotation_rows). Throws std::invalid_argument for a window not positive.
std::vector<StrainIncrement> strain_increments(const std::vector<RotationState>& rows,
                                               double window_deg);

struct FabricState {
  std::int64_t step = 0;
  double alpha_deg = 0.0;
  Fabric contacts;                 // D_ij of the body-body contacts
  double alpha_F_deg = 0.0;        // major direction of D in the x-z plane, from z, (−90, 90]
  double alpha_minus_F_deg = 0.0;  // α − α_F folded into (−90, 90]
  OrientationFabric bodies;        // D^p of the long axes
};

/// The fabric of a frame at path angle `alpha_deg`: normals of the contacts between distinct
/// bodies (members of one clump never touch; wall contacts are left out), N_p the bodies.
/// Throws InputError naming `source` for a frame without contacts between bodies.
FabricState rotation_fabric(const Frame& frame, double alpha_deg, const std::string& source);

struct CycleSummary {
  int cycle = 0;                     // 1, 2, …
  double eps_v = 0.0, eps_yy = 0.0;  // at its end, from the rotation's start
  double non_coaxiality_deg = 0.0;   // mean of the windows in it
  double fabric_radius = 0.0;        // mean distance of the loop from its centre
  Eigen::Vector2d fabric_centre = Eigen::Vector2d::Zero();  // ((D_xx − D_zz)/2, D_xz)
  std::size_t frames = 0;
};

/// Per complete cycle of 180°.
std::vector<CycleSummary> cycle_summaries(const std::vector<RotationState>& rows,
                                          const std::vector<StrainIncrement>& increments,
                                          const std::vector<FabricState>& fabric);

/// a folded into (−90, 90] degrees (directions of axes).
double fold_axis_deg(double a);

/// The whole report of a run (what `granoscope analyze rotation` writes and granoscope.rotation
/// returns): the rotation's rows of `curve`, the increments over `window_deg`, the fabric of the
/// frames from the rotation's start (those after the curve's last row before it; a frame's α:
/// that of the curve row nearest in step) and the cycles. Throws InputError naming `curve_source` (no rotation) or `run_source` (no frame of
/// the rotation, a frame without contacts between bodies), std::invalid_argument for a window
/// not positive.
struct RotationReport {
  std::vector<RotationState> rows;
  std::vector<StrainIncrement> increments;
  std::vector<FabricState> fabric;
  std::vector<CycleSummary> cycles;
};
RotationReport rotation_report(const std::vector<RotationState>& curve,
                               const std::vector<Frame>& frames, double window_deg,
                               const std::string& curve_source, const std::string& run_source);

/// The report's tables as named columns: rotation_strain, rotation_increments, rotation_fabric
/// and rotation_cycles (the CSV files of `analyze rotation`, docs/rotation.md).
using RotationColumns = std::vector<std::pair<std::string, std::vector<double>>>;
RotationColumns rotation_strain_table(const RotationReport& r);
RotationColumns rotation_increments_table(const RotationReport& r);
RotationColumns rotation_fabric_table(const RotationReport& r);
RotationColumns rotation_cycles_table(const RotationReport& r);

}  // namespace gs::analysis
