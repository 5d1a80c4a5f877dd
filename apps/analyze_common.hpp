// Options and helpers shared by the snapshot analyses `analyze rev | shearzone | invariants |
// fabric | rose | chains | walls`: frame selection (--frame, default last; --to), lengths given
// in m or in d50, the slab (seed 000 §3: a slice 5 d50 thick, default the front view x-z through
// the specimen centre), a region box, and the particle/contact selection they imply.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "slab_projection.hpp"
#include "snapshot.hpp"

namespace gs::cli {

struct FrameArgs {
  std::string input;
  long frame = -1;  // negative: from the end
  std::optional<long> to;
  std::optional<double> d50;  // m; default: from the frame

  /// Adds INPUT (positional), --frame, --d50 and, with `with_to`, --to.
  void add_to(CLI::App& cmd, bool with_to, bool input_required = true);
  /// The frame (negative --frame counts from the end).
  Frame load() const;
  /// The --to frame, when given.
  std::optional<Frame> load_to() const;
  long frame_index() const;
  /// d50 of the frame unless --d50 was given (m).
  double d50_of(const Frame& f) const;
};

/// A length given in m (`m`) or in multiples of d50 (`k`): m if given, else k d50, else
/// fallback_d50 d50. Throws InputError for a given value <= 0 or not finite.
double length_option(const std::string& file, const char* name, const std::optional<double>& m,
                     const std::optional<double>& k, double fallback_d50, double d50);

/// Rejects a non-finite or non-positive value with one line naming the option.
void require_positive(const std::string& file, const char* name, double v);

/// REV grid: cell size L and step s, in m or d50 (defaults 5 d50 and 1 d50).
struct GridArgs {
  std::optional<double> cell, cell_d50, step, step_d50;
  void add_to(CLI::App& cmd);
  double cell_size(const std::string& file, double d50) const;
  double step_size(const std::string& file, double d50) const;
};

struct SelectionArgs {
  bool slab = false;  // --slab: the default front slab
  std::vector<double> slab_origin, slab_normal, slab_axis;
  std::optional<double> slab_thickness, slab_d50;
  std::vector<double> region;  // x0 y0 z0 x1 y1 z1

  void add_to(CLI::App& cmd, bool with_region = true);
  bool slab_requested() const;
  /// The slab (default: front view, normal -y, axis x: map x to the right, z up; through the
  /// centre of the particles; 5 d50 thick). Throws InputError on bad geometry.
  std::optional<analysis::Slab> make_slab(const std::string& file, const Frame& f,
                                          double d50) const;
  /// Region as (lo, hi), validated.
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> make_region(
      const std::string& file) const;
  /// The slab and region as one predicate on points (all points when neither is given).
  struct Selection {
    std::optional<analysis::Slab> slab;
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // slab axes
    std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> box;
    bool active() const { return slab || box; }
    bool contains(const Eigen::Vector3d& x) const;
  };
  Selection selection(const std::string& file, const Frame& f, double d50) const;
};

/// Plane axes for 2D views: rows e1, e2, n. 2D frames: x, y; 3D: the slab's axes when given,
/// else the front view (x to the right, z up).
Eigen::Matrix3d view_axes(const Frame& f, const std::optional<analysis::Slab>& slab);

}  // namespace gs::cli
