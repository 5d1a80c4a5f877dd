// Shared options of the snapshot analyses (see analyze_common.hpp).
#include "analyze_common.hpp"

#include <cmath>

#include "errors.hpp"
#include "frame_motion.hpp"
#include "grain_size.hpp"

namespace gs::cli {

void FrameArgs::add_to(CLI::App& cmd, bool with_to, bool input_required) {
  auto* in = cmd.add_option("input", input,
                            "snapshot file (granoscope HDF5, VTK, YADE, LIGGGHTS, packing CSV)");
  if (input_required) in->required();
  cmd.add_option("--frame", frame, "frame index, negative from the end (default -1: the last)");
  if (with_to)
    cmd.add_option("--to", to, "second frame: displacement from --frame to --to (by id)");
  cmd.add_option("--d50", d50, "median diameter in m (default: from the frame, by volume)");
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
  if (f.particles.empty()) throw InputError(input, "the frame has no particles");
  return analysis::d50(f);
}

void require_positive(const std::string& file, const char* name, double v) {
  if (!(v > 0.0) || !std::isfinite(v))
    throw InputError(file, std::string(name) + " must be a finite number > 0", value_str(v));
}

double length_option(const std::string& file, const char* name, const std::optional<double>& m,
                     const std::optional<double>& k, double fallback_d50, double d50) {
  if (m) {
    require_positive(file, name, *m);
    return *m;
  }
  if (k) {
    require_positive(file, (std::string(name) + "-d50").c_str(), *k);
    return *k * d50;
  }
  return fallback_d50 * d50;
}

void GridArgs::add_to(CLI::App& cmd) {
  cmd.add_option("--cell", cell, "REV cell size L in m");
  cmd.add_option("--cell-d50", cell_d50, "REV cell size in d50 (default 5, seed 000 §3)");
  cmd.add_option("--step", step, "grid step s in m");
  cmd.add_option("--step-d50", step_d50, "grid step in d50 (default 1)");
}

double GridArgs::cell_size(const std::string& file, double d50) const {
  return length_option(file, "--cell", cell, cell_d50, 5.0, d50);
}

double GridArgs::step_size(const std::string& file, double d50) const {
  return length_option(file, "--step", step, step_d50, 1.0, d50);
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

bool SelectionArgs::slab_requested() const {
  return slab || !slab_origin.empty() || !slab_normal.empty() || !slab_axis.empty() ||
         slab_thickness || slab_d50;
}

namespace {

Eigen::Vector3d vec(const std::string& file, const char* name, const std::vector<double>& v) {
  const Eigen::Vector3d x(v[0], v[1], v[2]);
  if (!x.allFinite()) throw InputError(file, std::string(name) + " must be finite numbers");
  return x;
}

}  // namespace

std::optional<analysis::Slab> SelectionArgs::make_slab(const std::string& file, const Frame& f,
                                                       double d50) const {
  if (!slab_requested()) return std::nullopt;
  if (f.two_d) throw InputError(file, "a slab needs a 3D frame (two_d is set)");
  analysis::Slab s;
  const auto [lo, hi] = particle_bounds(f);
  s.origin = slab_origin.size() == 3 ? vec(file, "--slab-origin", slab_origin) : 0.5 * (lo + hi);
  s.normal =
      slab_normal.size() == 3 ? vec(file, "--slab-normal", slab_normal) : Eigen::Vector3d(0, -1, 0);
  s.axis1 = slab_axis.size() == 3 ? vec(file, "--slab-axis", slab_axis) : Eigen::Vector3d::UnitX();
  s.thickness = length_option(file, "--slab-thickness", slab_thickness, slab_d50, 5.0, d50);
  try {
    (void)analysis::slab_axes(s);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  return s;
}

std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> SelectionArgs::make_region(
    const std::string& file) const {
  if (region.empty()) return std::nullopt;
  const Eigen::Vector3d lo(region[0], region[1], region[2]), hi(region[3], region[4], region[5]);
  if (!lo.allFinite() || !hi.allFinite() || !(lo.array() < hi.array()).all()) {
    throw InputError(file, "--region needs finite x0 y0 z0 x1 y1 z1 with x0 < x1, y0 < y1, z0 < z1",
                     value_str(lo.transpose()) + " " + value_str(hi.transpose()));
  }
  return std::make_pair(lo, hi);
}

SelectionArgs::Selection SelectionArgs::selection(const std::string& file, const Frame& f,
                                                  double d50) const {
  Selection s;
  s.slab = make_slab(file, f, d50);
  if (s.slab) s.axes = analysis::slab_axes(*s.slab);
  s.box = make_region(file);
  return s;
}

bool SelectionArgs::Selection::contains(const Eigen::Vector3d& x) const {
  if (slab && std::abs(axes.row(2).dot(x - slab->origin)) > 0.5 * slab->thickness) return false;
  return !box ||
         ((x.array() >= box->first.array()).all() && (x.array() <= box->second.array()).all());
}

Eigen::Matrix3d view_axes(const Frame& f, const std::optional<analysis::Slab>& slab) {
  if (slab) return analysis::slab_axes(*slab);
  Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
  if (f.two_d) return a;
  a.row(0) = Eigen::Vector3d::UnitX();
  a.row(1) = Eigen::Vector3d::UnitZ();
  a.row(2) = -Eigen::Vector3d::UnitY();
  return a;
}

}  // namespace gs::cli
