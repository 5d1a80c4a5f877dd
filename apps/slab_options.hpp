// Command-line options of a slab projected onto its plane (seed 000 §5), shared by
// `analyze strain` and `analyze hhd` / `analyze vortices` (analysis::ProjectionSlabSpec holds
// what they mean).
#pragma once

#include <CLI/CLI.hpp>

#include "selection.hpp"

namespace gs::cli {

using SlabArgs = analysis::ProjectionSlabSpec;

/// --slab-origin, --slab-normal, --slab-axis, --slab-thickness, --slab-d50.
void add_slab_options(CLI::App* app, SlabArgs& a);

}  // namespace gs::cli
