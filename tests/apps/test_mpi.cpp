// `mpirun -np 2 granoscope simulate` (issue 23, docs/scale.md): two processes on localhost step
// the same scene as one process, bit for bit; a checkpoint written by either resumes on the
// other number of processes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../io/test_util.hpp"
#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"

namespace {

using gs::test::slurp;
namespace fs = std::filesystem;

const fs::path kData = GS_TEST_DATA_DIR;
const fs::path kScenes = fs::path(GS_SOURCE_DIR) / "data" / "scenes";
const std::string kExe = std::string(GS_BINARY_DIR) + "/bin/granoscope";
// Root is allowed (CI runs as root); more processes than cores are allowed; shared-memory
// transport without the kernel's cross-memory attach, which containers often forbid.
const std::string kMpirun =
    "mpirun --allow-run-as-root --oversubscribe --mca btl_vader_single_copy_mechanism none -np ";

std::vector<std::string> words(const std::string& cmd) {
  std::vector<std::string> out;
  std::istringstream in(cmd);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

/// Runs a command line (no shell quoting needed here); its exit code, stderr in `err`.
int run(const std::string& cmd, std::string* err = nullptr) {
  const auto e = fs::temp_directory_path() / ("gs_mpi_err_" + std::to_string(::getpid()));
  const int status = std::system((cmd + " >/dev/null 2>" + e.string() + " </dev/null").c_str());
  if (err) *err = slurp(e);
  fs::remove(e);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

/// Particles and contacts the same to the bit; walls' loads (sums over processes in another
/// order) to round-off.
void expect_same_run(const fs::path& a_file, const fs::path& b_file) {
  const auto a = gs::read_hdf5_trajectory(a_file);
  const auto b = gs::read_hdf5_trajectory(b_file);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  std::size_t contacts = 0;
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    gs::test::expect_same_frame(a.frames[i], b.frames[i], false);
    contacts += a.frames[i].contacts.size();
    ASSERT_EQ(a.frames[i].walls.size(), b.frames[i].walls.size());
    for (std::size_t w = 0; w < a.frames[i].walls.size(); ++w) {
      const auto &p = a.frames[i].walls[w], &q = b.frames[i].walls[w];
      EXPECT_EQ(p.a, q.a);
      EXPECT_EQ(p.b, q.b);
      EXPECT_LE((p.force - q.force).norm(), 1e-12 * (1 + p.force.norm())) << "wall " << w;
    }
  }
  EXPECT_GT(contacts, 100u);
}

bool mpirun_present() {
  return run("mpirun --version") == 0;
}

}  // namespace

/// `SCENE` (with `extra` options) on one process and on two: the same runs.
void one_against_two(const std::string& scene, const std::string& extra, const std::string& h5) {
  gs::test::ScratchDir dir("mpi_one_two");
  const std::string args = " simulate " + scene + " -q --threads 1 " + extra + " -o ";
  ASSERT_EQ(run(kExe + args + (dir / "one").string()), 0);
  std::string err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + args + (dir / "two").string(), &err), 0) << err;
  expect_same_run(dir / "one" / h5, dir / "two" / h5);
}

// The shared YADE oedometer (883 spheres, five box walls, the top one moving): 2 000 steps on one
// process and on two (slabs along z).
TEST(Mpi, TwoProcessesStepTheOedometerAsOneBitForBit) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  one_against_two((kScenes / "oedometer_yade.toml").string(), "--steps 2000", "oedometer_yade.h5");
}

// The same packing dropped onto its floor under a strong, slanted gravity: 6 000 steps with ~90
// neighbour-list rebuilds, particles and their contacts moving between the processes.
TEST(Mpi, TwoProcessesStepAFallingPackingAsOneBitForBit) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  one_against_two((kData / "scenes" / "oedometer_fall.toml").string(), "", "oedometer_fall.h5");
}

// A checkpoint is one process's format whatever wrote it: a two-process run stopped after a
// checkpoint resumes on one process, and a one-process run's on two, to the uninterrupted run.
TEST(Mpi, CheckpointsResumeOnAnyNumberOfProcesses) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_resume");
  const std::string scene = (kData / "scenes" / "oedometer_fall.toml").string();
  const std::string args = " simulate " + scene + " -q --threads 1 -o ";
  ASSERT_EQ(run(kExe + args + (dir / "straight").string()), 0);
  const fs::path two_then_one = dir / "two_then_one", one_then_two = dir / "one_then_two";
  // (SIGTERM: mpirun passes it on to its processes)
  ASSERT_TRUE(gs::test::stop_at_checkpoint(
      words(kMpirun + "2 " + kExe + args + two_then_one.string()), two_then_one, 3000, SIGTERM))
      << "the run ended before it could be stopped";
  ASSERT_TRUE(gs::test::stop_at_checkpoint(words(kExe + args + one_then_two.string()), one_then_two,
                                           3000, SIGTERM));
  std::string err;
  ASSERT_EQ(run(kExe + args + two_then_one.string() + " --resume", &err), 0) << err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + args + one_then_two.string() + " --resume", &err), 0)
      << err;
  expect_same_run(dir / "straight" / "oedometer_fall.h5", two_then_one / "oedometer_fall.h5");
  expect_same_run(dir / "straight" / "oedometer_fall.h5", one_then_two / "oedometer_fall.h5");
}

// What the decomposition does not handle yet, and a scene error, are one line from process 0
// and exit code 2.
TEST(Mpi, UnsupportedScenesAndBadScenesGiveOneLineAndExit2) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_bad");
  std::string err;
  const std::string tri = (kScenes / "triaxial.toml").string();
  EXPECT_EQ(
      run(kMpirun + "2 " + kExe + " simulate " + tri + " -q -o " + (dir / "t").string(), &err), 2);
  EXPECT_EQ(err.substr(0, err.find('\n') + 1),
            "error: " + tri +
                ": under mpirun only plain scenes run yet (no scene.test, no [fill]) (triaxial)\n");
  const fs::path bad = dir / "bad.toml";
  {
    std::ofstream o(bad);
    o << slurp(kScenes / "oedometer_yade.toml") << "\n[solver.nonsense]\n";
  }
  EXPECT_EQ(
      run(kMpirun + "2 " + kExe + " simulate " + bad.string() + " -q -o " + (dir / "b").string(),
          &err),
      2);
  // (one line from us; mpirun may add its own report of the exit code after it)
  EXPECT_EQ(err.rfind("error: " + bad.string() + ": ", 0), 0u) << err;
}
