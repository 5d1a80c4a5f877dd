// `mpirun -np 2 granoscope simulate` (issue 23, docs/scale.md): two processes on localhost step
// the same scene as one process, bit for bit; a checkpoint written by either resumes on the
// other number of processes.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <hdf5.h>

#include "../io/test_util.hpp"
#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "mpi_domain.hpp"

namespace {

using gs::test::slurp;
namespace fs = std::filesystem;

const fs::path kData = GS_TEST_DATA_DIR;
const fs::path kScenes = fs::path(GS_SOURCE_DIR) / "data" / "scenes";
const std::string kExe = std::string(GS_BINARY_DIR) + "/bin/granoscope";
// Root is allowed (CI runs as root); more processes than cores are allowed; shared-memory
// transport without the kernel's cross-memory attach, which containers often forbid.
// A run that hangs fails after 5 minutes instead (timeout's SIGTERM, which mpirun passes on).
const std::string kMpirun =
    "timeout 300 mpirun --allow-run-as-root --oversubscribe --mca btl_vader_single_copy_mechanism "
    "none -np ";

std::vector<std::string> words(const std::string& cmd) {
  std::vector<std::string> out;
  std::istringstream in(cmd);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

/// Runs a command line (no shell quoting needed here); its exit code, stderr in `err`, stdout
/// in `out`.
int run(const std::string& cmd, std::string* err = nullptr, std::string* out = nullptr) {
  const auto e = fs::temp_directory_path() / ("gs_mpi_err_" + std::to_string(::getpid()));
  const auto o = fs::temp_directory_path() / ("gs_mpi_out_" + std::to_string(::getpid()));
  const int status = std::system(
      (cmd + " >" + (out ? o.string() : "/dev/null") + " 2>" + e.string() + " </dev/null").c_str());
  if (err) *err = slurp(e);
  if (out) *out = slurp(o);
  fs::remove(e);
  fs::remove(o);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

/// Particles, contacts and clumps the same to the bit; the walls' loads too where `exact_walls`
/// (a laboratory test's, summed over every process's wall contacts in pair order as one process
/// sums them), to round-off otherwise (summed per process, then over processes).
void expect_same_run(const fs::path& a_file, const fs::path& b_file, bool exact_walls = false) {
  const auto a = gs::read_hdf5_trajectory(a_file);
  const auto b = gs::read_hdf5_trajectory(b_file);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  std::size_t contacts = 0;
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    gs::test::expect_same_frame(a.frames[i], b.frames[i], false);
    contacts += a.frames[i].contacts.size();
    const auto &ca = a.frames[i].clumps, &cb = b.frames[i].clumps;
    ASSERT_EQ(ca.size(), cb.size());
    for (std::size_t k = 0; k < ca.size(); ++k) {  // the clump bodies, to the bit
      EXPECT_EQ(ca[k].id, cb[k].id);
      EXPECT_EQ(ca[k].position, cb[k].position) << "clump " << k;
      EXPECT_EQ(ca[k].orientation.coeffs(), cb[k].orientation.coeffs()) << "clump " << k;
      EXPECT_EQ(ca[k].velocity, cb[k].velocity) << "clump " << k;
      EXPECT_EQ(ca[k].angular_velocity, cb[k].angular_velocity) << "clump " << k;
    }
    ASSERT_EQ(a.frames[i].walls.size(), b.frames[i].walls.size());
    for (std::size_t w = 0; w < a.frames[i].walls.size(); ++w) {
      const auto &p = a.frames[i].walls[w], &q = b.frames[i].walls[w];
      EXPECT_EQ(p.a, q.a);
      EXPECT_EQ(p.b, q.b);
      if (exact_walls) {
        EXPECT_EQ(p.force, q.force) << "wall " << w;
        EXPECT_EQ(p.torque, q.torque) << "wall " << w;
      } else {
        EXPECT_LE((p.force - q.force).norm(), 1e-12 * (1 + p.force.norm())) << "wall " << w;
      }
    }
  }
  EXPECT_GT(contacts, 100u);
}

/// A dataset of an HDF5 file as doubles (empty when missing).
std::vector<double> read_dataset(const fs::path& file, const char* name) {
  std::vector<double> v;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return v;
  const hid_t d = H5Dopen2(f, name, H5P_DEFAULT);
  if (d >= 0) {
    const hid_t s = H5Dget_space(d);
    v.resize(static_cast<std::size_t>(H5Sget_simple_extent_npoints(s)));
    H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Sclose(s);
    H5Dclose(d);
  }
  H5Fclose(f);
  return v;
}

bool mpirun_present() {
  return run("mpirun --version") == 0;
}

}  // namespace

/// `SCENE` (with `extra` options) on one process and on `processes`: the same runs. The
/// summary line of the processes' run in `summary`.
void one_against_two(const std::string& scene, const std::string& extra, const std::string& h5,
                     const std::string& processes = "2", std::string* summary = nullptr) {
  gs::test::ScratchDir dir("mpi_one_two");
  const std::string args = " simulate " + scene + " -q --threads 1 " + extra + " -o ";
  ASSERT_EQ(run(kExe + args + (dir / "one").string()), 0);
  std::string err;
  ASSERT_EQ(run(kMpirun + processes + " " + kExe + args + (dir / "two").string(), &err, summary), 0)
      << err;
  expect_same_run(dir / "one" / h5, dir / "two" / h5);
}

// The bricks' grid: the least cut area Σ (g_k − 1)·A_k, only along sides that may be cut, ties
// to more bricks on the earlier sides (hand-counted areas).
TEST(Mpi, BricksCutTheLeastArea) {
  using gs::solver::brick_grid;
  using G = std::array<int, 3>;
  const Eigen::Vector3d cube(1, 1, 1), column(1, 1, 10), slab(10, 10, 1);
  const std::array<bool, 3> all{true, true, true}, planar{true, true, false};
  EXPECT_EQ(brick_grid(1, cube, all), (G{1, 1, 1}));
  EXPECT_EQ(brick_grid(2, cube, all), (G{2, 1, 1}));     // a tie of three: x
  EXPECT_EQ(brick_grid(3, column, all), (G{1, 1, 3}));   // a prime: slabs across the long side
  EXPECT_EQ(brick_grid(4, cube, all), (G{2, 2, 1}));     // area 2 against 3 for slabs
  EXPECT_EQ(brick_grid(8, cube, all), (G{2, 2, 2}));     // 3 against 4 (2 x 4 x 1)
  EXPECT_EQ(brick_grid(4, column, all), (G{1, 1, 4}));   // 3 against 11 for 2 x 1 x 2
  EXPECT_EQ(brick_grid(16, slab, all), (G{4, 4, 1}));    // never across the thin side here
  EXPECT_EQ(brick_grid(8, cube, planar), (G{4, 2, 1}));  // z not cut: 4 x 2 (area 4), x first
  EXPECT_EQ(brick_grid(6, Eigen::Vector3d(3, 2, 1), all), (G{3, 2, 1}));
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

// Four processes in bricks (two along x, two along z: particles and contacts change bricks
// across two sides) step the falling packing as one.
TEST(Mpi, FourProcessesInBricksStepAFallingPackingAsOneBitForBit) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  std::string summary;
  one_against_two((kData / "scenes" / "oedometer_fall.toml").string(), "", "oedometer_fall.h5", "4",
                  &summary);
  EXPECT_NE(summary.find("mpirun: 4 processes, bricks 2 x 1 x 2;"), std::string::npos) << summary;
}

/// A plain scene in a periodic cell from the YADE reference packings in tests/data.
std::string periodic_scene(const std::string& packing, const std::string& solver,
                           const std::string& cell) {
  return "[scene]\nname = \"cell\"\npacking = \"" + (kData / packing).string() +
         "\"\n[material]\nyoung_Pa = 3e7\nstiffness_ratio = 0.3\nfriction_deg = 25.0\n"
         "density_kg_m3 = 2550.0\nrolling_stiffness = 0.5\nrolling_limit = 0.3\n[solver]\n" +
         solver +
         "damping = 0.05\nmax_overlap_ratio = 0.5\n[output]\ntrajectory = \"cell.h5\"\nevery = "
         "500\nhistory_every = 100\ncheckpoint_every = 100000\n[cell]\n" +
         cell;
}

// YADE's periodic reference (1 000 spheres in a cube cell) sheared ten times faster than there
// (L_xz = 20/s, 3 000 steps: γ = 0.15, several rebuilds): slabs along the cell's base vector x
// (two and three processes) or 2 x 2 bricks (four), in the fractional coordinates, the first
// and the last neighbours across the boundary. They step it as one, bit for bit.
TEST(Mpi, ProcessesShearAPeriodicCellAsOneBitForBit) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_cell");
  const fs::path scene = dir / "cell.toml";
  std::ofstream(scene) << periodic_scene(
      "yade_periodic/packing.csv", "dt_s = 2.58e-06\nsteps = 3000\n",
      "size_m = [0.019384323656096786, 0.019384323656096786, 0.019384323656096786]\n"
      "velocity_gradient_1_s = [[0, 0, 20.0], [0, 0, 0], [0, 0, 0]]\n");
  const std::string args = " simulate " + scene.string() + " -q --threads 1 -o ";
  ASSERT_EQ(run(kExe + args + (dir / "one").string()), 0);
  std::string err, out;
  for (const char* n : {"2", "3", "4"}) {
    ASSERT_EQ(run(kMpirun + n + " " + kExe + args + (dir / n).string(), &err, &out), 0) << err;
    expect_same_run(dir / "one" / "cell.h5", dir / n / "cell.h5");
  }
  // (four processes: bricks across x and y, each next to the others across two faces)
  EXPECT_NE(out.find("bricks 2 x 2 x 1 (along the cell's base vectors)"), std::string::npos) << out;
}

