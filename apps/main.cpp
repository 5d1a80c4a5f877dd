// granoscope command-line interface. Each module registers its subcommands (apps/commands.hpp).
#include <CLI/CLI.hpp>
#include <iostream>

#include "snapshot.hpp"

int main(int argc, char** argv) {
  CLI::App app{"granoscope: DEM simulation and analysis of granular materials"};
  app.set_version_flag("--version", gs::code_version());
  app.require_subcommand(1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return 0;
}
