// The silo report of a whole run (see silo_series.hpp).
#include "silo_series.hpp"

#include <cmath>
#include <stdexcept>

#include "errors.hpp"
#include "grain_size.hpp"
#include "selection.hpp"
#include "silo_theory.hpp"

namespace gs::analysis {

double janssen_p_over_g(double K, double mu, double width, double height) {
  const double R = 0.5 * width;  // (the weight gamma b h depth cancels)
  return janssen_vertical_stress(1.0, K, mu, R, height) / height;
}

SiloSeries silo_series(const std::string& file, const std::vector<Frame>& t, const SiloSpec& a) {
  if (t.empty()) throw InputError(file, "no frames");
  const long n = static_cast<long>(t.size());
  if (a.from < 0 || a.from >= n)
    throw InputError(file, "--from: no such frame (" + std::to_string(n) + " frames)",
                     std::to_string(a.from));
  SiloSeries out;
  long from = a.from;
  if (a.from_time) {  // the first frame at or after that time
    from = 0;
    while (from < n && t[static_cast<std::size_t>(from)].time < *a.from_time - 1e-12) ++from;
    if (from == n || !std::isfinite(*a.from_time))
      throw InputError(file, "--from-time: after the last frame", value_str(*a.from_time));
  }
  out.from = from;
  const Frame& last = t.back();
  if (last.particles.empty()) throw InputError(file, "the last frame has no particles");
  if (a.d50) require_positive(file, "--d50", *a.d50);
  const double d50 = a.d50 ? *a.d50 : a.scene_d50 ? *a.scene_d50 : analysis::d50(last);
  out.d50 = d50;
  out.d50_source = a.d50         ? "given"
                   : a.scene_d50 ? "the scene's"
                                 : "median by volume of the last frame";
  SiloReportOptions& o = out.options;
  o.up = a.up;
  o.across = a.across;
  o.bin = length_option(file, "--bin", a.bin, a.bin_d50, 5.0, d50);
  if (a.depth) require_positive(file, "--depth", *a.depth);
  o.depth = a.depth.value_or(0.0);
  require_positive(file, "--gravity", a.gravity);
  o.gravity = a.gravity;
  require_positive(file, "--zone-bin-d50", a.zone_bin_d50);
  require_positive(file, "--zone-band-d50", a.zone_band_d50);
  o.zone_bin = a.zone_bin_d50 * d50;
  o.zone_band = a.zone_band_d50 * d50;
  if (!(a.zone_window_d50 >= 0) || !std::isfinite(a.zone_window_d50))
    throw InputError(file, "--zone-window-d50: negative", value_str(a.zone_window_d50));
  o.zone_window = a.zone_window_d50 * d50;
  if (!(a.zone_extent_factor > 1) || !std::isfinite(a.zone_extent_factor))
    throw InputError(file, "--zone-extent-factor: must be above 1",
                     value_str(a.zone_extent_factor));
  o.zone_extent_factor = a.zone_extent_factor;
  if (a.zone_height) require_positive(file, "--zone-height", *a.zone_height);
  o.zone_height = a.zone_height.value_or(0.0);
  for (const double f : a.layers)
    if (!(f > 0 && f < 1))
      throw InputError(file, "--layers: a fraction not in (0, 1)", value_str(f));
  o.layer_fractions = a.layers;
  require_positive(file, "--layer-bin-d50", a.layer_bin_d50);
  require_positive(file, "--layer-band-d50", a.layer_band_d50);
  o.layer_bin = a.layer_bin_d50 * d50;
  o.layer_band = a.layer_band_d50 * d50;
  if (a.rose_bins < 4 || a.rose_bins > 3600)
    throw InputError(file, "--rose-bins: not in [4, 3600]", std::to_string(a.rose_bins));
  o.fabric_bins = a.rose_bins;
  if (!(a.phi_i > 0 && a.phi_i < 90))
    throw InputError(file, "--phi-i: not in (0, 90) deg", value_str(a.phi_i));
  require_positive(file, "--en-k", a.en_k);
  if (!(a.rev_width_d50 >= 0) || !std::isfinite(a.rev_width_d50))
    throw InputError(file, "--rev-width-d50: negative", value_str(a.rev_width_d50));
  o.rev_width = a.rev_width_d50 * d50;
  if (a.flow_bands < 0 || a.flow_bands > 10000)
    throw InputError(file, "--flow-bands: not in [0, 10000]", std::to_string(a.flow_bands));
  o.flow_bands = a.flow_bands;
  require_positive(file, "--flow-wall-d50", a.flow_wall_d50);
  o.flow_wall_width = a.flow_wall_d50 * d50;
  if (!(a.flow_threshold > 0 && a.flow_threshold < 1))
    throw InputError(file, "--flow-threshold: not in (0, 1)", value_str(a.flow_threshold));
  o.flow_threshold = a.flow_threshold;
  auto& reports = out.reports;
  for (long i = from; i < n; ++i) {
    try {
      reports.push_back(
          silo_report(t[static_cast<std::size_t>(i)], o, &t[static_cast<std::size_t>(from)]));
    } catch (const std::invalid_argument& e) {
      throw InputError(file, "frame " + std::to_string(i) + ": " + e.what());
    }
  }
  // The states of seed 004 §5.3.1: initial (the first frame reported), maximum (the largest
  // N_left + N_right), residual (the last).
  std::size_t k_max = 0;
  for (std::size_t k = 0; k < reports.size(); ++k)
    if (reports[k].N_left + reports[k].N_right > reports[k_max].N_left + reports[k_max].N_right)
      k_max = k;
  out.states = {SiloState{"initial", 0}, SiloState{"maximum", k_max},
                SiloState{"residual", reports.size() - 1}};
  for (auto& s : out.states) {
    const auto& r = reports[s.index];
    const double phi_w = 0.5 * (r.phi_left_deg + r.phi_right_deg);
    const double mu = std::tan(phi_w * M_PI / 180.0);
    s.phi_w_mean_deg = phi_w;
    s.K_drescher = s.P_G_drescher = s.P_G_en1991 = NAN;
    if (mu > 0 && r.width > 0 && r.fill_height > 0) {
      if (phi_w <= a.phi_i) {
        s.K_drescher = drescher_lateral_ratio(a.phi_i, phi_w);
        s.P_G_drescher = janssen_p_over_g(s.K_drescher, mu, r.width, r.fill_height);
      }
      s.P_G_en1991 = janssen_p_over_g(a.en_k, mu, r.width, r.fill_height);
    }
  }
  const char* names[] = {"frame",
                         "time_s",
                         "G_N",
                         "P_N",
                         "T_left_N",
                         "T_right_N",
                         "N_left_N",
                         "N_right_N",
                         "P_G",
                         "T_left_G",
                         "T_right_G",
                         "N_left_G",
                         "N_right_G",
                         "balance_G",
                         "phi_w_left_deg",
                         "phi_w_right_deg",
                         "discharged_kg",
                         "flow_pattern",
                         "transition_left_m",
                         "transition_right_m",
                         "flow_speed_m_s",
                         "zone_left_m",
                         "zone_right_m",
                         "zone_extent_left_m",
                         "zone_extent_right_m"};
  for (const char* name : names) out.series.emplace_back(name, std::vector<double>{});
  for (std::size_t k = 0; k < reports.size(); ++k) {
    const auto& r = reports[k];
    const double v[] = {static_cast<double>(from) + static_cast<double>(k),
                        r.time,
                        r.G,
                        r.P,
                        r.T_left,
                        r.T_right,
                        r.N_left,
                        r.N_right,
                        r.P / r.G,
                        r.T_left / r.G,
                        r.T_right / r.G,
                        r.N_left / r.G,
                        r.N_right / r.G,
                        r.balance,
                        r.phi_left_deg,
                        r.phi_right_deg,
                        (reports.front().G - r.G) / a.gravity,
                        static_cast<double>(static_cast<int>(r.flow)),
                        r.transition_left,
                        r.transition_right,
                        r.flow_speed,
                        r.zone_left,
                        r.zone_right,
                        r.zone_extent_left,
                        r.zone_extent_right};
    for (std::size_t c = 0; c < out.series.size(); ++c) out.series[c].second.push_back(v[c]);
  }
  return out;
}

}  // namespace gs::analysis
