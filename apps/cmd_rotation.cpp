// `granoscope analyze rotation RUN.h5`: seed 003's measures of a principal stress rotation run
// (analysis/rotation_report.hpp): the strains of the rotation against α and cycles (Figs 6, 7, 9),
// the normalised strain increments and the non-coaxiality over windows of Δα (Fig 10), the
// contact fabric and α − α_F per frame (Figs 14-16), the clumps' orientation fabric (Fig 17), and
// a line per cycle.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "rotation_report.hpp"
#include "trajectory_io.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

struct RotationArgs {
  std::string input, curve, output;
  double window_deg = 3.0;
};

std::vector<VtkArray> csv_columns(const ga::RotationColumns& c) {
  std::vector<VtkArray> out;
  for (const auto& [name, v] : c) out.push_back({name, 1, v});
  return out;
}

void run_rotation(const RotationArgs& a) {
  const std::filesystem::path in(a.input);
  const std::filesystem::path curve_path =
      a.curve.empty() ? in.parent_path() / "curve.csv" : std::filesystem::path(a.curve);
  if (!(a.window_deg > 0))
    throw InputError(a.input, "--window-deg must be positive", std::to_string(a.window_deg));
  const auto curve = ga::read_rotation_curve(curve_path);
  const auto r = ga::rotation_report(curve, read_snapshots(a.input).frames, a.window_deg,
                                     curve_path.string(), a.input);
  const std::filesystem::path out(a.output);
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw InputError(a.output, "cannot create the output directory", ec.message());
  write_csv_table(out / "rotation_strain.csv", csv_columns(ga::rotation_strain_table(r)));
  write_csv_table(out / "rotation_increments.csv", csv_columns(ga::rotation_increments_table(r)));
  write_csv_table(out / "rotation_fabric.csv", csv_columns(ga::rotation_fabric_table(r)));
  write_csv_table(out / "rotation_cycles.csv", csv_columns(ga::rotation_cycles_table(r)));
  // The summary: the paper's statements in numbers.
  const auto& rows = r.rows;
  double ncs = 0, ymax = 0, dymax = 0;
  for (const auto& s : r.increments) ncs += s.non_coaxiality_deg;
  for (const auto& s : rows)
    ymax = std::max(ymax, std::max(std::abs(s.sigma(0, 1)), std::abs(s.sigma(1, 2))) / s.p);
  for (const auto& f : r.fabric)
    dymax = std::max(dymax, std::max(std::abs(f.contacts.D(0, 1)), std::abs(f.contacts.D(1, 2))));
  std::printf("rotation: alpha 0 -> %.4g deg (%.3g cycles), %zu curve rows, %zu frames\n",
              rows.back().alpha_deg, rows.back().alpha_deg / 180.0, rows.size(), r.fabric.size());
  std::printf("  eps_v %.4g, eps_yy %.4g at the end (from the rotation's start)\n",
              rows.back().eps_v, rows.back().eps(1, 1));
  if (!r.increments.empty())
    std::printf("  non-coaxiality alpha_deps - alpha: mean %.3g deg over %zu windows of %.3g deg\n",
                ncs / static_cast<double>(r.increments.size()), r.increments.size(), a.window_deg);
  std::printf("  y principal: max |s_xy|, |s_yz| / p = %.3g; max |D_xy|, |D_yz| = %.3g\n", ymax,
              dymax);
  for (const auto& c : r.cycles)
    std::printf(
        "  cycle %d: eps_v %.4g, eps_yy %.4g, non-coaxiality %.3g deg, fabric loop "
        "radius %.3g about (%.3g, %.3g)\n",
        c.cycle, c.eps_v, c.eps_yy, c.non_coaxiality_deg, c.fabric_radius, c.fabric_centre.x(),
        c.fabric_centre.y());
  std::printf("wrote %s/rotation_{strain,increments,fabric,cycles}.csv\n", a.output.c_str());
}

}  // namespace

void register_analyze_rotation(CLI::App& app) {
  auto& analyze = analyze_command(app);
  auto a = std::make_shared<RotationArgs>();
  auto* s = analyze.add_subcommand(
      "rotation",
      "Principal stress rotation report (seed 003 §3-4): strains against alpha and cycles, "
      "non-coaxiality, contact and particle-orientation fabric per frame, a line per cycle");
  s->add_option("input", a->input, "trajectory of a stress_rotation run")->required();
  s->add_option("--curve", a->curve, "the run's curve.csv (default: beside the trajectory)");
  s->add_option("-o,--output", a->output, "output directory for the CSV tables")->required();
  s->add_option("--window-deg", a->window_deg,
                "window of alpha for the normalised strain increments, deg (default 3, §3.2)");
  s->callback([a] { run_rotation(*a); });
}

}  // namespace gs::cli