// The planar cell (YADE's 2D emulation, the periodic2d reference: 600 spheres in one plane,
// L = diag(2, −2, 0)/s), with two threads in each of two processes.
TEST(Mpi, ProcessesStepAPlanarPeriodicCellAsOneBitForBit) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_cell2d");
  const fs::path scene = dir / "cell.toml";
  std::ofstream(scene) << periodic_scene(
      "yade_periodic2d/packing.csv", "dt_s = 2.95e-06\nsteps = 3000\n",
      "size_m = [0.04783235800060865, 0.04783235800060865, 0.008]\n"
      "velocity_gradient_1_s = [[2.0, 0, 0], [0, -2.0, 0], [0, 0, 0]]\n"
      "two_d = \"spheres_in_plane\"\n");
  ASSERT_EQ(
      run(kExe + " simulate " + scene.string() + " -q --threads 1 -o " + (dir / "one").string()),
      0);
  std::string err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + " simulate " + scene.string() + " -q --threads 2 -o " +
                    (dir / "two").string(),
                &err),
            0)
      << err;
  expect_same_run(dir / "one" / "cell.h5", dir / "two" / "cell.h5");
}

/// The largest difference of the particles' velocities in the last frames of two runs.
double velocity_gap(const fs::path& a_file, const fs::path& b_file) {
  const auto a = gs::read_hdf5_trajectory(a_file);
  const auto b = gs::read_hdf5_trajectory(b_file);
  const auto &p = a.frames.back().particles, &q = b.frames.back().particles;
  EXPECT_EQ(p.size(), q.size());
  double gap = 0;
  for (std::size_t i = 0; i < std::min(p.size(), q.size()); ++i)
    gap = std::max(gap, (p[i].velocity - q[i].velocity).cwiseAbs().maxCoeff());
  return gap;
}

