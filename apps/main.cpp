// granoscope command-line interface. Each module registers its subcommands (apps/commands.hpp).
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <string>

#include "commands.hpp"
#include "snapshot.hpp"

namespace gs::cli {

CLI::App& analyze_command(CLI::App& app) {
  for (auto* sub : app.get_subcommands([](CLI::App* s) { return s->get_name() == "analyze"; }))
    return *sub;
  auto* a = app.add_subcommand("analyze", "Analyses of snapshots and trajectories");
  a->require_subcommand(1);
  return *a;
}

}  // namespace gs::cli

int main(int argc, char** argv) {
  CLI::App app{"granoscope: DEM simulation and analysis of granular materials"};
  app.set_version_flag("--version", gs::code_version());
  app.require_subcommand(1);
  // Subcommands, one line each (keep sorted by module):
  gs::cli::register_info(app);
  gs::cli::register_convert(app);
  gs::cli::register_figures(app);
  gs::cli::register_simulate(app);
  gs::cli::register_surface(app);
  gs::cli::register_dic(app);
  gs::cli::register_analyze_strain(app);
  gs::cli::register_analyze_rev(app);
  gs::cli::register_analyze_contacts(app);
  gs::cli::register_analyze_hhd(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print as CLI11 prints them; a usage error is one line, the rule of
    // every CLI path ("error: what (value)"), with no second "Run with --help" line.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::string what = e.what();
    for (char& c : what)
      if (c == '\n') c = ' ';
    std::cerr << "error: " << what << "\n";
    return 2;
  } catch (const gs::cli::ExitStatus& s) {
    return s.code;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
