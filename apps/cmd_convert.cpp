// `granoscope convert IN OUT`: any supported input to .h5 / .vtu / .pvd / .csv (by extension).
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "import_options.hpp"

namespace gs::cli {

void register_convert(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("convert", "Convert between snapshot formats, chosen by file extension");
  auto in = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto frame = std::make_shared<long>(-1);
  auto imp = std::make_shared<ImportArgs>();
  cmd->add_option("IN", *in, "input file (any supported format)")->required();
  cmd->add_option("OUT", *out,
                  "output: .h5 (all frames), .pvd (all frames), .vtu or .csv (one frame)")
      ->required();
  cmd->add_option("--frame", *frame, "frame written to .vtu/.csv; negative counts from the end")
      ->capture_default_str();
  imp->add_to(*cmd);
  cmd->callback([=] {
    output_format(*out);  // reject an unknown output type before reading anything
    const Trajectory t = read_snapshots(*in, imp->options());
    write_snapshots(*out, t, *frame);
    std::cerr << "wrote " << *out << " (" << t.frames.size() << " frame(s) read)\n";
  });
}

}  // namespace gs::cli