// A servo on the cell's diagonal (σxx = σyy = −150 kPa from the contacts' stiffness, the shear
// of the YADE case on top) reads the cell's stress, which each process sums over its own
// contacts and the processes add in their order: not the one-process order, so the runs part
// at round-off once the servo leaves its rate limit (step ~660). Issue 23's bound: they stay
// within the divergence of two one-process runs whose inputs differ by one ulp. Two such
// inputs: every x one ulp up (velocities part by 1.7e-4 m/s at step 2 000 here), and the
// servo's target one ulp down, a change the servo feels each step as the process order's
// round-off (9.7e-10 m/s; two processes 5.8e-10, docs/scale.md). The test asks for the first
// and for ten times the second (the ratio to it depends on the machine's bits); it fails by
// orders of magnitude when the cell's stress is summed from ghosts a step old (checked).
TEST(Mpi, AServoedCellStaysWithinTheOneUlpDivergence) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_cell_servo");
  const std::string cell =
      "size_m = [0.019384323656096786, 0.019384323656096786, 0.019384323656096786]\n"
      "velocity_gradient_1_s = [[0, 0, 2.0], [0, 0, 0], [0, 0, 0]]\n"
      "control = [\"stress\", \"stress\", \"rate\"]\ntarget = [-1.5e5, -1.5e5, 0.0]\n"
      "servo_fraction = 0.3\nmax_rate_1_s = 2.0\n";
  const std::string solver = "dt_s = 2.58e-06\nsteps = 2000\n";
  std::ofstream(dir / "cell.toml") << periodic_scene("yade_periodic/packing.csv", solver, cell);
  {  // the packing with every x one ulp up
    std::ifstream in(kData / "yade_periodic" / "packing.csv");
    std::ofstream out(dir / "ulp.csv");
    out.precision(17);
    std::string line;
    std::getline(in, line);
    out << line << "\n";
    while (std::getline(in, line)) {
      std::vector<std::string> f;
      std::stringstream ss(line);
      for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
      ASSERT_EQ(f.size(), 5u);
      out << f[0] << "," << std::nextafter(std::stod(f[1]), HUGE_VAL) << "," << f[2] << "," << f[3]
          << "," << f[4] << "\n";
    }
  }
  std::string text = periodic_scene("yade_periodic/packing.csv", solver, cell);
  const std::string from = (kData / "yade_periodic" / "packing.csv").string();
  text.replace(text.find(from), from.size(), (dir / "ulp.csv").string());
  std::ofstream(dir / "ulp.toml") << text;
  std::string target = cell;  // −1.5e5 one ulp towards zero
  const std::string t = "target = [-1.5e5, -1.5e5";
  target.replace(target.find(t), t.size(), "target = [-149999.99999999997, -149999.99999999997");
  std::ofstream(dir / "target.toml") << periodic_scene("yade_periodic/packing.csv", solver, target);
  const std::string opts = " -q --threads 1 -o ";
  std::string err;
  ASSERT_EQ(
      run(kExe + " simulate " + (dir / "cell.toml").string() + opts + (dir / "one").string(), &err),
      0)
      << err;
  ASSERT_EQ(
      run(kExe + " simulate " + (dir / "ulp.toml").string() + opts + (dir / "ulp").string(), &err),
      0)
      << err;
  ASSERT_EQ(
      run(kExe + " simulate " + (dir / "target.toml").string() + opts + (dir / "target").string(),
          &err),
      0)
      << err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + " simulate " + (dir / "cell.toml").string() + opts +
                    (dir / "two").string(),
                &err),
            0)
      << err;
  const double ulp = velocity_gap(dir / "one" / "cell.h5", dir / "ulp" / "cell.h5");
  const double target_ulp = velocity_gap(dir / "one" / "cell.h5", dir / "target" / "cell.h5");
  const double two = velocity_gap(dir / "one" / "cell.h5", dir / "two" / "cell.h5");
  EXPECT_GT(target_ulp, 0);
  EXPECT_LE(two, ulp) << "two processes part from one more than a one-ulp change of the x";
  EXPECT_LE(two, 10 * target_ulp) << "… or than a one-ulp change of the target (" << target_ulp
                                  << " m/s)";
}

// The falling packing with two triangle meshes for walls: a saw-tooth floor (one contact per
// sphere and flat region, the default) and a saw-tooth side wall with YADE's facets (a wall
// per triangle), which the slanted gravity presses the packing against; per-triangle forces
// written. Particles and contacts to the bit; the walls' and triangles' loads to round-off.
TEST(Mpi, TwoProcessesStepMeshWallsAsOne) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_mesh");
  ASSERT_EQ(run(kExe +
                " surface sawtooth --length 0.029 --width 0.029 --height 0.001 --spacing "
                "0.004 --origin -0.002,-0.002,-0.004 --along 1,0,0 --normal 0,0,1 -o " +
                (dir / "floor.stl").string()),
            0);
  ASSERT_EQ(run(kExe +
                " surface sawtooth --length 0.029 --width 0.1 --height 0.0005 --spacing "
                "0.002 --origin 0.025,-0.002,-0.004 --along 0,1,0 --normal -1,0,0 -o " +
                (dir / "side.stl").string()),
            0);
  std::string text = slurp(kData / "scenes" / "oedometer_fall.toml");
  auto cut = [&](const std::string& what, const std::string& with) {
    const auto at = text.find(what);
    ASSERT_NE(at, std::string::npos) << what;
    text.replace(at, what.size(), with);
  };
  cut("../../../data/oedometer/packing.csv",
      (fs::path(GS_SOURCE_DIR) / "data" / "oedometer" / "packing.csv").string());
  cut("[[walls]]\nname = \"bottom\"\nshape = \"box\"\ncenter_m = [0.0125, 0.0125, -0.006]\n"
      "half_extents_m = [0.025, 0.025, 0.002]\n",
      "");
  cut("[[walls]]\nname = \"x+\"\nshape = \"box\"\ncenter_m = [0.027, 0.0125, 0.05]\n"
      "half_extents_m = [0.002, 0.025, 0.1]\n",
      "");
  cut("checkpoint_every = 1000\n", "checkpoint_every = 1000\nfacet_forces = true\n");
  text +=
      "\n[[mesh]]\nfile = \"floor.stl\"\nname = \"floor\"\n\n[[mesh]]\nfile = "
      "\"side.stl\"\nname = \"side\"\ncontact = \"yade\"\n";
  std::ofstream(dir / "mesh.toml") << text;
  const std::string args = " simulate " + (dir / "mesh.toml").string() + " -q --threads 1 -o ";
  ASSERT_EQ(run(kExe + args + (dir / "one").string()), 0);
  std::string err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + args + (dir / "two").string(), &err), 0) << err;
  expect_same_run(dir / "one" / "oedometer_fall.h5", dir / "two" / "oedometer_fall.h5");
  const auto a = gs::read_hdf5_trajectory(dir / "one" / "oedometer_fall.h5");
  const auto b = gs::read_hdf5_trajectory(dir / "two" / "oedometer_fall.h5");
  ASSERT_EQ(a.frames.size(), b.frames.size());
  std::size_t loaded = 0;
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    const auto &p = a.frames[i].facet_loads, &q = b.frames[i].facet_loads;
    ASSERT_EQ(p.size(), q.size());
    for (std::size_t k = 0; k < p.size(); ++k) {
      EXPECT_LE((p[k].force - q[k].force).norm(), 1e-12 * (1 + p[k].force.norm()));
      loaded += p[k].force.norm() > 0;
    }
  }
  EXPECT_GT(loaded, 50u);
}

