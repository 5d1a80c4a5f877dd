// Options and helpers shared by the snapshot analyses `analyze rev | shearzone | invariants |
// fabric | rose | chains | walls`: frame selection (--frame, default last; --to), lengths given
// in m or in d50, the slab (seed 000 §3: a slice 5 d50 thick, default the front view x-z through
// the specimen centre), a region box, and the particle/contact selection they imply.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rev_map.hpp"
#include "selection.hpp"
#include "slab_projection.hpp"
#include "snapshot.hpp"

namespace gs::cli {

struct FrameArgs {
  std::string input;
  long frame = -1;  // negative: from the end
  std::optional<long> to;
  std::optional<double> d50;  // m; default: d50_of()

  /// Adds INPUT (positional), --frame, --d50 and, with `with_to`, --to.
  void add_to(CLI::App& cmd, bool with_to, bool input_required = true);
  /// The frame (negative --frame counts from the end).
  Frame load() const;
  /// The --to frame, when given.
  std::optional<Frame> load_to() const;
  long frame_index() const;
  /// --d50, else the d50 the run's scene recorded (analysis::recorded_d50), else the frame's
  /// median by volume (m).
  double d50_of(const Frame& f) const;
};

using analysis::length_option;
using analysis::require_positive;
using analysis::view_axes;

/// REV grid: cell size L and step s, in m or d50 (defaults 5 d50 and 1 d50).
struct GridArgs : analysis::GridSpec {
  void add_to(CLI::App& cmd);
};

/// --slab, --slab-origin, --slab-normal, --slab-axis, --slab-thickness, --slab-d50, --region
/// (analysis/selection.hpp holds what they mean).
struct SelectionArgs : analysis::SelectionSpec {
  using Selection = analysis::Selection;
  void add_to(CLI::App& cmd, bool with_region = true);
  Selection selection(const std::string& file, const Frame& f, double d50) const {
    return analysis::make_selection(file, f, d50, *this);
  }
};

}  // namespace gs::cli
