// A run of a scene, as `granoscope simulate` makes it and Python's granoscope.Scene.run: the
// loading programmes in turn (preparation, then the test; a plain run of N steps), writing the
// HDF5 trajectory, the monitor history, the test's curve, the prepared specimen, results.csv,
// and checkpoints it resumes from bit for bit. Progress goes to a callback, which may ask the run
// to stop: it then writes a checkpoint and returns, and a later run with `resume` continues.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scene_file.hpp"
#include "simulation.hpp"
#include "thread_tuner.hpp"

namespace gs::solver {

/// Where a run stands (passed to RunOptions::progress).
struct RunProgress {
  std::string phase;            // the programme's name: preparation, steps, triaxial, ...
  std::size_t phase_index = 0;  // 0-based
  std::size_t phases = 1;
  std::int64_t step = 0;
  double time_s = 0.0;
  double phase_fraction = 0.0;  // 0..1 of the current programme
  double fraction = 0.0;        // 0..1 of the whole run (programmes counted equally)
  double steps_per_s = 0.0;     // since this run (or resume) began
  double eta_s = 0.0;
  bool phase_start = false;  // the first report of a programme
};

struct RunOptions {
  std::filesystem::path out;          // output directory (default out/<scene name>)
  std::optional<std::int64_t> steps;  // stop at this step (a plain scene: its own steps)
  int threads = 0;                    // 0: the scene's
  bool resume = false;                // continue from the last checkpoint in `out`
  std::string provenance;             // metadata; default "granoscope simulate FILE"
  /// With `threads = "auto"` in one process: the windows in which the run times its steps on
  /// the counts it compares (thread_tuner.hpp).
  ThreadTunerOptions thread_tuning;
  /// Called at the start of each programme and every `progress_every` steps; returning false
  /// stops the run (checkpoint written, outputs left to resume). May throw to abort likewise.
  std::function<bool(const RunProgress&)> progress;
  std::int64_t progress_every = 64;
  /// Lines for the user: summaries (print) and warnings / notices (warn). Default: dropped.
  std::function<void(const std::string&)> print, warn;
  /// A domain decomposition over processes (`mpirun`; solver/parallel/): `attach` is called
  /// with the simulation once it is set up (or loaded from a checkpoint), `gather` before each
  /// output (history row, frame, checkpoint, the end: process 0's simulation then holds the
  /// whole state) and `release` after it; `any` is an OR over processes (stops, blow-ups). Every
  /// process runs the same loop; only process 0's outputs count (`root`: the others write to a
  /// scratch directory). Plain scenes only.
  struct Parallel {
    bool root = true;
    std::function<void(Simulation&)> attach, gather, release;
    std::function<bool(bool)> any;
  };
  std::optional<Parallel> parallel;
};

using RunResults = std::vector<std::pair<std::string, double>>;

struct RunOutcome {
  std::filesystem::path out, trajectory, history, curve;  // curve: empty for a plain run
  bool ended = false;         // the last programme ended (results hold its numbers)
  bool stopped = false;       // stopped by the progress callback: resumable
  bool was_complete = false;  // resume of a finished run: nothing run
  std::int64_t step = 0;      // the last step
  std::int64_t steps_run = 0;
  std::size_t particles = 0;
  double seconds = 0.0;
  RunResults results;
};

/// Runs `scene` (loaded by load_scene). Throws InputError (naming the scene file) for a bad
/// scene, a locked or unwritable output directory, a failed filling or a blow-up.
RunOutcome run_scene(Scene scene, const RunOptions& options);

/// `results.csv` of a run: name,value rows.
void write_run_results(const std::filesystem::path& path, const RunResults& r);
RunResults read_run_results(const std::filesystem::path& path);

}  // namespace gs::solver