/// Waits (up to a minute) until no process holds the run directory's lock: a process of a job
/// whose launcher was stopped may still be ending.
void wait_unlocked(const fs::path& dir) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    const int fd = ::open((dir / ".simulate.lock").c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) return;
    const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    ::close(fd);
    if (free) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// Clumps: 234 rods of four overlapping spheres (r = 0.6 mm, 1 mm apart: each member up to
// 1.5 mm from the centre of mass, more than 2 r_max + skin) dropped into a 60 mm long trough,
// so that the slabs (along x) cut through the settled pile. A clump is owned, with its members,
// by the process of its centre of mass; the ghost layer is wider by the clumps' extent (without
// that, the runs part by millimetres: checked). Two processes with two threads each and three
// processes equal one process to the bit, and a two-process run stopped after a checkpoint
// resumes on one process to the uninterrupted run.
TEST(Mpi, ProcessesStepClumpsAsOneBitForBit) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_clumps");
  {
    std::ofstream csv(dir / "rods.csv");
    csv.precision(17);
    csv << "template,x,y,z,qw,qx,qy,qz\n";
    int n = 0;
    for (int k = 0; k < 6; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 13; ++i, ++n) {  // a turn of a about a unit axis u, from n
          const double a = 0.7 * n + 0.3, b = 1.3 * n, c = 0.37 * n;
          const Eigen::Vector3d u(std::sin(b) * std::cos(c), std::sin(b) * std::sin(c),
                                  std::cos(b));
          csv << "rod," << 0.0022 + 0.0044 * i << "," << 0.0022 + 0.0044 * j << ","
              << 0.0022 + 0.0044 * k << "," << std::cos(a) << "," << std::sin(a) * u[0] << ","
              << std::sin(a) * u[1] << "," << std::sin(a) * u[2] << "\n";
        }
  }
  std::ofstream(dir / "rods.toml") << R"([scene]
name = "rods"
[material]
young_Pa = 3.0e7
stiffness_ratio = 0.3
friction_deg = 18.0
density_kg_m3 = 2550.0
rolling_stiffness = 0.7
rolling_limit = 0.4
[solver]
dt_s = 1.0e-6
damping = 0.08
gravity_m_s2 = [100.0, 0.0, -2000.0]
steps = 10000
max_overlap_ratio = 0.5
[output]
trajectory = "rods.h5"
every = 1000
history_every = 100
checkpoint_every = 1000
[[walls]]
name = "floor"
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[walls]]
name = "x-"
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[walls]]
name = "x+"
shape = "box"
center_m = [0.062, 0.0125, 0.05]
half_extents_m = [0.002, 0.025, 0.1]
[[walls]]
name = "y-"
shape = "plane"
point_m = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[walls]]
name = "y+"
shape = "plane"
point_m = [0.0, 0.0132, 0.0]
normal = [0.0, -1.0, 0.0]
[[clump_template]]
name = "rod"
members = [[-0.0015, 0.0, 0.0, 0.0006], [-0.0005, 0.0, 0.0, 0.0006], [0.0005, 0.0, 0.0, 0.0006],
           [0.0015, 0.0, 0.0, 0.0006]]
[clumps]
packing = "rods.csv"
mass = "union"
)";
  const std::string scene = (dir / "rods.toml").string();
  const std::string args = " simulate " + scene + " -q -o ";
  ASSERT_EQ(run(kExe + args + (dir / "one").string() + " --threads 1"), 0);
  std::string err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + args + (dir / "two").string() + " --threads 2", &err), 0)
      << err;
  ASSERT_EQ(run(kMpirun + "3 " + kExe + args + (dir / "three").string() + " --threads 1", &err), 0)
      << err;
  expect_same_run(dir / "one" / "rods.h5", dir / "two" / "rods.h5");
  expect_same_run(dir / "one" / "rods.h5", dir / "three" / "rods.h5");
  const auto t = gs::read_hdf5_trajectory(dir / "three" / "rods.h5");
  EXPECT_EQ(t.frames.back().clumps.size(), 234u);
  const fs::path resumed = dir / "resumed";
  ASSERT_TRUE(gs::test::stop_at_checkpoint(
      words(kMpirun + "2 " + kExe + args + resumed.string() + " --threads 1"), resumed, 5000,
      SIGTERM))
      << "the run ended before it could be stopped";
  wait_unlocked(resumed);  // (mpirun returns before its processes have all ended)
  ASSERT_EQ(run(kExe + args + resumed.string() + " --threads 1 --resume", &err), 0) << err;
  expect_same_run(dir / "one" / "rods.h5", resumed / "rods.h5");
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
  // (mpirun returns before its processes have all ended; the resume needs the directory's lock)
  wait_unlocked(two_then_one);
  wait_unlocked(one_then_two);
  std::string err;
  ASSERT_EQ(run(kExe + args + two_then_one.string() + " --resume", &err), 0) << err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + args + one_then_two.string() + " --resume", &err), 0)
      << err;
  expect_same_run(dir / "straight" / "oedometer_fall.h5", two_then_one / "oedometer_fall.h5");
  expect_same_run(dir / "straight" / "oedometer_fall.h5", one_then_two / "oedometer_fall.h5");
}

