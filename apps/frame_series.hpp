// `granoscope analyze ... --frames A:B` (issue 23; docs/analysis.md "Frame series"): the analysis
// of one frame run for each frame of a range, in worker processes (--jobs, default the machine's
// cores; under mpirun the processes share the frames), with a progress line on a terminal, and
// the per-frame outputs merged into one output with a frame axis (io/field_series.hpp).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gs::cli {

struct FrameSeriesArgs {
  std::string frames;  // "A:B" or "A:B:S"; empty: one frame (--frame)
  int jobs = 0;        // worker processes; 0: the machine's cores

  /// Adds --frames and --jobs (after the command's other options: --frames excludes --frame,
  /// --to, --csv, --vti and --vtp where the command has them).
  void add_to(CLI::App& cmd);
  bool active() const { return !frames.empty(); }
};

/// The frames of `spec` in a trajectory of `count` frames, as a Python slice: "A:B" from A up
/// to B excluded, "A:B:S" every S-th; negative A, B count from the end; A or B left out: the
/// first or the last frame (B = the end). Throws InputError (naming `input`) on a malformed
/// range, a step below 1, or a range with no frame.
std::vector<long> frame_range(const std::string& input, const std::string& spec, long count);

/// Runs `one(frame, output)` for every frame of `series` in `input` (the analysis of that frame,
/// writing only its HDF5 output, to `output`), and merges the outputs into `output`. Prints one
/// line: the command, the frames, the workers, the time.
void run_frame_series(const std::string& command, const std::string& input,
                      const FrameSeriesArgs& series, const std::string& output,
                      const std::function<void(long, const std::string&)>& one);

/// Gives the analysis command `cmd` (arguments `a`: `in` a FrameArgs, `output`, `series`) its
/// --frames and --jobs, and a callback that runs `run` on one frame, or on each frame of the
/// series (A a copy of the arguments with the frame and the part's output set).
template <class A>
void add_frame_series(CLI::App& cmd, const std::shared_ptr<A>& a, const std::string& command,
                      void (*run)(const A&)) {
  a->series.add_to(cmd);
  cmd.callback([a, command, run] {
    if (!a->series.active()) return run(*a);
    run_frame_series(command, a->in.input, a->series, a->output,
                     [a, run](long frame, const std::string& out) {
                       A b = *a;
                       b.in.frame = frame;
                       b.output = out;
                       run(b);
                     });
  });
}

}  // namespace gs::cli
