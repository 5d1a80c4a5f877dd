// `granoscope analyze interface RUN.h5`: the interface shear zone of seed 004 §4.3–4.4 in one
// frame of an interface shear run (analysis/interface_zone.hpp): the profiles of the mean
// rotation and of the horizontal displacement against the height above the surface, the zone's
// boundaries and thickness from the rotation profile's inflections, and the slip at the surface.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "analyze_common.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_motion.hpp"
#include "grain_size.hpp"
#include "hdf5_trajectory.hpp"
#include "interface_zone.hpp"
#include "trajectory_io.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

struct InterfaceArgs {
  FrameArgs in;  // input, --frame, --d50
  std::string output, csv;
  long from = 0;
  ga::InterfaceSpec spec;
};

void run_interface(const InterfaceArgs& a) {
  const std::string& file = a.in.input;
  const Frame f = a.in.load();
  const long k = a.in.frame_index();
  const double d50 = a.in.d50_of(f);
  long r = a.from;
  if (r < 0) r += static_cast<long>(frame_count(file));
  const std::optional<Frame> reference =
      r != k ? std::optional<Frame>(read_frame(file, r)) : std::nullopt;
  // The surface's mean level: given, or what the interface shear run recorded.
  std::optional<double> recorded;
  if (!a.spec.surface_z && is_hdf5_file(file))
    recorded = ga::recorded_surface(TrajectoryReader(file).metadata().parameters);
  ga::InterfaceZoneOptions o = ga::interface_zone_options(file, d50, a.spec, recorded);
  if (reference) o.reference = &*reference;
  ga::InterfaceZone z;
  try {
    z = ga::interface_zone(f, o);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, "frame " + std::to_string(k) + ": " + e.what());
  }
  H5FieldFile h(a.output, "granoscope-interface");
  h.attr("source", file);
  h.attr("frame", static_cast<long long>(k));
  h.attr("reference_frame", static_cast<long long>(r));
  h.attr("time_s", f.time);
  h.attr("d50", d50);
  h.attr("bin", o.bin);
  h.attr("surface_z_m", o.surface_z);
  h.attr("x_lo_m", z.x_lo);
  h.attr("x_hi_m", z.x_hi);
  h.attr("peak_height_m", z.peak_height);
  h.attr("zone_lower_m", z.lower);
  h.attr("zone_upper_m", z.upper);
  h.attr("zone_thickness_m", z.thickness);
  h.attr("u_top_m", z.u_top);
  h.attr("u_surface_m", z.u_surface);
  h.attr("slip_ratio", z.slip_ratio);
  h.write("/height_m", z.height);
  h.write("/rotation_rad", z.rotation);
  h.write("/displacement_x_m", z.displacement);
  h.write("/count", z.count);
  h.commit();
  if (!a.csv.empty())
    write_csv_table(a.csv, {{"height_m", 1, z.height},
                            {"rotation_rad", 1, z.rotation},
                            {"displacement_x_m", 1, z.displacement},
                            {"count", 1, z.count}});
  std::printf(
      "interface zone, frame %ld (t = %.4g s): rotation peak %.2f d50 above the surface, zone "
      "%.2f to %.2f d50 (thickness %.2f d50); displacement since frame %ld: top %.4g m, at the "
      "surface %.4g m (slip ratio %.3f)\n",
      k, f.time, z.peak_height / d50, z.lower / d50, z.upper / d50, z.thickness / d50, r, z.u_top,
      z.u_surface, z.slip_ratio);
}

}  // namespace

void register_analyze_interface(CLI::App& app) {
  auto& analyze = analyze_command(app);
  auto a = std::make_shared<InterfaceArgs>();
  auto* s = analyze.add_subcommand(
      "interface",
      "Interface shear zone (seed 004 §4.3-4.4): rotation and displacement profiles against the "
      "height above the surface, the zone's thickness from the rotation profile's inflections, "
      "the slip at the surface");
  a->in.add_to(*s, false);
  s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-interface)")->required();
  s->add_option("--csv", a->csv, "also write the profiles as CSV");
  s->add_option("--from", a->from,
                "reference frame of the displacements, negative from the end (default 0)");
  s->add_option("--surface-z", a->spec.surface_z,
                "the surface's mean level in m (default: recorded by the interface shear run)");
  s->add_option("--bin", a->spec.bin, "profile bin in m");
  s->add_option("--bin-d50", a->spec.bin_d50, "profile bin in d50 (default 1)");
  s->add_option("--inset-d50", a->spec.inset_d50,
                "profiles this far in from the specimen's ends, d50 (default 2)");
  s->callback([a] { run_interface(*a); });
}

}  // namespace gs::cli
