#include "frame_series.hpp"

#include <fcntl.h>
#include <omp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "errors.hpp"
#include "field_series.hpp"
#include "frame_motion.hpp"

#ifdef GRANOSCOPE_MPI
#include <mpi.h>
#endif

namespace gs::cli {

namespace fs = std::filesystem;

void FrameSeriesArgs::add_to(CLI::App& cmd) {
  auto* o = cmd.add_option("--frames", frames,
                           "a range of frames A:B or A:B:S (a Python slice: B excluded, "
                           "negatives from the end): one output with a frame axis");
  // (one frame's options; and the other outputs, which a series does not merge)
  for (const char* other : {"--frame", "--to", "--csv", "--vti", "--vtp"})
    if (auto* p = cmd.get_option_no_throw(other)) o->excludes(p);
  cmd.add_option("--jobs", jobs, "frames analysed at once with --frames (default: the cores)");
}

std::vector<long> frame_range(const std::string& input, const std::string& spec, long count) {
  std::vector<std::string> f;
  std::stringstream ss(spec);
  for (std::string x; std::getline(ss, x, ':');) f.push_back(x);
  if (!spec.empty() && spec.back() == ':') f.emplace_back();
  if (f.size() < 2 || f.size() > 3)
    throw InputError(input, "--frames: expected A:B or A:B:S", spec);
  auto number = [&](const std::string& s, long fallback) {
    if (s.empty()) return fallback;
    std::size_t used = 0;
    long v = 0;
    try {
      v = std::stol(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size()) throw InputError(input, "--frames: not an integer", s);
    return v;
  };
  long a = number(f[0], 0), b = number(f[1], count);
  const long step = f.size() == 3 ? number(f[2], 1) : 1;
  if (step < 1) throw InputError(input, "--frames: the step must be at least 1", spec);
  if (a < 0) a += count;
  if (b < 0) b += count;
  a = std::clamp(a, 0L, count);
  b = std::clamp(b, 0L, count);
  std::vector<long> out;
  for (long k = a; k < b; k += step) out.push_back(k);
  if (out.empty())
    throw InputError(
        input, "--frames: no frame in the range (the trajectory has " + std::to_string(count) + ")",
        spec);
  return out;
}

namespace {

std::string slurp_line(const fs::path& p) {
  std::ifstream in(p);
  std::string s;
  std::getline(in, s);
  return s;
}

/// The progress line on a terminal: frames done, frames/s, ETA.
void progress(const std::string& command, std::size_t done, std::size_t total,
              std::chrono::steady_clock::time_point t0) {
  if (!isatty(STDERR_FILENO)) return;
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = el > 0 ? static_cast<double>(done) / el : 0;
  std::fprintf(stderr, "\r%s: frame %zu/%zu  %.3g frames/s  ETA %.0f s   ", command.c_str(), done,
               total, rate, rate > 0 ? static_cast<double>(total - done) / rate : 0.0);
  if (done == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

/// Frame k (a position in `frames`) in this process, its report to /dev/null: part k to
/// parts/k.h5, its error (if any) to parts/k.err; false on an error.
bool run_here(const std::vector<long>& frames, std::size_t k, const fs::path& parts,
              const std::function<void(long, const std::string&)>& one) {
  std::cout.flush();
  std::fflush(stdout);
  const int saved = dup(STDOUT_FILENO);
  const int null = ::open("/dev/null", O_WRONLY);
  if (null >= 0) dup2(null, STDOUT_FILENO);
  bool ok = true;
  try {
    one(frames[k], (parts / (std::to_string(k) + ".h5")).string());
  } catch (const std::exception& e) {
    std::ofstream(parts / (std::to_string(k) + ".err")) << e.what() << "\n";
    ok = false;
  }
  std::cout.flush();
  std::fflush(stdout);
  if (saved >= 0) {
    dup2(saved, STDOUT_FILENO);
    ::close(saved);
  }
  if (null >= 0) ::close(null);
  return ok;
}

[[noreturn]] void fail_with(const std::vector<long>& frames, std::size_t k, const fs::path& parts) {
  const std::string why = slurp_line(parts / (std::to_string(k) + ".err"));
  throw std::runtime_error(why.empty() ? "--frames: the analysis of frame " +
                                             std::to_string(frames[k]) + " failed"
                                       : why);
}

/// Frames `mine` (positions in `frames`): in this process one after the other when `jobs` is
/// 0, else in worker processes, `jobs` at a time. Part k to parts/k.h5; on a failure the frames
/// not started are not run, and the first failing frame's error is thrown.
void run_workers(const std::string& command, const std::vector<long>& frames,
                 const std::vector<std::size_t>& mine, int jobs, const fs::path& parts,
                 const std::function<void(long, const std::string&)>& one, bool show) {
  const auto t0 = std::chrono::steady_clock::now();
  if (jobs == 0) {
    for (std::size_t i = 0; i < mine.size(); ++i) {
      if (!run_here(frames, mine[i], parts, one)) fail_with(frames, mine[i], parts);
      if (show) progress(command, i + 1, mine.size(), t0);
    }
    return;
  }
  std::vector<std::pair<pid_t, std::size_t>> running;
  std::size_t next = 0, done = 0;
  std::optional<std::size_t> failed;
  std::cout.flush();
  std::fflush(nullptr);
  while (done < mine.size()) {
    while (!failed && next < mine.size() && static_cast<int>(running.size()) < jobs) {
      const std::size_t k = mine[next++];
      const pid_t pid = fork();
      if (pid < 0) throw std::runtime_error("--frames: cannot start a worker process");
      if (pid == 0) {
        // The worker: one frame, one thread.
        omp_set_num_threads(1);
        const bool ok = run_here(frames, k, parts, one);
        std::fflush(nullptr);
        _exit(ok ? 0 : 2);
      }
      running.emplace_back(pid, k);
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) break;
    const auto it =
        std::find_if(running.begin(), running.end(), [&](const auto& r) { return r.first == pid; });
    if (it == running.end()) continue;
    const std::size_t k = it->second;
    running.erase(it);
    ++done;
    if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) && (!failed || k < *failed)) failed = k;
    if (failed) {  // stop: the frames not started are not run
      done += mine.size() - next;
      next = mine.size();
    }
    if (show) progress(command, done, mine.size(), t0);
  }
  if (failed) fail_with(frames, *failed, parts);
}

}  // namespace

void run_frame_series(const std::string& command, const std::string& input,
                      const FrameSeriesArgs& series, const std::string& output,
                      const std::function<void(long, const std::string&)>& one) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto count = static_cast<long>(frame_count(input));
  const std::vector<long> frames = frame_range(input, series.frames, count);
  if (series.jobs < 0)
    throw InputError(input, "--jobs: must be at least 1", std::to_string(series.jobs));
  const int jobs = series.jobs > 0
                       ? series.jobs
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  int rank = 0, size = 1;
  const bool mpi = launched_processes() > 1;
#ifdef GRANOSCOPE_MPI
  if (mpi) {
    MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
  }
#else
  if (mpi)
    throw InputError(input, "this build has no MPI (apt-get install libopenmpi-dev)", "mpirun");
#endif
  // The parts beside the output (under mpirun the processes must share that folder), named by
  // process 0's id.
  long id = static_cast<long>(getpid());
#ifdef GRANOSCOPE_MPI
  if (mpi) MPI_Bcast(&id, 1, MPI_LONG, 0, MPI_COMM_WORLD);
#endif
  const fs::path target(output);
  const fs::path parts =
      target.parent_path() / ("." + target.filename().string() + ".frames-" + std::to_string(id));
  std::string error;
  try {
    if (rank == 0) fs::create_directories(parts);
#ifdef GRANOSCOPE_MPI
    if (mpi) MPI_Barrier(MPI_COMM_WORLD);
#endif
    std::vector<std::size_t> mine;
    for (std::size_t k = 0; k < frames.size(); ++k)
      if (static_cast<int>(k % static_cast<std::size_t>(size)) == rank) mine.push_back(k);
    // (under mpirun each process its frames, itself, or with --jobs workers if given)
    run_workers(command, frames, mine, mpi && series.jobs == 0 ? 0 : jobs, parts, one, rank == 0);
  } catch (const std::exception& e) {
    error = e.what();
  }
  int failed = error.empty() ? 0 : 1;
#ifdef GRANOSCOPE_MPI
  if (mpi) {
    int any = 0;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    // (the lowest process that failed reports: one line)
    int first = failed ? rank : size;
    int lowest = size;
    MPI_Allreduce(&first, &lowest, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (any && rank != lowest) error.clear();
    failed = any;
  }
#endif
  if (!failed && rank == 0) {
    try {
      std::vector<fs::path> files;
      for (std::size_t k = 0; k < frames.size(); ++k)
        files.push_back(parts / (std::to_string(k) + ".h5"));
      merge_field_series(files, frames, target);
    } catch (const std::exception& e) {
      error = e.what();
      failed = 1;
    }
  }
  if (rank == 0) {
    std::error_code ec;
    fs::remove_all(parts, ec);
  }
#ifdef GRANOSCOPE_MPI
  if (mpi) {
    MPI_Bcast(&failed, 1, MPI_INT, 0, MPI_COMM_WORLD);
    MPI_Finalize();
  }
#endif
  if (failed) {
    if (error.empty()) throw ExitStatus{2};  // (another process reported it)
    throw std::runtime_error(error);
  }
  if (rank != 0) return;
  const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << command << ": " << frames.size() << " frames (" << frames.front() << " to "
            << frames.back() << ") in " << el << " s, "
            << (mpi ? std::to_string(size) + " processes" : std::to_string(jobs) + " workers")
            << "; wrote " << output << "\n";
}

}  // namespace gs::cli
