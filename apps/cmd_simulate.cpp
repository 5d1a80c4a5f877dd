// `granoscope simulate SCENE.toml`: runs a DEM scene — a plain run of N steps, or a laboratory
// test (specimen preparation, then triaxial / plane-strain compression or direct shear) —
// writing an HDF5 trajectory (frames with contacts and walls), a monitor history, the test's
// macroscopic curve (CSV), the prepared specimen, and checkpoints it resumes from bit-for-bit.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <limits>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "scene_file.hpp"
#include "scene_run.hpp"
#ifdef GRANOSCOPE_MPI
#include <mpi.h>

#include "mpi_domain.hpp"
#endif

namespace gs::cli {

namespace {

namespace fs = std::filesystem;

struct Args {
  std::string scene;
  std::string out;
  std::int64_t steps = -1;
  int threads = 0;
  bool resume = false;
  bool quiet = false;
};

using Results = solver::RunResults;

/// One run; its results when its last programme ended (not when --steps stopped it first).
/// Progress on stderr: a line rewritten every 0.5 s on a terminal; elsewhere (a log, CI) one
/// line when a phase starts and at each 10 % of it.
Results run(const Args& a, int sweep_point = -1,
            std::optional<solver::RunOptions::Parallel> parallel = {}) {
  solver::Scene scene = solver::load_scene(a.scene, sweep_point);
  solver::RunOptions o;
  o.parallel = std::move(parallel);
  o.out = a.out;
  if (a.steps >= 0) o.steps = a.steps;
  o.threads = a.threads;
  o.resume = a.resume;
  o.provenance = "granoscope simulate " + a.scene;
  o.print = [](const std::string& line) { std::printf("%s\n", line.c_str()); };
  o.warn = [](const std::string& line) { std::cerr << line << "\n"; };
  const bool root = !o.parallel || o.parallel->root;
  if (!root) o.print = o.warn = {};  // (process 0 speaks for all)
  const bool tty = root && isatty(STDERR_FILENO) && !a.quiet;
  const bool log = root && !tty && !a.quiet;
  auto last_print = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  std::size_t logged_phase = std::numeric_limits<std::size_t>::max();
  int logged_tenth = -1;
  bool printed = false;
  if (tty || log) {
    o.progress = [&](const solver::RunProgress& p) {
      if (tty) {
        const auto now = std::chrono::steady_clock::now();
        if (p.phase_start || now - last_print > std::chrono::milliseconds(500)) {
          std::fprintf(stderr, "\r%s %zu/%zu: step %lld  %.1f%%  %.3g steps/s  ETA %.0f s   ",
                       p.phase.c_str(), p.phase_index + 1, p.phases, static_cast<long long>(p.step),
                       100.0 * p.phase_fraction, p.steps_per_s, p.eta_s);
          last_print = now;
          printed = true;
        }
        return true;
      }
      const int tenth = static_cast<int>(p.phase_fraction * 10.0 + 1e-9);
      if (logged_phase == p.phase_index && (p.phase_start || tenth <= logged_tenth)) return true;
      logged_phase = p.phase_index;
      logged_tenth = tenth;
      std::fprintf(stderr, "%s %zu/%zu: step %lld  %.0f%%  %.3g steps/s  ETA %.0f s\n",
                   p.phase.c_str(), p.phase_index + 1, p.phases, static_cast<long long>(p.step),
                   100.0 * p.phase_fraction, p.steps_per_s, p.eta_s);
      std::fflush(stderr);
      return true;
    };
  }
  const solver::RunOutcome r = solver::run_scene(std::move(scene), o);  // (its particles go)
  if (printed) std::fprintf(stderr, "\n");
  return r.results;
}

/// A scene with [sweep]: one run per value, each in OUT/<key leaf>_<value>/ (resumed, or read
/// back when complete, with --resume), and OUT/sweep.csv: the value and each run's results.
/// Under mpirun (`parallel`) every run is decomposed over the processes, one after the other.
void run_sweep(const Args& a, const solver::Scene& first,
               const std::optional<solver::RunOptions::Parallel>& parallel = {}) {
  const bool root = !parallel || parallel->root;  // (process 0 speaks for all)
  const solver::SweepInfo& sw = *first.sweep;
  const std::string leaf = sw.key.substr(sw.key.rfind('.') + 1);
  const fs::path out = a.out.empty() ? fs::path("out") / first.name : fs::path(a.out);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(out.string(), "cannot create output directory", ec.message());
  std::vector<std::pair<std::string, Results>> rows;
  std::vector<std::string> failed;
  for (std::size_t i = 0; i < sw.values.size(); ++i) {
    Args one = a;
    one.out = (out / (leaf + "_" + sw.values[i])).string();
    const bool started = fs::exists(fs::path(one.out) / "checkpoint.txt") ||
                         fs::exists(fs::path(one.out) / "results.csv");
    one.resume = a.resume && started;
    if (root)
      std::printf("sweep %s = %s (%zu of %zu) -> %s\n", sw.key.c_str(), sw.values[i].c_str(), i + 1,
                  sw.values.size(), one.out.c_str());
    std::fflush(stdout);
    try {
      rows.emplace_back(sw.values[i], run(one, static_cast<int>(i), parallel));
    } catch (const InputError& e) {
      // A point that fails (a blow-up, a jam) does not stop the others: its row stays empty.
      // (under mpirun every process meets it at the same step)
      if (root)
        std::printf("sweep %s = %s failed: %s\n", sw.key.c_str(), sw.values[i].c_str(), e.what());
      std::fflush(stdout);
      rows.emplace_back(sw.values[i], Results{});
      failed.push_back(sw.values[i]);
    }
    // The table so far, after every point.
    std::vector<std::string> names;
    for (const auto& [v, r] : rows)
      for (const auto& [n, x] : r)
        if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    AtomicOutput table(out / "sweep.csv");
    {
      std::ofstream o(table.temp_path());
      o << leaf;
      for (const auto& n : names) o << "," << n;
      o << ",run\n";
      char buf[64];
      for (std::size_t j = 0; j < rows.size(); ++j) {
        o << rows[j].first;
        for (const auto& n : names) {
          const auto it = std::find_if(rows[j].second.begin(), rows[j].second.end(),
                                       [&](const auto& p) { return p.first == n; });
          if (it != rows[j].second.end()) {
            std::snprintf(buf, sizeof buf, "%.9g", it->second);
            o << "," << buf;
          } else {
            o << ",";
          }
        }
        o << "," << leaf << "_" << rows[j].first << "\n";
      }
      if (!o.flush()) throw InputError((out / "sweep.csv").string(), "cannot write output");
    }
    table.commit();
  }
  if (root) std::printf("wrote %s\n", (out / "sweep.csv").string().c_str());
  if (!failed.empty()) {
    std::string list;
    for (const auto& v : failed) list += (list.empty() ? "" : ", ") + v;
    throw InputError(a.scene,
                     "sweep: " + std::to_string(failed.size()) + " of " +
                         std::to_string(sw.values.size()) + " runs failed (see the output above)",
                     list);
  }
}

#ifdef GRANOSCOPE_MPI
/// A scene run by the processes of an mpirun (docs/scale.md): each steps its slab
/// (solver/parallel/mpi_domain.hpp); process 0 writes the outputs, the others a scratch copy
/// that is removed at the end. An error found by every process (the scene, a blow-up) is
/// reported once by process 0, exit code 2; one process's own error aborts them all.
void run_mpi(const Args& a) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  solver::MpiDomain domain(MPI_COMM_WORLD);
  const bool root = domain.rank() == 0;
  fs::path scratch;
  auto fail = [&](const std::string& line, bool everyone) {
    if (everyone) {
      // An error every process should meet at the same point (a scene error, a blow-up, which
      // the processes agree on) is confirmed by a barrier all of them reach within a few
      // seconds; one this process met alone (a file it read) leaves the others waiting
      // elsewhere, and then aborts them instead of leaving them to hang.
      MPI_Request all;
      MPI_Ibarrier(MPI_COMM_WORLD, &all);
      int reached = 0;
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!reached && std::chrono::steady_clock::now() < until) {
        MPI_Test(&all, &reached, MPI_STATUS_IGNORE);
        if (!reached) usleep(1000);
      }
      everyone = reached != 0;
    }
    if (root || !everyone) std::fprintf(stderr, "error: %s\n", line.c_str());
    std::fflush(stderr);
    if (!scratch.empty()) {
      std::error_code ec;
      fs::remove_all(scratch, ec);
    }
    if (everyone) {
      MPI_Finalize();
      std::exit(2);
    }
    MPI_Abort(MPI_COMM_WORLD, 2);
  };
  // Checks every process makes alike, agreed on before the run starts.
  std::string error;
  try {
    if (provided < MPI_THREAD_SERIALIZED)
      throw InputError(a.scene, "this MPI does not allow calls from OpenMP threads",
                       "MPI_THREAD_SERIALIZED");
    (void)solver::load_scene(a.scene);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (domain.any(!error.empty()))
    fail(error.empty() ? a.scene + ": failed on another process" : error, true);
  Args mine = a;
  if (!root) {
    // The other processes run the same loop, writing to a scratch directory (resuming from a
    // copy of process 0's). Their warnings on std::cerr (a programme's, from the curve rows they
    // compute on their own part) are process 0's to give: not printed (errors go through fail).
    std::cerr.rdbuf(nullptr);
    const fs::path out =
        a.out.empty() ? fs::path("out") / solver::load_scene(a.scene).name : fs::path(a.out);
    scratch = fs::temp_directory_path() /
              ("granoscope-rank" + std::to_string(domain.rank()) + "-" + std::to_string(getpid()));
    std::error_code ec;
    fs::remove_all(scratch, ec);
    if (a.resume && fs::exists(out))
      fs::copy(out, scratch, fs::copy_options::recursive, ec);
    else
      fs::create_directories(scratch, ec);
    mine.out = scratch.string();
  }
  // (process 0 cuts its outputs back to the checkpoint when it resumes: not before the others
  // have copied them)
  MPI_Barrier(MPI_COMM_WORLD);
  solver::RunOptions::Parallel par;
  par.root = root;
  par.attach = [&](solver::Simulation& sim) {
    try {
      domain.attach(sim);
    } catch (const std::invalid_argument& e) {
      throw InputError(a.scene, "mpirun", e.what());
    }
  };
  par.gather = [&](solver::Simulation& sim) { domain.gather(sim); };
  par.release = [&](solver::Simulation& sim) { domain.release(sim); };
  par.any = [&](bool mine_flag) { return domain.any(mine_flag); };
  try {
    if (solver::scene_has_sweep(a.scene))
      run_sweep(mine, solver::load_scene(a.scene), par);
    else
      run(mine, -1, par);
  } catch (const InputError& e) {
    fail(e.what(), true);  // (the scene's, or a blow-up: every process stops at the same step)
  } catch (const std::exception& e) {
    fail(e.what(), false);
  }
  // What the processes sent each other, summed over them (docs/scale.md).
  double sent[2] = {static_cast<double>(domain.halo_bytes()),
                    static_cast<double>(domain.rebuild_bytes())},
         total[2] = {};
  MPI_Reduce(sent, total, 2, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  if (root) {
    std::printf(
        "mpirun: %d processes, bricks %d x %d x %d%s; neighbour-list rebuilds %lld; sent by all "
        "processes: %.4g MB in halo exchanges (each step), %.4g MB at rebuilds\n",
        domain.size(), domain.grid()[0], domain.grid()[1], domain.grid()[2],
        domain.periodic() ? " (along the cell's base vectors)" : "",
        static_cast<long long>(domain.rebuilds()), total[0] / 1e6, total[1] / 1e6);
  }
  if (!scratch.empty()) {
    std::error_code ec;
    fs::remove_all(scratch, ec);
  }
  MPI_Finalize();
}
#endif

void run_scene(const Args& a) {
  if (launched_processes() > 1) {
#ifdef GRANOSCOPE_MPI
    return run_mpi(a);
#else
    throw InputError(
        a.scene, "this granoscope was built without MPI (apt-get install libopenmpi-dev, rebuild)",
        "mpirun");
#endif
  }
  if (solver::scene_has_sweep(a.scene)) return run_sweep(a, solver::load_scene(a.scene));
  run(a);
}

}  // namespace

void register_simulate(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Run a DEM scene (TOML, docs/scenes.md)");
  auto a = std::make_shared<Args>();
  cmd->add_option("SCENE", a->scene, "scene file (.toml)")->required();
  cmd->add_option("-o,--out", a->out, "output directory (default out/<scene name>)");
  cmd->add_option("--steps", a->steps,
                  "stop at this step (a plain scene: its number of steps; a laboratory test "
                  "ends earlier if its programme ends first)")
      ->check(CLI::Range(std::int64_t{0}, std::numeric_limits<std::int64_t>::max()));
  cmd->add_option("--threads", a->threads,
                  "override the thread count (1 to " + std::to_string(solver::kMaxThreads) + ")")
      ->check(CLI::Range(1, solver::kMaxThreads));
  cmd->add_flag("--resume", a->resume, "continue from the last checkpoint in the output directory");
  cmd->add_flag("-q,--quiet", a->quiet, "no progress line");
  cmd->callback([a] { run_scene(*a); });
}

}  // namespace gs::cli