/// The history's removal columns (count, mass) of each row, as written.
std::vector<std::string> removal_columns(const fs::path& history) {
  std::vector<std::string> out;
  std::istringstream in(slurp(history));
  for (std::string line; std::getline(in, line);) {
    const auto b = line.rfind(',');
    const auto a = b == std::string::npos ? b : line.rfind(',', b - 1);
    if (a != std::string::npos) out.push_back(line.substr(a + 1));
  }
  return out;
}

/// A scene with an outlet on one process, then on each of `processes`, then on two stopped
/// at the checkpoint at or past `stop_step` and resumed on one: every run equals the first,
/// particles and contacts to the bit and the history's removal columns as written. Returns
/// the first run's removal columns (the header first).
std::vector<std::string> removals_as_on_one(const gs::test::ScratchDir& dir,
                                            const std::string& scene, const std::string& h5,
                                            const std::vector<std::string>& processes,
                                            long stop_step) {
  const std::string args = " simulate " + scene + " -q --threads 1 -o ";
  std::string err;
  EXPECT_EQ(run(kExe + args + (dir / "one").string(), &err), 0) << err;
  const auto one = removal_columns(dir / "one" / "history.csv");
  for (const std::string& np : processes) {
    const fs::path out = dir / ("p" + np);
    EXPECT_EQ(run(kMpirun + np + " " + kExe + args + out.string(), &err), 0) << err;
    expect_same_run(dir / "one" / h5, out / h5);
    EXPECT_EQ(removal_columns(out / "history.csv"), one) << np << " processes";
  }
  const fs::path resumed = dir / "two_then_one";
  EXPECT_TRUE(gs::test::stop_at_checkpoint(words(kMpirun + "2 " + kExe + args + resumed.string()),
                                           resumed, stop_step, SIGTERM))
      << "the run ended before it could be stopped";
  wait_unlocked(resumed);
  EXPECT_EQ(run(kExe + args + resumed.string() + " --resume", &err), 0) << err;
  expect_same_run(dir / "one" / h5, resumed / h5);
  EXPECT_EQ(removal_columns(resumed / "history.csv"), one);
  return one;
}

// An outlet (tests/data/scenes/oedometer_drain.toml: the falling packing drained through a
// slot in its floor, 67 spheres removed over 3 000 steps, several in one step). Each owner
// retires its own particles as they leave; the step then ends with a rebuild, where every
// process holds every state and counts them in index order as one process does (without that
// count, the test fails: checked). Two and four processes equal one: particles and contacts to
// the bit, and the
// removed count and mass of every history row as written. A two-process run stopped after a
// checkpoint in the middle of the discharge resumes on one process to the uninterrupted run.
TEST(Mpi, AnOutletRemovesOnEveryProcessAsOnOne) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_outlet");
  const auto one = removals_as_on_one(dir, (kData / "scenes" / "oedometer_drain.toml").string(),
                                      "oedometer_drain.h5", {"2", "4"}, 4000);
  ASSERT_EQ(one.size(), 62u);  // (the header and 61 rows)
  EXPECT_EQ(one.back().substr(0, one.back().find(',')), "67");
}

// A filling and an outlet (tests/data/scenes/fill_drain.toml: three layers of 200 spheres
// poured in quick succession into a box whose floor has a slot closed by a lid, the lid
// switched off once the filling has settled, then an outlet under the slot). Every process
// decides when the next layer goes in from the same sums (the kinetic energy and its
// threshold, added in index order from the owners' terms), and places it among every
// particle's present state (a rebuild just before). Checked: placed among the states of the
// last rebuild instead, the runs part at step 10 500; with each process's sums over its own
// particles only, the processes insert at different steps and the run hangs (the test then
// fails at mpirun's time limit). Two and three processes equal one:
// particles and contacts to the bit (the frame at the switch-off too, which lists the lid's
// contacts of the last step), the removal columns of the history as written; a two-process run
// stopped after a checkpoint in the middle of the filling resumes on one process to the
// uninterrupted run.
TEST(Mpi, AFillingAndAnOutletRunAsOnOneProcess) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_fill");
  const auto one = removals_as_on_one(dir, (kData / "scenes" / "fill_drain.toml").string(),
                                      "fill_drain.h5", {"2", "3"}, 8000);
  ASSERT_EQ(one.size(), 88u);  // (the header and 87 rows: 15 425 steps of filling, 6 000 more)
  EXPECT_GT(std::stoi(one.back().substr(0, one.back().find(','))), 100);
}

