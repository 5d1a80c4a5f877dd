// The silo report of a whole run as `granoscope analyze silo` computes it (and Python's
// granoscope.silo; seed 004 §5.3): silo_report on every frame from the initial state on, the
// series P/G, T/G, N/G, phi_w, discharge and flow pattern, and the three states of §5.3.1
// (initial, maximum = the largest N_left + N_right, residual = the last) with the slice method
// beside ours (Eq 5.1 with R = b/2; K from Eq 5.2 (Drescher) and EN 1991-4's K). One
// implementation for both faces.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "silo_report.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

/// The options as the CLI names them (lengths in m, or in d50 where the name says so).
struct SiloSpec {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ(), across = Eigen::Vector3d::UnitX();
  std::optional<double> bin, bin_d50, depth, d50, zone_height, from_time;
  // The d50 the run's scene recorded (recorded_d50): used when `d50` is not given, before the
  // last frame's median by volume.
  std::optional<double> scene_d50;
  double zone_bin_d50 = 1.0, zone_band_d50 = 5.0;
  double zone_window_d50 = 0.0;  // the REV cell across (0: bins of zone_bin_d50)
  double zone_extent_factor = 2.0;
  long from = 0;
  double gravity = 9.81;
  std::vector<double> layers{0.2, 0.5, 0.8};
  double layer_bin_d50 = 2.0, layer_band_d50 = 5.0;
  int rose_bins = 36;
  double phi_i = 35.0, en_k = 0.63;  // deg; EN 1991-4 K = 0.45 x 1.4
  double rev_width_d50 = 2.0;
  int flow_bands = 10;
  double flow_wall_d50 = 3.0, flow_threshold = 0.1;
};

struct SiloState {
  const char* name = "";  // initial, maximum, residual
  std::size_t index = 0;  // into SiloSeries::reports
  double phi_w_mean_deg = 0.0;
  double K_drescher = 0.0, P_G_drescher = 0.0, P_G_en1991 = 0.0;  // NaN where n/a
};

struct SiloSeries {
  double d50 = 0.0;
  const char* d50_source = "";  // "given", "the scene's" or "median by volume of the last frame"
  SiloReportOptions options;
  long from = 0;                                                    // the initial state's frame
  std::vector<SiloFrameReport> reports;                             // frames from, from + 1, ...
  std::vector<std::pair<std::string, std::vector<double>>> series;  // per frame, by name
  std::array<SiloState, 3> states;
};

/// The report of `frames` (a silo run's trajectory). Throws InputError (naming `file`) for a bad
/// option or a frame the report cannot be made of.
SiloSeries silo_series(const std::string& file, const std::vector<Frame>& frames,
                       const SiloSpec& spec);

/// Janssen's P/G (seed 004 Eq 5.1) for a fill of height h in a plane silo of width b with
/// friction on its side walls: P/G = (z0/h)(1 - exp(-h/z0)), z0 = R/(K mu), R = b/2.
double janssen_p_over_g(double K, double mu, double width, double height);

}  // namespace gs::analysis
