// `granoscope analyze silo RUN.h5`: the silo report of seed 004 §5.3 over the frames of a run
// (analysis/silo_report.hpp): P/G, T/G, N/G per side wall, the balance (P + 2T)/G and φ_w per
// frame, and the wall stress profiles σ11, σ21 against the height at the initial, maximum
// (largest N) and residual (last) states.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "analyze_common.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "grain_size.hpp"
#include "silo_report.hpp"
#include "silo_series.hpp"
#include "trajectory_io.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

struct SiloArgs {
  std::string input, output, csv, profiles_csv;
  std::vector<double> up{0.0, 0.0, 1.0}, across{1.0, 0.0, 0.0};
  ga::SiloSpec spec;
};

void run_silo(const SiloArgs& a) {
  ga::SiloSpec spec = a.spec;
  spec.up = Eigen::Vector3d(a.up[0], a.up[1], a.up[2]);
  spec.across = Eigen::Vector3d(a.across[0], a.across[1], a.across[2]);
  const Trajectory t = read_snapshots(a.input);
  spec.scene_d50 = ga::recorded_d50(t.metadata.parameters);
  const ga::SiloSeries run = ga::silo_series(a.input, t.frames, spec);
  const auto& reports = run.reports;
  const auto& series = run.series;
  const double d50 = run.d50;
  const long from = run.from;
  std::printf("d50 %.6g m (%s)\n", d50, run.d50_source);
  const ga::SiloReportOptions& o = run.options;
  H5FieldFile h(a.output, "granoscope-silo");
  h.attr("source", a.input);
  h.attr("d50", d50);
  h.attr("bin", o.bin);
  h.group("/series");
  for (const auto& [name, v] : series) h.write(std::string("/series/") + name, v);
  h.group("/profiles");
  std::vector<double> st, ph, s11l, s21l, s11r, s21r, l11l, l21l, l11r, l21r;
  for (std::size_t i = 0; i < run.states.size(); ++i) {
    const ga::SiloState& state = run.states[i];
    const char* name = state.name;
    const std::size_t k = state.index;
    const auto& r = reports[k];
    const std::string g = std::string("/profiles/") + name;
    h.group(g);
    h.attr("frame", static_cast<long long>(from + static_cast<long>(k)), g);
    h.attr("time_s", r.time, g);
    h.write(g + "/height_m", r.profile.height);
    h.write(g + "/sigma11_left_Pa", r.profile.sigma11_left);
    h.write(g + "/sigma21_left_Pa", r.profile.sigma21_left);
    h.write(g + "/sigma11_right_Pa", r.profile.sigma11_right);
    h.write(g + "/sigma21_right_Pa", r.profile.sigma21_right);
    h.write(g + "/lw_sigma11_left_Pa", r.profile.lw_sigma11_left);
    h.write(g + "/lw_sigma21_left_Pa", r.profile.lw_sigma21_left);
    h.write(g + "/lw_sigma11_right_Pa", r.profile.lw_sigma11_right);
    h.write(g + "/lw_sigma21_right_Pa", r.profile.lw_sigma21_right);
    h.attr("zone_height_m", r.zone_height, g);
    h.attr("zone_left_m", r.zone_left, g);
    h.attr("zone_right_m", r.zone_right, g);
    h.attr("zone_core_rad", r.zone_core, g);
    h.attr("zone_extent_left_m", r.zone_extent_left, g);
    h.attr("zone_extent_right_m", r.zone_extent_right, g);
    h.write(g + "/zone_across_m", r.zone_across);
    h.write(g + "/zone_rotation_rad", r.zone_rotation);
    // Void ratio across the width at the layers' heights (one row per layer).
    std::vector<double> lh, la, le, lu, lw;
    for (const auto& L : r.layers)
      for (std::size_t b = 0; b < L.across.size(); ++b) {
        lh.push_back(L.height);
        la.push_back(L.across[b]);
        le.push_back(L.void_ratio[b]);
        lu.push_back(L.displacement_down[b]);
        lw.push_back(L.rotation[b]);
      }
    h.write(g + "/layer_height_m", lh);
    h.write(g + "/layer_across_m", la);
    h.write(g + "/layer_void_ratio", le);
    h.write(g + "/layer_displacement_down_m", lu);
    h.write(g + "/layer_rotation_rad", lw);
    h.write(g + "/rose_left_angle_deg", r.rose_angle_deg);
    h.write(g + "/rose_left_density", r.rose_density);
    h.attr("fabric_left_angle_deg", r.fabric_angle_deg, g);
    h.attr("fabric_left_anisotropy", r.fabric_anisotropy, g);
    h.attr("fabric_left_contacts", static_cast<long long>(r.fabric_contacts), g);
    // The slice method beside ours (Eq 5.1 with R = b/2; K from Eq 5.2 with this state's
    // mean wall friction angle, and EN 1991-4's K).
    const double phi_w = state.phi_w_mean_deg;
    const double k_dr = state.K_drescher, p_dr = state.P_G_drescher, p_en = state.P_G_en1991;
    h.attr("phi_w_mean_deg", phi_w, g);
    h.attr("K_drescher", k_dr, g);
    h.attr("P_G_drescher", p_dr, g);
    h.attr("P_G_en1991", p_en, g);
    h.attr("width_m", r.width, g);
    h.attr("fill_height_m", r.fill_height, g);
    for (std::size_t b = 0; b < r.profile.height.size(); ++b) {
      st.push_back(static_cast<double>(i));
      ph.push_back(r.profile.height[b]);
      s11l.push_back(r.profile.sigma11_left[b]);
      s21l.push_back(r.profile.sigma21_left[b]);
      s11r.push_back(r.profile.sigma11_right[b]);
      s21r.push_back(r.profile.sigma21_right[b]);
      const bool lw = !r.profile.lw_sigma11_left.empty();
      l11l.push_back(lw ? r.profile.lw_sigma11_left[b] : NAN);
      l21l.push_back(lw ? r.profile.lw_sigma21_left[b] : NAN);
      l11r.push_back(lw ? r.profile.lw_sigma11_right[b] : NAN);
      l21r.push_back(lw ? r.profile.lw_sigma21_right[b] : NAN);
    }
    std::printf(
        "%-8s frame %ld (t = %.4g s): P/G %.3f, T/G %.3f / %.3f, N/G %.3f / %.3f (left / right), "
        "phi_w %.1f / %.1f deg, (P + T_left + T_right)/G %.3f; wall zones %.1f / %.1f d50 at "
        "%.3g m (extent %.1f / %.1f d50)\n",
        name, from + static_cast<long>(k), r.time, r.P / r.G, r.T_left / r.G, r.T_right / r.G,
        r.N_left / r.G, r.N_right / r.G, r.phi_left_deg, r.phi_right_deg, r.balance,
        r.zone_left / d50, r.zone_right / d50, r.zone_height, r.zone_extent_left / d50,
        r.zone_extent_right / d50);
    std::printf("         P/G by the slice method (Eq 5.1, R = b/2, mu = tan %.1f deg): ", phi_w);
    if (std::isnan(k_dr) && !(phi_w > 0))
      std::printf("n/a (no wall friction mobilised)");
    else if (std::isnan(k_dr))
      std::printf("Drescher n/a (phi_w > phi_i = %g deg)", a.spec.phi_i);
    else
      std::printf("Drescher %.3f (K %.3f, Eq 5.2, phi_i %g deg)", p_dr, k_dr, a.spec.phi_i);
    if (phi_w > 0) std::printf(", EN 1991-4 %.3f (K %g)", p_en, a.spec.en_k);
    std::printf("; ours %.3f\n", r.P / r.G);
    for (const auto& L : r.layers) {
      double e_wall = 0, e_mid = 0;
      const std::size_t nb = L.void_ratio.size();
      e_wall = 0.5 * (L.void_ratio.front() + L.void_ratio.back());
      e_mid = L.void_ratio[nb / 2];
      std::printf("         void ratio at %.3g m: %.3f next to the walls, %.3f in the middle\n",
                  L.height, e_wall, e_mid);
    }
    if (!r.profile.lw_sigma11_left.empty()) {
      // Mean over the bins of both walls: the wall-binned stresses against Love–Weber's.
      double w11 = 0, l11 = 0, w21 = 0, l21 = 0;
      const auto& q = r.profile;
      for (std::size_t b = 0; b < q.height.size(); ++b) {
        w11 += 0.5 * (q.sigma11_left[b] + q.sigma11_right[b]);
        l11 += 0.5 * (q.lw_sigma11_left[b] + q.lw_sigma11_right[b]);
        w21 += 0.5 * (q.sigma21_left[b] + q.sigma21_right[b]);
        l21 += 0.5 * (q.lw_sigma21_left[b] + q.lw_sigma21_right[b]);
      }
      const double nb = static_cast<double>(q.height.size());
      std::printf(
          "         wall stresses, mean over the height: sigma11 %.4g Pa (walls) / %.4g Pa "
          "(Love-Weber, near-wall cells), sigma21 %.4g / %.4g Pa\n",
          w11 / nb, l11 / nb, w21 / nb, l21 / nb);
    }
    if (o.flow_bands > 0)
      std::printf(
          "         flow: %s (the walls move from %.3g / %.3g m up; fastest column "
          "%.3g m/s)\n",
          ga::flow_pattern_name(r.flow), r.transition_left, r.transition_right, r.flow_speed);
    if (r.fabric_contacts > 0)
      std::printf(
          "         left half: %zu contacts, major direction %.1f deg from the wall normal "
          "(anisotropy %.3f)\n",
          r.fabric_contacts, r.fabric_angle_deg, r.fabric_anisotropy);
  }
  h.commit();
  if (!a.csv.empty()) {
    std::vector<VtkArray> cols;
    for (const auto& [name, v] : series) cols.push_back({name, 1, v});
    write_csv_table(a.csv, cols);
  }
  if (!a.profiles_csv.empty())
    write_csv_table(a.profiles_csv, {{"state", 1, st},
                                     {"height_m", 1, ph},
                                     {"sigma11_left_Pa", 1, s11l},
                                     {"sigma21_left_Pa", 1, s21l},
                                     {"sigma11_right_Pa", 1, s11r},
                                     {"sigma21_right_Pa", 1, s21r},
                                     {"lw_sigma11_left_Pa", 1, l11l},
                                     {"lw_sigma21_left_Pa", 1, l21l},
                                     {"lw_sigma11_right_Pa", 1, l11r},
                                     {"lw_sigma21_right_Pa", 1, l21r}});
}

}  // namespace