// Seed 004's silo programme (tests/data/scenes/silo_tiny.toml: two layers of 150 spheres
// poured between saw-tooth walls, then a centred outlet; 12.6 % discharged). Its start reads
// every particle (the mass in the silo, the fill's surface, the void ratio: a rebuild gives
// every process every state first), its curve rows and summary are written from the whole
// assembly (gathered on process 0, as the history). Two and three processes equal one:
// particles, contacts and wall loads to the bit, the curve the same text (the walls' forces
// too), the summary line the same. (Not told apart here: the start's reads and the curve's from
// the states of the last rebuild instead of the present ones; the settled fill moves too little
// between rebuilds for the printed digits to differ.)
TEST(Mpi, TheSiloRunsAsOnOneProcess) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_silo");
  const std::string scene = (kData / "scenes" / "silo_tiny.toml").string();
  const std::string args = " simulate " + scene + " -q --threads 1 -o ";
  std::string err, out_one;
  ASSERT_EQ(run(kExe + args + (dir / "one").string(), &err, &out_one), 0) << err;
  auto summary = [](const std::string& out) {
    const auto at = out.find("silo (gravitational");
    return at == std::string::npos ? std::string() : out.substr(at, out.find('\n', at) - at);
  };
  ASSERT_NE(summary(out_one), "") << out_one;
  const std::string curve = slurp(dir / "one" / "curve.csv");
  ASSERT_GT(std::count(curve.begin(), curve.end(), '\n'), 5);
  for (const std::string np : {"2", "3"}) {
    const fs::path out = dir / ("p" + np);
    std::string out_np;
    ASSERT_EQ(run(kMpirun + np + " " + kExe + args + out.string(), &err, &out_np), 0) << err;
    expect_same_run(dir / "one" / "trajectory.h5", out / "trajectory.h5", true);
    EXPECT_EQ(summary(out_np), summary(out_one));
    EXPECT_EQ(slurp(out / "curve.csv"), curve) << np << " processes";
  }
}

/// The history's rows (`history.csv`) of two runs the same text, but for the ledger's sums over
/// processes (the dissipation and work terms and the residual), which must agree within 1e-9 of
/// their column's largest magnitude in the run.
void expect_same_history(const fs::path& one, const fs::path& other) {
  auto table = [](const fs::path& f) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(slurp(f));
    for (std::string line; std::getline(in, line);) {
      rows.emplace_back();
      std::istringstream l(line);
      for (std::string c; std::getline(l, c, ',');) rows.back().push_back(c);
    }
    return rows;
  };
  const auto a = table(one / "history.csv"), b = table(other / "history.csv");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 2u);
  const auto& head = a[0];
  for (std::size_t c = 0; c < head.size(); ++c) {
    const bool summed = head[c].find("dissipation") != std::string::npos ||
                        head[c].find("work") != std::string::npos ||
                        head[c].find("residual") != std::string::npos;
    double scale = 0;
    for (std::size_t r = 1; r < a.size(); ++r)
      if (summed) scale = std::max(scale, std::abs(std::stod(a[r].at(c))));
    for (std::size_t r = 1; r < a.size(); ++r) {
      ASSERT_EQ(b[r].size(), a[r].size()) << "history row " << r;
      if (!summed) {
        EXPECT_EQ(b[r][c], a[r][c]) << head[c] << ", history row " << r;
      } else {
        EXPECT_LE(std::abs(std::stod(b[r][c]) - std::stod(a[r][c])), 1e-9 * scale)
            << head[c] << ", history row " << r;
      }
    }
  }
}

/// Every output a laboratory test writes in `one` and `other` the same: trajectory and prepared
/// specimen to the bit (expect_same_run), the curves, the preparation's curve and the results
/// as text, the history (expect_same_history).
void expect_same_lab_run(const fs::path& one, const fs::path& other, const std::string& h5) {
  expect_same_history(one, other);
  expect_same_run(one / h5, other / h5, true);
  if (fs::exists(one / "specimen.h5"))
    expect_same_run(one / "specimen.h5", other / "specimen.h5", true);
  for (const char* f : {"curve.csv", "preparation.csv", "results.csv"}) {
    ASSERT_EQ(fs::exists(other / f), fs::exists(one / f)) << f;
    if (fs::exists(one / f)) {
      EXPECT_EQ(slurp(other / f), slurp(one / f)) << other / f;
    }
  }
}

// The laboratory tests under mpirun (tests/data/scenes/*_tiny.toml: a few hundred spheres, each
// prepared by compaction and loaded): the triaxial test, the plane-strain test (the membranes'
// loads, every 20 steps, from every particle's present position, shared by the owners), the
// direct shear test and the interface shear test over a saw-tooth surface (its start reads the
// void ratio of every particle: a rebuild first; grains pushed off the surface removed), and
// seed 003's stress rotation (dimers deposited, carved by the polyhedron, whose servo reads the
// moment of its walls' contact forces, summed as the walls' loads are).
// The preparation's equilibrium checks (the unbalanced force, the energies, the core's void
// ratio) are made on the whole assembly gathered on process 0, their verdict sent to every
// process; the servos read the walls' loads, which every step sums over every process's wall
// contacts in pair order, as one process does. Two processes (three for the plane-strain test)
// equal one: trajectory, prepared specimen, curves and results, and the summary lines. Checked
// by mutation: with the checks on each process's own part the processes disagree on the stage
// and the run hangs or parts; with the walls' loads summed per process, then over processes,
// the runs part at round-off once a servo works within its speed limit; with the membranes
// found from each process's own states, the plane-strain curve differs (its reference volume);
// with the preparation's check deciding "surely unsettled" from each process's sums at 0.9 of
// the unbalanced-force tolerance instead of beyond their round-off, the runs part.
// (Not told apart here: the interface shear's start reading the states of the last rebuild
// instead of the present ones, its void ratio at the start does not change in the printed
// digits; the carving's energy counted on every process instead of by the owners, the settled
// bed's kinetic energy and the cut contacts' elastic energy are below the history's tolerance.)
TEST(Mpi, LaboratoryTestsRunAsOnOneProcess) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_lab");
  struct Case {
    const char *scene, *h5, *summary, *processes;
  };
  for (const Case& c :
       {Case{"triaxial_tiny", "triaxial.h5", "triaxial:", "2"},
        Case{"plane_strain_tiny", "plane_strain.h5", "plane strain", "3"},
        Case{"direct_shear_tiny", "direct_shear.h5", "direct shear", "2"},
        Case{"interface_shear_tiny", "interface_shear.h5", "interface shear", "2"},
        Case{"stress_rotation_tiny", "stress_rotation.h5", "stress rotation", "2"}}) {
    const std::string args = " simulate " +
                             (kData / "scenes" / (std::string(c.scene) + ".toml")).string() +
                             " -q --threads 1 -o ";
    std::string err, out_one, out_np;
    const fs::path one = dir / (std::string(c.scene) + "_one"),
                   np = dir / (std::string(c.scene) + "_np");
    ASSERT_EQ(run(kExe + args + one.string(), &err, &out_one), 0) << err;
    ASSERT_EQ(run(kMpirun + c.processes + " " + kExe + args + np.string(), &err, &out_np), 0)
        << err;
    expect_same_lab_run(one, np, c.h5);
    auto summaries = [](const std::string& out) {  // the lines before "<name>: N steps of …"
      return out.substr(0, out.find(" steps of "));
    };
    EXPECT_NE(out_one.find(c.summary), std::string::npos) << out_one;
    EXPECT_EQ(summaries(out_np).substr(0, summaries(out_np).rfind('\n')),
              summaries(out_one).substr(0, summaries(out_one).rfind('\n')))
        << c.scene;
  }
}

