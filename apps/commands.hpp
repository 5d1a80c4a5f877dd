// Subcommand registration. Each module adds a `register_*` function in apps/cmd_<name>.cpp and
// one line in main.cpp. Callbacks throw (gs::InputError for bad input); main() prints
// "error: FILE: what (value)" on one line and exits with code 2.
#pragma once

#include <CLI/CLI.hpp>

namespace gs::cli {

// Declarations, one line each (keep sorted by module):

/// `granoscope analyze` parent; analyses register below it (analyze hhd, analyze strain, ...).
CLI::App& analyze_command(CLI::App& app);
/// `granoscope analyze strain` and `granoscope analyze voidcells` (apps/cmd_strain.cpp).
void register_analyze_strain(CLI::App& app);

}  // namespace gs::cli
