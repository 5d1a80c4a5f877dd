// `granoscope simulate`: outputs, bit-for-bit resume after a kill, bad scenes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "../io/test_util.hpp"
#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"

namespace {

using gs::test::slurp;

const std::filesystem::path kData = GS_TEST_DATA_DIR;
const std::string kExe = std::string(GS_BINARY_DIR) + "/bin/granoscope";

int run(const std::string& args, std::string* err = nullptr) {
  const auto e =
      std::filesystem::temp_directory_path() / ("gs_sim_err_" + std::to_string(::getpid()));
  const int status =
      std::system((kExe + " " + args + " >/dev/null 2>" + e.string() + " </dev/null").c_str());
  if (err) *err = slurp(e);
  std::filesystem::remove(e);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

}  // namespace

TEST(Simulate, ResumeAfterKillIsBitForBitIdentical) {
  gs::test::ScratchDir dir("simulate");
  const std::string scene = (kData / "scenes" / "drop.toml").string();
  ASSERT_EQ(run("simulate " + scene + " -q -o " + (dir / "straight").string()), 0);

  const auto killed = dir / "killed";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    dup2(devnull, 2);
    execl(kExe.c_str(), kExe.c_str(), "simulate", scene.c_str(), "-q", "-o", killed.c_str(),
          nullptr);
    _exit(127);
  }
  // Kill once a checkpoint past step 2000 is on disk, mid-run.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const std::string idx = slurp(killed / "checkpoint.txt");
    const auto k = idx.find("\nstep ");
    if (k != std::string::npos && std::stol(idx.substr(k + 6)) >= 2000) break;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before it could be killed";
  EXPECT_FALSE(std::filesystem::exists(killed / "drop.h5"));
  EXPECT_TRUE(std::filesystem::exists(killed / "drop.h5.partial"));
  // The partial trajectory is readable.
  EXPECT_GE(gs::TrajectoryReader(killed / "drop.h5.partial").frame_count(), 5u);

  ASSERT_EQ(run("simulate " + scene + " -q --resume -o " + killed.string()), 0);
  EXPECT_EQ(slurp(dir / "straight" / "history.csv"), slurp(killed / "history.csv"));
  const auto a = gs::read_hdf5_trajectory(dir / "straight" / "drop.h5");
  const auto b = gs::read_hdf5_trajectory(killed / "drop.h5");
  ASSERT_EQ(a.frames.size(), 17u);  // steps 0, 500, ..., 8000
  ASSERT_EQ(a.frames.size(), b.frames.size());
  std::size_t contacts = 0;
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    gs::test::expect_same_frame(a.frames[i], b.frames[i]);
    contacts += a.frames[i].contacts.size();
  }
  EXPECT_GT(contacts, 10u);  // contacts (with histories) are part of the comparison
  EXPECT_FALSE(std::filesystem::exists(killed / "checkpoint.txt"));  // cleaned up at the end
}

TEST(Simulate, BadScenesGiveOneLineAndExit2) {
  gs::test::ScratchDir dir("simulate_bad");
  const std::string good = slurp(kData / "scenes" / "drop.toml");
  std::filesystem::copy_file(kData / "scenes" / "drop_packing.csv", dir / "drop_packing.csv");
  auto variant = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string s = good;
    const auto k = s.find(from);
    EXPECT_NE(k, std::string::npos) << from;
    s.replace(k, from.size(), to);
    std::ofstream(dir / name) << s;
    return (dir / name).string();
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {(dir / "missing.toml").string(), "no such scene file"},
      {variant("young.toml", "young_Pa = 5.0e7", "young_Pa = -5.0e7"),
       "material.young_Pa: must be positive (-50000000)"},
      {variant("syntax.toml", "[solver]", "[solver"), "TOML syntax error"},
      {variant("shape.toml", "shape = \"plane\"", "shape = \"sphere\""),
       "walls[0].shape: expected \"box\" or \"plane\" (sphere)"},
      {variant("nopack.toml", "drop_packing.csv", "nope.csv"), "no such file"},
      {variant("damp.toml", "damping = 0.1", "damping = 1.5"),
       "solver.damping: outside [0, 1) (1.5)"},
      {variant("vec.toml", "normal = [0.0, 0.0, 1.0]", "normal = [0.0, 1.0]"),
       "walls[0].normal: expected an array of 3 numbers"},
  };
  for (const auto& [file, what] : cases) {
    std::string err;
    EXPECT_EQ(run("simulate " + file + " -q -o " + (dir / "out").string(), &err), 2) << file;
    EXPECT_EQ(err.rfind("error: ", 0), 0u) << err;
    EXPECT_NE(err.find(what), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
  // Resume without a checkpoint.
  std::string err;
  EXPECT_EQ(run("simulate " + (kData / "scenes" / "drop.toml").string() + " -q --resume -o " +
                    (dir / "empty").string(),
                &err),
            2);
  EXPECT_NE(err.find("no checkpoint to resume from"), std::string::npos) << err;
}
