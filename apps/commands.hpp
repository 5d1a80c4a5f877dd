// Subcommand registration. Each module adds a `register_*` function in apps/cmd_<name>.cpp and
// one line in main.cpp. Callbacks throw (gs::InputError for bad input); main() prints
// "error: FILE: what (value)" on one line and exits with code 2.
#pragma once

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdlib>

namespace gs::cli {

/// Processes in this launch (mpirun sets OMPI_COMM_WORLD_SIZE; other launchers PMI_SIZE).
inline int launched_processes() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* s = std::getenv(v)) return std::max(1, std::atoi(s));
  return 1;
}

/// Thrown by a subcommand to make main() return `code` without printing anything more (the
/// message, if any, was printed already, e.g. by a child process).
struct ExitStatus {
  int code;
};

// Declarations, one line each (keep sorted by module):
void register_info(CLI::App& app);      // io
void register_convert(CLI::App& app);   // io
void register_figures(CLI::App& app);   // apps
void register_simulate(CLI::App& app);  // solver
void register_surface(CLI::App& app);   // solver (apps/cmd_surface.cpp)
void register_dic(CLI::App& app);       // dic (apps/cmd_dic.cpp)

/// `granoscope analyze` parent; analyses register below it (analyze hhd, analyze strain, ...).
CLI::App& analyze_command(CLI::App& app);
/// `granoscope analyze strain` and `granoscope analyze voidcells` (apps/cmd_strain.cpp).
void register_analyze_strain(CLI::App& app);
/// `granoscope analyze rev | shearzone | invariants` (apps/cmd_rev.cpp).
void register_analyze_rev(CLI::App& app);
/// `granoscope analyze fabric | rose | chains | walls` (apps/cmd_contacts.cpp).
void register_analyze_contacts(CLI::App& app);

/// `granoscope analyze silo` (apps/cmd_silo.cpp).
void register_analyze_silo(CLI::App& app);
/// `granoscope analyze rotation` (apps/cmd_rotation.cpp).
void register_analyze_rotation(CLI::App& app);
/// `granoscope analyze interface` (apps/cmd_interface.cpp).
void register_analyze_interface(CLI::App& app);

/// `granoscope analyze hhd` and `granoscope analyze vortices` (apps/cmd_hhd.cpp).
void register_analyze_hhd(CLI::App& app);
/// `granoscope analyze materials` (apps/cmd_materials.cpp).
void register_analyze_materials(CLI::App& app);

}  // namespace gs::cli
