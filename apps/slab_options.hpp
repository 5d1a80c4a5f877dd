// Command-line options of a slab projected onto its plane (seed 000 §5), shared by
// `analyze strain` and `analyze hhd` / `analyze vortices`.
#pragma once

#include <CLI/CLI.hpp>
#include <vector>

#include "slab_projection.hpp"
#include "snapshot.hpp"

namespace gs::cli {

struct SlabArgs {
  std::vector<double> origin, normal, axis;  // empty: defaults (origin 0, normal z, axis x)
  double thickness = 0.0;                    // m
  double d50_multiple = 0.0;                 // thickness in units of the frame's d50
  bool any() const { return !normal.empty() || thickness > 0.0 || d50_multiple > 0.0; }
};

/// --slab-origin, --slab-normal, --slab-axis, --slab-thickness, --slab-d50.
void add_slab_options(CLI::App* app, SlabArgs& a);

/// The slab for `frame`: given vectors, thickness in m or d50_multiple × d50(frame).
analysis::Slab make_slab(const SlabArgs& a, const Frame& frame);

}  // namespace gs::cli
