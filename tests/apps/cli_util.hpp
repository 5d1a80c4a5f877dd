// Helpers for end-to-end tests of the `granoscope` executable.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../io/test_util.hpp"
#include "hdf5_trajectory.hpp"

namespace gs::test {

inline const std::string kGranoscope = std::string(GS_BINARY_DIR) + "/bin/granoscope";

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct CliResult {
  int rc = -1;
  std::string out, err;
};

/// Runs `granoscope ARGS` with stdin from /dev/null; stdout and stderr go through files in
/// `scratch` (removed afterwards).
inline CliResult run_cli(const std::string& args, const std::filesystem::path& scratch) {
  const auto o = scratch / "stdout.txt", e = scratch / "stderr.txt";
  const std::string cmd =
      kGranoscope + " " + args + " >" + o.string() + " 2>" + e.string() + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  r.out = slurp(o);
  r.err = slurp(e);
  std::filesystem::remove(o);
  std::filesystem::remove(e);
  return r;
}

/// One line "error: FILE: ...", exit code 2.
inline void expect_rejected(const CliResult& r, const std::string& file) {
  EXPECT_EQ(r.rc, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: " + file + ": ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

/// Starts the program `argv` (stdout and stderr to /dev/null) in a process group of its own,
/// and sends the group `sig` once a checkpoint at or past `step` is in `out`; false if the
/// program ended first (exit code 0).
inline bool stop_at_checkpoint(const std::vector<std::string>& argv,
                               const std::filesystem::path& out, long step, int sig) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    setpgid(0, 0);
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execvp(args[0], args.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    const std::string idx = slurp(out / "checkpoint.txt");
    const auto k = idx.find("\nstep ");
    if (k != std::string::npos && std::stol(idx.substr(k + 6)) >= step) break;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  kill(-pid, sig);
  // (a launcher such as mpirun that does not end within a minute of the signal is killed, so
  // that a test fails rather than hangs)
  int status = 0;
  const auto grace = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > grace) {
      kill(-pid, SIGKILL);
      waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

/// Starts `granoscope simulate SCENE -q -o OUT` and kills it (SIGKILL) once a checkpoint past
/// `step` is on disk; false if the run ended first.
inline bool run_and_kill(const std::string& scene, const std::filesystem::path& out, long step) {
  return stop_at_checkpoint({kGranoscope, "simulate", scene, "-q", "-o", out.string()}, out, step,
                            SIGKILL);
}

/// A CSV file of numbers as its header and rows.
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  double num(std::size_t r, const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return rows.at(r).at(i);
    ADD_FAILURE() << "no column " << name;
    return std::nan("");
  }
};

inline CsvTable read_csv_table(const std::filesystem::path& p) {
  std::istringstream in(slurp(p));
  CsvTable t;
  std::string line, cell;
  std::getline(in, line);
  std::istringstream h(line);
  while (std::getline(h, cell, ',')) t.header.push_back(cell);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream v(line);
    auto& row = t.rows.emplace_back();
    while (std::getline(v, cell, ',')) row.push_back(std::strtod(cell.c_str(), nullptr));
  }
  return t;
}

/// `s` with the first `from` replaced by `to` (a test failure when there is none).
inline std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at == std::string::npos)
    ADD_FAILURE() << "no " << from;
  else
    s.replace(at, from.size(), to);
  return s;
}

/// Each scene text of `cases` run by `simulate` in `dir` fails with exit code 2 and one line on
/// stderr containing the case's message.
inline void expect_bad_scenes(const std::filesystem::path& dir,
                              const std::vector<std::pair<std::string, std::string>>& cases) {
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto p = dir / ("bad" + std::to_string(i) + ".toml");
    std::ofstream(p) << cases[i].first;
    const auto r = run_cli("simulate " + p.string() + " -q -o " + (dir / "out").string(), dir);
    EXPECT_EQ(r.rc, 2) << i;
    EXPECT_NE(r.err.find(cases[i].second), std::string::npos) << i << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << i << ": " << r.err;
  }
}

/// `scene` run straight into dir/straight, and for each step of `kill_after` killed there and
/// resumed into dir/killed<step>: the output files `files` and every frame of the trajectory
/// `trajectory` are the same as the straight run's.
inline void expect_resume_bit_for_bit(const std::filesystem::path& dir, const std::string& scene,
                                      const std::vector<long>& kill_after,
                                      const std::vector<std::string>& files,
                                      const std::string& trajectory) {
  ASSERT_EQ(run_cli("simulate " + scene + " -q -o " + (dir / "straight").string(), dir).rc, 0);
  const auto a = read_hdf5_trajectory(dir / "straight" / trajectory);
  for (const long k : kill_after) {
    const auto killed = dir / ("killed" + std::to_string(k));
    ASSERT_TRUE(run_and_kill(scene, killed, k)) << "the run finished before step " << k;
    const auto r = run_cli("simulate " + scene + " -q --resume -o " + killed.string(), dir);
    ASSERT_EQ(r.rc, 0) << r.err;
    for (const auto& f : files)
      EXPECT_EQ(slurp(dir / "straight" / f), slurp(killed / f)) << f << " after " << k;
    const auto b = read_hdf5_trajectory(killed / trajectory);
    ASSERT_EQ(a.frames.size(), b.frames.size());
    for (std::size_t i = 0; i < a.frames.size(); ++i) expect_same_frame(a.frames[i], b.frames[i]);
  }
}

}  // namespace gs::test
