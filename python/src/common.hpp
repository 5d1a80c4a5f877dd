// Keyword arguments shared by the analysis bindings: the frame's d50 and the selection keywords
// (the CLI's --slab* / --region / --d50 options, same names and meanings).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "selection.hpp"
#include "snapshot.hpp"

namespace gs::py_bind {

using OptVec = std::optional<std::vector<double>>;
constexpr const char* kFrame = "<frame>";  // how messages name a frame given from Python

/// Raises a pending Ctrl-C (KeyboardInterrupt) as a C++ exception that unwinds the library call
/// it is polled from. Takes the GIL (callable from code that released it; with it held, too).
void raise_pending_signal();

/// d50 as the CLI's --d50 option gives it, else the frame's (m).
double frame_d50(const Frame& f, std::optional<double> d50);

/// The selection options as given.
analysis::SelectionSpec selection_spec(bool slab, const OptVec& slab_origin,
                                       const OptVec& slab_normal, const OptVec& slab_axis,
                                       std::optional<double> slab_thickness,
                                       std::optional<double> slab_d50, const OptVec& region);

}  // namespace gs::py_bind
