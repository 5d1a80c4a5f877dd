// `granoscope simulate` with a [cell]: the YADE 2D case from a scene file, end to end, and the
// cell's bad inputs.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <hdf5.h>
#include "../io/test_util.hpp"
#include "cli_util.hpp"

#include "hdf5_trajectory.hpp"

namespace {

using gs::test::slurp;

const std::string kExe = std::string(GS_BINARY_DIR) + "/bin/granoscope";

int run(const std::string& args, std::string* err = nullptr) {
  const auto e =
      std::filesystem::temp_directory_path() / ("gs_simp_err_" + std::to_string(::getpid()));
  const int status =
      std::system((kExe + " " + args + " >/dev/null 2>" + e.string() + " </dev/null").c_str());
  if (err) *err = slurp(e);
  std::filesystem::remove(e);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

/// ../shared/reference/yade/periodic2d beside the checkout, else the copy in tests/data.
std::filesystem::path reference_dir() {
  const auto shared =
      std::filesystem::path(GS_SOURCE_DIR) / ".." / "shared" / "reference" / "yade" / "periodic2d";
  if (std::filesystem::exists(shared / "packing.csv")) return shared;
  return std::filesystem::path(GS_TEST_DATA_DIR) / "yade_periodic2d";
}

using Table = gs::test::CsvTable;
const auto read_table = gs::test::read_csv_table;

std::string scene_text(const std::string& cell) {
  const auto packing = reference_dir() / "packing.csv";
  return "[scene]\nname = \"p2d\"\npacking = \"" + packing.string() +
         "\"\n[material]\nyoung_Pa = 3e7\nstiffness_ratio = 0.3\nfriction_deg = 25.0\n"
         "density_kg_m3 = 2550.0\nrolling_stiffness = 0.5\nrolling_limit = 0.3\n"
         "[solver]\ndt_s = 2.95e-06\ndamping = 0.05\nsteps = 300\nmax_overlap_ratio = 0.5\n"
         "[output]\nevery = 100\nhistory_every = 100\ncheckpoint_every = 1000\n[cell]\n" +
         cell;
}

const std::string kCell =
    "size_m = [0.04783235800060865, 0.04783235800060865, 0.008]\n"
    "velocity_gradient_1_s = [[2.0, 0, 0], [0, -2.0, 0], [0, 0, 0]]\n"
    "two_d = \"spheres_in_plane\"\n";

}  // namespace

// The stress in the history at step 300 is YADE's (periodic2d/out/stress.csv) to round-off.
TEST(SimulatePeriodic, YadePlanarCaseFromASceneFile) {
  gs::test::ScratchDir dir("simulate_periodic");
  std::ofstream(dir / "p2d.toml") << scene_text(kCell);
  std::string err;
  ASSERT_EQ(
      run("simulate " + (dir / "p2d.toml").string() + " -q -o " + (dir / "out").string(), &err), 0)
      << err;
  const Table hist = read_table(dir / "out" / "history.csv");
  const Table ref = read_table(reference_dir() / "out" / "stress.csv");
  std::size_t rh = hist.rows.size(), rr = ref.rows.size();
  for (std::size_t r = 0; r < hist.rows.size(); ++r)
    if (std::lround(hist.num(r, "step")) == 300) rh = r;
  for (std::size_t r = 0; r < ref.rows.size(); ++r)
    if (std::lround(ref.num(r, "step")) == 300) rr = r;
  ASSERT_LT(rh, hist.rows.size());
  ASSERT_LT(rr, ref.rows.size());
  const char* ij[] = {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
  double norm = 0, diff = 0;
  for (int k = 0; k < 9; ++k) {
    const double y = ref.num(rr, "s" + std::to_string(k / 3) + std::to_string(k % 3));
    const double o = hist.num(rh, std::string("cell_stress_") + ij[k] + "_Pa");
    norm += y * y;
    diff += (o - y) * (o - y);
  }
  EXPECT_LT(std::sqrt(diff / norm), 1e-9);
  EXPECT_EQ(hist.num(rh, "contacts"), ref.num(rr, "contacts"));
  EXPECT_EQ(hist.num(rh, "cell_hzz_m"), 0.008);
  // `info` reports the cell and the dimension.
  const auto info = dir / "info.txt";
  ASSERT_EQ(std::system((kExe + " info " + (dir / "out" / "trajectory.h5").string() + " > " +
                         info.string() + " 2>&1")
                            .c_str()),
            0);
  const std::string text = slurp(info);
  // (after 300 steps of L = diag(2, −2, 0)/s: H_xx = 0.0478324·(1 + 2·dt)^299 = 0.0479168, …)
  char cell_line[160];
  std::snprintf(cell_line, sizeof cell_line,
                "cell:         periodic, H = [%.6g 0 0; 0 %.6g 0; 0 0 0.008] m",
                0.04783235800060865 * std::pow(1 + 2 * 2.95e-6, 299),
                0.04783235800060865 * std::pow(1 - 2 * 2.95e-6, 299));
  EXPECT_NE(text.find(cell_line), std::string::npos) << cell_line << "\n" << text;
  EXPECT_NE(text.find("dimension:    2D"), std::string::npos) << text;
  // Frames carry the cell, the 2D flag and positions wrapped into the cell.
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "trajectory.h5");
  ASSERT_FALSE(t.frames.empty());
  const auto& f = t.frames.back();
  EXPECT_TRUE(f.domain.periodic);
  EXPECT_TRUE(f.two_d);
  EXPECT_NEAR(f.domain.cell(2, 2), 0.008, 1e-15);
  for (const auto& p : f.particles) {
    const Eigen::Vector3d s = f.domain.cell.inverse() * p.position;
    EXPECT_TRUE((s.array() > -1e-9).all() && (s.array() < 1 + 1e-9).all()) << p.id;
  }
}

TEST(SimulatePeriodic, BadCellsFailWithOneLine) {
  gs::test::ScratchDir dir("simulate_periodic_bad");
  const std::pair<std::string, std::string> cases[] = {
      {"size_m = [0.004, 0.004, 0.008]\n", "below 3 (2 r_max + skin)"},
      {"hsize_m = [[0.05, 0.05, 0], [0.05, 0.05, 0], [0, 0, 0.008]]\n", "singular or inverted"},
      {"hsize_m = [[0.05, 0, 0], [0, -0.05, 0], [0, 0, 0.008]]\n", "singular or inverted"},
      {"size_m = [0.05, 0.05, 0.008]\nvelocity_gradient_1_s = [[1, 0], [0, 1]]\n", "3 rows of 3"},
      {"size_m = [0.05, 0.05, 0.008]\ntwo_d = \"discs\"\n", "cell.two_d"},
      {"size_m = [0.05, 0.05, 0.008]\nsize_x = 1\n", "unknown key"},
      {"size_m = [0.05, 0.05, 0.008]\nhsize_m = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n",
       "one of size_m and hsize_m"},
      {"size_m = [0.05, 0.05, 0.008]\ncontrol = [\"stress\", \"rate\", \"strain\"]\n",
       "cell.control"},
      {"size_m = [0.05, 0.05, 0.008]\ncontrol = [\"stress\", \"rate\", \"rate\"]\n"
       "target = [-1e5, -0.1, 0]\nmax_rate_1_s = 0.5\n",
       "cell.servo_gain: missing"},
      {"size_m = [0.05, 0.05, 0.008]\ncontrol = [\"stress\", \"stress\", \"rate\"]\n"
       "target = [-1e5, -1e5, 0.1]\nservo_gain = 1e-4\nmax_rate_1_s = 0.5\n"
       "two_d = \"spheres_in_plane\"\n",
       "xy plane only"},
      {"size_m = [0.05, 0.05, 0.008]\nservo_gain = 1e-4\n", "needs cell.control"},
  };
  int k = 0;
  for (const auto& [cell, expect] : cases) {
    const auto scene = dir / ("bad" + std::to_string(k++) + ".toml");
    std::ofstream(scene) << scene_text(cell);
    std::string err;
    EXPECT_EQ(run("simulate " + scene.string() + " -q -o " + (dir / "out").string(), &err), 2)
        << cell;
    EXPECT_NE(err.find(expect), std::string::npos) << cell << " -> " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_EQ(err.rfind("error: ", 0), 0u) << err;
  }
}

// The analyses read the cell from the frames: `analyze invariants` on the simulated periodic run
// gives the engine's own cell stress (history columns) from the wrapped positions and contacts,
// with the analysis' conventions (compression positive, σ_ij = Σ l_i f_j / V: the transpose; a
// 2D frame per unit depth, N/m: the engine's stress per volume times the cell's thickness).
TEST(SimulatePeriodic, AnalysesUseTheCell) {
  gs::test::ScratchDir dir("simulate_periodic_inv");
  std::ofstream(dir / "p.toml") << scene_text(kCell);
  ASSERT_EQ(run("simulate " + (dir / "p.toml").string() + " -q -o " + (dir / "out").string()), 0);
  std::string err;
  ASSERT_EQ(run("analyze invariants " + (dir / "out" / "trajectory.h5").string() + " -o " +
                    (dir / "inv.h5").string(),
                &err),
            0)
      << err;
  double t[9] = {};
  const hid_t f = H5Fopen((dir / "inv.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t d = H5Dopen2(f, "/stress/tensor", H5P_DEFAULT);
  ASSERT_GE(d, 0);
  ASSERT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, t), 0);
  H5Dclose(d);
  H5Fclose(f);
  const Table hist = read_table(dir / "out" / "history.csv");
  const std::size_t last = hist.rows.size() - 1;
  const char* ij[] = {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
  double norm = 0, diff = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (i == 2 || j == 2) continue;  // (2D: the in-plane block)
      const double engine =
          hist.num(last, std::string("cell_stress_") + ij[3 * j + i] + "_Pa") * 0.008;
      norm += engine * engine;
      diff += (t[3 * i + j] + engine) * (t[3 * i + j] + engine);
    }
  EXPECT_LT(std::sqrt(diff / norm), 1e-9);
}
