// Helpers for end-to-end tests of the `granoscope` executable.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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

}  // namespace gs::test