// A sweep (the tiny triaxial test to 1 % axial strain at two confining pressures) under
// mpirun: each point decomposed over the processes in turn; every point's outputs and the
// sweep's table equal one process's.
TEST(Mpi, ASweepRunsEachPointDecomposed) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_sweep");
  std::string text = slurp(kData / "scenes" / "triaxial_tiny.toml");
  const std::string from = "max_strain = 0.02";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "max_strain = 0.01");
  text += "\n[sweep]\nkey = \"triaxial.confining_Pa\"\nvalues = [1.0e5, 2.0e5]\n";
  std::ofstream(dir / "sweep.toml") << text;
  const std::string args = " simulate " + (dir / "sweep.toml").string() + " -q --threads 1 -o ";
  std::string err;
  ASSERT_EQ(run(kExe + args + (dir / "one").string(), &err), 0) << err;
  ASSERT_EQ(run(kMpirun + "2 " + kExe + args + (dir / "two").string(), &err), 0) << err;
  EXPECT_EQ(slurp(dir / "two" / "sweep.csv"), slurp(dir / "one" / "sweep.csv"));
  for (const char* point : {"confining_Pa_1e+05", "confining_Pa_2e+05"})
    expect_same_lab_run(dir / "one" / point, dir / "two" / point, "triaxial.h5");
}

// A triaxial test stopped on two processes in the middle of its preparation (the checkpoint at
// step 3 000 or past it) resumes on one process, and one stopped on one process resumes on
// three: both end as the uninterrupted run (its outputs, to the bit and as text).
TEST(Mpi, ALaboratoryTestResumesOnAnyNumberOfProcesses) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_lab_resume");
  const std::string args =
      " simulate " + (kData / "scenes" / "triaxial_tiny.toml").string() + " -q --threads 1 -o ";
  std::string err;
  ASSERT_EQ(run(kExe + args + (dir / "straight").string(), &err), 0) << err;
  const fs::path two_then_one = dir / "two_then_one", one_then_three = dir / "one_then_three";
  ASSERT_TRUE(gs::test::stop_at_checkpoint(
      words(kMpirun + "2 " + kExe + args + two_then_one.string()), two_then_one, 3000, SIGTERM))
      << "the run ended before it could be stopped";
  wait_unlocked(two_then_one);
  ASSERT_TRUE(gs::test::stop_at_checkpoint(words(kExe + args + one_then_three.string()),
                                           one_then_three, 3000, SIGTERM));
  ASSERT_EQ(run(kExe + args + two_then_one.string() + " --resume", &err), 0) << err;
  ASSERT_EQ(run(kMpirun + "3 " + kExe + args + one_then_three.string() + " --resume", &err), 0)
      << err;
  expect_same_lab_run(dir / "straight", two_then_one, "triaxial.h5");
  expect_same_lab_run(dir / "straight", one_then_three, "triaxial.h5");
}

// The periodic biaxial test (tests/data/scenes/biaxial_periodic_tiny.toml: 150 disks, the cell's
// servo compacting them, then the test to 0.4 % axial strain). The cell's stress is summed by
// each process over its own contacts and added over processes: not one process's order (each
// step would have to share every contact's terms), so the runs part at round-off once the servo
// reads it within its rate limits (issue 23's bound then: Mpi.AServoedCellStaysWithinTheOneUlp…).
// Before that, the runs must be the same: every history row (the cell, its stress, the energies
// but for the dissipation sums) equals one process's to the bit up to the first row that a
// one-ulp change of the lateral stress changes, and there are a good many such rows (the
// preparation's checks on the gathered whole, its stage changes, the servo at its limit).
TEST(Mpi, APeriodicBiaxialTestRunsAsOnOneUntilRoundOffCounts) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_biaxial");
  const fs::path scene = kData / "scenes" / "biaxial_periodic_tiny.toml";
  std::string text = slurp(scene);
  const std::string from = "lateral_stress_Pa = 1e5";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "lateral_stress_Pa = 99999.999999999985");
  std::ofstream(dir / "ulp.toml") << text;
  const std::string opts = " -q --threads 1 -o ";
  std::string err;
  ASSERT_EQ(run(kExe + " simulate " + scene.string() + opts + (dir / "one").string(), &err), 0)
      << err;
  ASSERT_EQ(
      run(kExe + " simulate " + (dir / "ulp.toml").string() + opts + (dir / "ulp").string(), &err),
      0)
      << err;
  ASSERT_EQ(
      run(kMpirun + "2 " + kExe + " simulate " + scene.string() + opts + (dir / "two").string(),
          &err),
      0)
      << err;
  auto rows = [](const fs::path& history) {  // without the dissipation sums (per process)
    std::vector<std::string> out;
    std::istringstream in(slurp(history));
    std::vector<bool> keep;
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> cells;
      std::istringstream l(line);
      for (std::string c; std::getline(l, c, ',');) cells.push_back(c);
      if (keep.empty())
        for (const auto& c : cells)
          keep.push_back(c.find("dissipation") == std::string::npos &&
                         c.find("residual") == std::string::npos);
      std::string row;
      for (std::size_t k = 0; k < cells.size() && k < keep.size(); ++k)
        if (keep[k]) row += cells[k] + ",";
      out.push_back(row);
    }
    return out;
  };
  const auto one = rows(dir / "one" / "history.csv"), ulp = rows(dir / "ulp" / "history.csv"),
             two = rows(dir / "two" / "history.csv");
  std::size_t same = 0;
  while (same < std::min(one.size(), ulp.size()) && one[same] == ulp[same]) ++same;
  ASSERT_GE(same, 20u) << "a one-ulp change of the lateral stress parts the run early";
  ASSERT_GE(two.size(), same);
  for (std::size_t r = 0; r < same; ++r) EXPECT_EQ(two[r], one[r]) << "history row " << r;
  ASSERT_EQ(gs::read_hdf5_trajectory(dir / "two" / "kb.h5").frames.size(),
            gs::read_hdf5_trajectory(dir / "one" / "kb.h5").frames.size());
}

