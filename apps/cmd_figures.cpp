// `granoscope figures INPUT -o DIR`: runs the shipped matplotlib scripts over a run's outputs.
#include <unistd.h>

#include <iostream>
#include <memory>

#include "commands.hpp"
#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "python_runner.hpp"

namespace gs::cli {

void register_figures(CLI::App& app) {
  auto* cmd = app.add_subcommand("figures", "Make the figures of a run or analysis output (HDF5)");
  auto in = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto type = std::make_shared<std::string>();
  auto frame = std::make_shared<long>(-1);
  cmd->add_option("INPUT", *in, "HDF5 file written by granoscope (trajectory or analysis)")
      ->required();
  cmd->add_option("-o,--out", *out, "output directory (created)")->required();
  cmd->add_option("--type", *type, "one figure type (e.g. positions); default: all for the input");
  cmd->add_option("--frame", *frame, "frame of a trajectory (negative counts from the end)")
      ->capture_default_str();
  auto field = std::make_shared<std::string>();
  cmd->add_option("--field", *field, "field of a map figure (rev), e.g. void_ratio, stress_zz");
  cmd->callback([=] {
    std::error_code ec;
    if (!std::filesystem::exists(*in, ec)) throw InputError(*in, "no such file");
    if (!is_hdf5_file(*in))
      throw InputError(
          *in, "figures need an HDF5 file written by granoscope (use `granoscope convert` first)");
    const std::string python = find_python();
    // The script's own failure here is a Python traceback: check the directory first.
    std::filesystem::create_directories(*out, ec);
    if (ec) throw InputError(*out, "cannot create output directory", ec.message());
    if (::access(out->c_str(), W_OK | X_OK) != 0)
      throw InputError(*out, "output directory is not writable");
    const auto script = figures_dir() / "granoscope_figures.py";
    if (!std::filesystem::exists(script, ec))
      throw InputError(script.string(), "figure scripts not found");
    std::vector<std::string> argv{python,    script.string(),       *in, "-o", *out,
                                  "--frame", std::to_string(*frame)};
    if (!type->empty()) {
      argv.push_back("--type");
      argv.push_back(*type);
    }
    if (!field->empty()) {
      argv.push_back("--field");
      argv.push_back(*field);
    }
    const int rc = run_process(argv);
    if (rc != 0) throw ExitStatus{rc == 2 ? 2 : (rc == 0 ? 0 : 2)};
  });
}

}  // namespace gs::cli
