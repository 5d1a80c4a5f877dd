// Shared options of the snapshot analyses (see analyze_common.hpp).
#include "analyze_common.hpp"

#include <cmath>

#include "errors.hpp"
#include "frame_motion.hpp"
#include "grain_size.hpp"
#include "hdf5_trajectory.hpp"

namespace gs::cli {

void FrameArgs::add_to(CLI::App& cmd, bool with_to, bool input_required) {
  auto* in = cmd.add_option("input", input,
                            "snapshot file (granoscope HDF5, VTK, YADE, LIGGGHTS, packing CSV)");
  if (input_required) in->required();
  cmd.add_option("--frame", frame, "frame index, negative from the end (default -1: the last)");
  if (with_to)
    cmd.add_option("--to", to, "second frame: displacement from --frame to --to (by id)");
  cmd.add_option(
      "--d50", d50,
      "median diameter in m (default: the one the run's scene recorded, else the frame's "
      "median by volume)");
}

long FrameArgs::frame_index() const {
  if (frame >= 0) return frame;
  const auto n = static_cast<long>(frame_count(input));
  return n + frame;  // out of range is reported by read_frame
}

Frame FrameArgs::load() const {
  if (d50) require_positive(input, "--d50", *d50);
  return read_frame(input, frame_index());
}

std::optional<Frame> FrameArgs::load_to() const {
  if (!to) return std::nullopt;
  long i = *to;
  if (i < 0) i += static_cast<long>(frame_count(input));
  return read_frame(input, i);
}

double FrameArgs::d50_of(const Frame& f) const {
  if (d50) return *d50;
  // The d50 a granoscope scene defined its lengths by (the silo's and the interface shear's
  // R_n = h_g/d50), when the run recorded one.
  if (is_hdf5_file(input))
    if (const auto r = analysis::recorded_d50(TrajectoryReader(input).metadata().parameters))
      return *r;
  if (f.particles.empty()) throw InputError(input, "the frame has no particles");
  return analysis::d50(f);
}

void GridArgs::add_to(CLI::App& cmd) {
  cmd.add_option("--cell", cell, "REV cell size L in m");
  cmd.add_option("--cell-d50", cell_d50, "REV cell size in d50 (default 5, seed 000 §3)");
  cmd.add_option("--step", step, "grid step s in m");
  cmd.add_option("--step-d50", step_d50, "grid step in d50 (default 1)");
}

void SelectionArgs::add_to(CLI::App& cmd, bool with_region) {
  cmd.add_flag("--slab", slab,
               "a slab through the specimen: default the front view (normal -y, axis x, so x "
               "to the right and z up) through the centre, 5 d50 thick (seed 000 §3)");
  cmd.add_option("--slab-origin", slab_origin, "slab mid-plane point x y z (m)")->expected(3);
  cmd.add_option("--slab-normal", slab_normal, "slab normal x y z")->expected(3);
  cmd.add_option("--slab-axis", slab_axis, "in-plane first axis x y z (map horizontal)")
      ->expected(3);
  cmd.add_option("--slab-thickness", slab_thickness, "slab thickness in m");
  cmd.add_option("--slab-d50", slab_d50, "slab thickness in d50 (default 5)");
  if (with_region) cmd.add_option("--region", region, "box x0 y0 z0 x1 y1 z1 (m)")->expected(6);
}

}  // namespace gs::cli
