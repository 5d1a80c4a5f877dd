#include "python_runner.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>

extern char** environ;

namespace gs::cli {

int run_process(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

namespace {
bool has_packages(const std::string& py) {
  // Quiet probe: redirect the child's output through a shell-free dup is overkill here; the
  // probe prints nothing on success and its ImportError goes to /dev/null.
  const std::string cmd = "'" + py + "' -c 'import matplotlib, numpy, h5py' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}
}  // namespace

std::string find_python() {
  // An interpreter named by the user is used or refused, never passed over in silence.
  if (const char* env = std::getenv("GRANOSCOPE_PYTHON"); env && *env) {
    const std::string py = env;
    if (py.find('\'') == std::string::npos && has_packages(py)) return py;
    std::error_code ec;
    const bool named_file = py.find('/') != std::string::npos;
    throw std::runtime_error(
        "GRANOSCOPE_PYTHON: " +
        std::string(named_file && !std::filesystem::exists(py, ec)
                        ? "no such interpreter"
                        : "not a Python 3 that imports matplotlib, numpy and h5py") +
        " (" + py + ")");
  }
  std::vector<std::string> candidates;
  candidates.emplace_back("/usr/bin/python3");
  candidates.emplace_back("python3");
  std::string tried;
  for (const auto& c : candidates) {
    if (c.find('\'') != std::string::npos) continue;
    if (has_packages(c)) return c;
    tried += (tried.empty() ? "" : ", ") + c;
  }
  throw std::runtime_error("no Python 3 with matplotlib, numpy and h5py (tried " + tried +
                           "; run scripts/setup or set GRANOSCOPE_PYTHON)");
}

std::filesystem::path figures_dir() {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const char* env = std::getenv("GRANOSCOPE_FIGURES_DIR"); env && *env) return env;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path() / ".." / "share" / "granoscope" / "figures";
    if (fs::exists(installed / "granoscope_figures.py", ec)) return installed;
  }
  return GRANOSCOPE_FIGURES_DIR;
}

}  // namespace gs::cli
