// granoscope command-line interface. Each module registers its subcommands (apps/commands.hpp).
#include <hdf5.h>

#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <string>

#include "atomic_file.hpp"
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

namespace {

/// CLI11 reports a mistyped subcommand as "A subcommand is required": name it, and the choices.
void check_subcommand_names(CLI::App& app, int argc, char** argv) {
  CLI::App* cur = &app;
  std::string path = "";
  for (int i = 1; i < argc && cur->get_require_subcommand_min() > 0; ++i) {
    const std::string a = argv[i];
    if (a.empty() || a[0] == '-') return;  // an option (--help, --version): CLI11's to judge
    CLI::App* next = nullptr;
    std::string names;
    for (auto* s : cur->get_subcommands([](CLI::App*) { return true; })) {
      if (s->check_name(a)) next = s;
      names += (names.empty() ? "" : ", ") + s->get_name();
    }
    if (!next)
      throw CLI::ParseError("unknown " + path + "subcommand (" + a + "); one of: " + names,
                            CLI::ExitCodes::ExtrasError);
    path += next->get_name() + " ";
    cur = next;
  }
}

}  // namespace

}  // namespace gs::cli

int main(int argc, char** argv) {
  // A file HDF5 could not close (a full disk) is closed again by HDF5's own exit handler, which
  // then crashes (SIGSEGV after our error line): every file is closed by its owner, so HDF5 gets
  // no exit handler.
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // HDF5's error stack printing: ours is one line
  const gs::InputScope inputs;  // no output of this command may replace one of its inputs
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
  gs::cli::register_analyze_silo(app);
  gs::cli::register_analyze_rotation(app);
  gs::cli::register_analyze_interface(app);
  gs::cli::register_analyze_hhd(app);
  gs::cli::register_analyze_materials(app);
  try {
    gs::cli::check_subcommand_names(app, argc, argv);
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
    // One line whatever a library put in its message (OpenCV's assertion text spans lines).
    std::string what = e.what();
    for (char& c : what)
      if (c == '\n' || c == '\r') c = ' ';
    while (!what.empty() && what.back() == ' ') what.pop_back();
    std::cerr << "error: " << what << "\n";
    return 2;
  }
  return 0;
}