void register_analyze_silo(CLI::App& app) {
  auto& analyze = analyze_command(app);
  auto a = std::make_shared<SiloArgs>();
  auto* s = analyze.add_subcommand(
      "silo",
      "Silo report (seed 004 §5.3): P/G, T/G, N/G and phi_w per side wall over the frames, and "
      "the wall stress profiles sigma11, sigma21 at the initial, maximum and residual states");
  s->add_option("input", a->input, "trajectory of a silo run (HDF5 or any snapshot format)")
      ->required();
  s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-silo)")->required();
  s->add_option("--csv", a->csv, "also write the series as CSV");
  s->add_option("--profiles-csv", a->profiles_csv,
                "also write the profiles as CSV (state 0 initial, 1 maximum, 2 residual)");
  s->add_option("--from", a->spec.from, "first frame (the initial state; default 0)");
  s->add_option("--from-time", a->spec.from_time,
                "first frame at or after this time in s (a silo run: curve.csv's first time_s, "
                "the end of the filling)");
  s->add_option("--up", a->up, "vertical direction x y z (default 0 0 1)")->expected(3);
  s->add_option("--across", a->across, "from the left wall to the right (default 1 0 0)")
      ->expected(3);
  s->add_option("--bin", a->spec.bin, "profile bin along the height in m");
  s->add_option("--bin-d50", a->spec.bin_d50, "profile bin in d50 (default 5)");
  s->add_option("--depth", a->spec.depth, "silo depth in m (default: extent of the particles)");
  s->add_option(
      "--d50", a->spec.d50,
      "d50 in m (default: the one the silo scene recorded, else the last frame's median by "
      "volume)");
  s->add_option("--gravity", a->spec.gravity, "m/s^2 for the weight G (default 9.81)");
  s->add_option("--zone-height", a->spec.zone_height,
                "height of the wall shear zones above the bottom in m (default: half the fill)");
  s->add_option("--zone-band-d50", a->spec.zone_band_d50,
                "thickness of the band the rotation profile is taken in, d50 (default 5)");
  s->add_option("--zone-bin-d50", a->spec.zone_bin_d50,
                "bins across the silo, or the REV cells' step, d50 (default 1)");
  s->add_option("--zone-window-d50", a->spec.zone_window_d50,
                "average the rotation profile in REV cells this wide, moved by --zone-bin-d50 "
                "(seed 004 §4.2: 5), d50 (default 0: bins, smoothed by [1 2 1]/4)");
  s->add_option("--zone-extent-factor", a->spec.zone_extent_factor,
                "a wall zone's extent ends where the rotation falls below this multiple of the "
                "core's (default 2)");
  s->add_option("--layers", a->spec.layers,
                "heights of the void-ratio layers as fractions of the fill (default 0.2 0.5 0.8: "
                "10, 25 and 40 cm of the seed's 0.5 m)");
  s->add_option("--layer-bin-d50", a->spec.layer_bin_d50,
                "void-ratio boxes across, d50 (default 2)");
  s->add_option("--layer-band-d50", a->spec.layer_band_d50,
                "thickness of the void-ratio layers, d50 (default 5)");
  s->add_option("--rose-bins", a->spec.rose_bins,
                "bins of the left half's contact rose over 360 deg (default 36)");
  s->add_option("--rev-width-d50", a->spec.rev_width_d50,
                "width of the near-wall Love-Weber cells, d50 (default 2; 0: none)");
  s->add_option("--flow-bands", a->spec.flow_bands,
                "bands of the fill for the flow pattern (default 10; 0: none)");
  s->add_option("--flow-wall-d50", a->spec.flow_wall_d50,
                "width of the columns at the walls for the flow pattern, d50 (default 3)");
  s->add_option("--flow-threshold", a->spec.flow_threshold,
                "a wall moves when its column goes down faster than this fraction of the "
                "fastest column (default 0.1)");
  s->add_option("--phi-i", a->spec.phi_i,
                "internal friction angle for Eq 5.2, deg (default 35, seed 004 §5.3.1)");
  s->add_option("--en-k", a->spec.en_k,
                "EN 1991-4 lateral pressure ratio (default 0.63 = 0.45 x 1.4, seed 004 §5.3.1)");
  s->callback([a] { run_silo(*a); });
}

}  // namespace gs::cli