// The shared YADE facet silo (tests/data/yade_facets: 1 000 spheres discharging from a 48-facet
// silo with a saw-tooth wall, YADE's facets: a wall per triangle, facet pairs deferred while
// provably apart) with a frame every 10 steps, 2 000 steps. Each frame gathers the whole
// assembly on process 0; it must step on from exactly the state it had. When it rebuilt its
// part's neighbour list after each frame instead (from the present positions, not those of the
// last rebuild), a deferred facet pair was admitted too late once in a while: the runs parted
// at step 1 720 (and the contacts written at step 500 already differed).
TEST(Mpi, FramesOftenLeaveTheRunAsOneProcessStepsIt) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_frames_often");
  {
    std::ofstream stl(dir / "silo.stl");
    stl.precision(17);
    stl << "solid silo\n";
    std::istringstream in(slurp(kData / "yade_facets" / "mesh.csv"));
    std::string line;
    std::getline(in, line);  // (header)
    while (std::getline(in, line)) {
      std::istringstream row(line);
      std::string cell;
      std::vector<double> v;
      for (int c = 0; std::getline(row, cell, ','); ++c)
        if (c >= 2) v.push_back(std::stod(cell));
      ASSERT_EQ(v.size(), 9u) << line;
      stl << "facet normal 0 0 0\nouter loop\n";
      for (int k = 0; k < 3; ++k)
        stl << "vertex " << v[3 * k] << " " << v[3 * k + 1] << " " << v[3 * k + 2] << "\n";
      stl << "endloop\nendfacet\n";
    }
    stl << "endsolid silo\n";
  }
  std::ofstream(dir / "silo.toml")
      << "[scene]\nname = \"silo\"\npacking = \""
      << (kData / "yade_facets" / "packing.csv").string()
      << "\"\n[material]\nyoung_Pa = 2.0e6\nstiffness_ratio = 0.3\nfriction_deg = 18.0\n"
         "density_kg_m3 = 2550.0\nrolling_stiffness = 0.5\nrolling_limit = 0.2\n[solver]\n"
         "dt_s = 1.43e-5\ndamping = 0.1\ngravity_m_s2 = [0.0, 0.0, -9.81]\nsteps = 2000\n"
         "max_overlap_ratio = 1.0\n[output]\ntrajectory = \"silo.h5\"\nevery = 10\n"
         "history_every = 500\ncheckpoint_every = 100000000\n[[mesh]]\nfile = \"silo.stl\"\n"
         "contact = \"yade\"\n[outlet]\nkeep_lo_m = [-1.0, -1.0, -0.01]\n"
         "keep_hi_m = [1.0, 1.0, 1.0]\n";
  one_against_two((dir / "silo.toml").string(), "", "silo.h5");
}

// `analyze … --frames` under mpirun: the processes share the frames, process 0 merges them;
// the series equals the one made by worker processes (every dataset, to the bit).
TEST(Mpi, AnalysesOverFramesShareTheFramesBetweenProcesses) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_frames");
  ASSERT_EQ(run(kExe + " simulate " + (kData / "scenes" / "oedometer_fall.toml").string() +
                " -q -o " + (dir / "run").string()),
            0);
  const std::string traj = (dir / "run" / "oedometer_fall.h5").string();
  std::string err;
  ASSERT_EQ(run(kExe + " analyze fabric " + traj + " --frames 1:7:2 --jobs 2 -o " +
                (dir / "jobs.h5").string()),
            0);
  ASSERT_EQ(run(kMpirun + "2 " + kExe + " analyze fabric " + traj + " --frames 1:7:2 -o " +
                    (dir / "mpi.h5").string(),
                &err),
            0)
      << err;
  for (const char* name : {"/frame", "/M", "/D", "/attributes/omega", "/attributes/contacts"}) {
    const auto a = read_dataset(dir / "jobs.h5", name), b = read_dataset(dir / "mpi.h5", name);
    EXPECT_EQ(a, b) << name;
    EXPECT_FALSE(a.empty()) << name;
  }
  EXPECT_EQ(read_dataset(dir / "mpi.h5", "/frame"), (std::vector<double>{1, 3, 5}));
}

// A scene error is one line from process 0 and exit code 2.
TEST(Mpi, BadScenesGiveOneLineAndExit2) {
  if (!mpirun_present()) GTEST_SKIP() << "mpirun not installed (apt-get install openmpi-bin)";
  gs::test::ScratchDir dir("mpi_bad");
  std::string err;
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
