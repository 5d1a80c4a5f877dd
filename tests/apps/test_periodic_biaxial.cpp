// `simulate` of the periodic biaxial test (seed 002 §4) on a small assembly, end to end: the
// graded disks compacted in the cell to the target void ratio, σ11 held by the width servo while
// the height shortens at its rate, frames at the listed strains carrying the cell's velocity
// gradient, `analyze voidcells` on them with no extra option; and the test's bad inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include <hdf5.h>
#include "../io/test_util.hpp"
#include "cli_util.hpp"

#include "hdf5_trajectory.hpp"

namespace {

using gs::test::replaced;
using gs::test::run_cli;
using gs::test::slurp;

using Table = gs::test::CsvTable;
using gs::test::read_csv_table;

// 150 of Kuhn's graded disks; softer (Ec = 1e8) and a faster compaction than the shipped scene,
// so that the whole test takes seconds.
std::string scene(const std::string& extra_specimen = "", const std::string& extra = "") {
  return "[scene]\nname = \"kb\"\ntest = \"biaxial_periodic\"\n"
         "[specimen]\ncount = 150\ndmin_m = 0.45e-3\ndmax_m = 1.4e-3\ndistribution = \"graded\"\n"
         "d50_m = 1e-3\nuniformity = 1.7\nvoid_ratio = 0.21\nseed = 3\n"
         "cloud_solid_fraction = 0.5\n" +
         extra_specimen +
         "[material]\nyoung_Pa = 1e8\nstiffness_ratio = 1.0\nfriction_deg = 26.565\n"
         "density_kg_m3 = 2650.0\n"
         "[solver]\ndt_s = \"auto\"\ndt_safety = 0.5\ndamping = 0.1\nthreads = 1\n"
         "[preparation]\nfriction_start_deg = 8.0\nfriction_factor = 0.5\nstage_steps = 1000\n"
         "check_every = 100\nservo_gain = 0.3\nmax_rate_1_s = 20.0\n"
         "[biaxial_periodic]\nlateral_stress_Pa = 1e5\nstrain_rate_1_s = 0.5\n"
         "max_strain = 0.004\nframe_strains = [0.0001, 0.0016]\nframe_every_strain = 0.002\n" +
         extra +
         "[output]\ntrajectory = \"kb.h5\"\ncurve_every = 50\nhistory_every = 500\n"
         "checkpoint_every = 5000\n";
}

}  // namespace

TEST(PeriodicBiaxial, SmallAssemblyEndToEnd) {
  gs::test::ScratchDir dir("periodic_biaxial");
  std::ofstream(dir / "kb.toml") << scene();
  const auto r = run_cli(
      "simulate " + (dir / "kb.toml").string() + " -q -o " + (dir / "out").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  // Preparation: ends at the target void ratio or below, with σ11 = σ22 = 100 kPa within 1 %.
  const Table prep = read_csv_table(dir / "out" / "preparation.csv");
  ASSERT_FALSE(prep.rows.empty());
  const std::size_t lp = prep.rows.size() - 1;
  EXPECT_LE(prep.num(lp, "void_ratio"), 0.21);
  for (const char* c : {"cell_stress_xx_Pa", "cell_stress_yy_Pa"})
    EXPECT_NEAR(prep.num(lp, c), 1e5, 1e3) << c;
  // The test: ε22 reaches 0.4 %, σ11 held within 2 % once loading has settled in, the area
  // strain and the void ratio consistent (e = A/A_s − 1 with A_s fixed).
  const Table curve = read_csv_table(dir / "out" / "curve.csv");
  ASSERT_GT(curve.rows.size(), 5u);
  const std::size_t last = curve.rows.size() - 1;
  EXPECT_GE(curve.num(last, "eps22_shortening"), 0.004);
  const double e0 = curve.num(0, "void_ratio");
  double worst = 0;
  for (std::size_t i = 0; i < curve.rows.size(); ++i) {
    const double ev = curve.num(i, "eps_v_dilation");
    EXPECT_NEAR(curve.num(i, "void_ratio"), (1 + e0) * (1 + ev) - 1, 1e-7) << i;
    if (curve.num(i, "eps22_shortening") > 0.001)
      worst = std::max(worst, std::abs(curve.num(i, "sigma11_Pa") - 1e5) / 1e5);
  }
  EXPECT_LT(worst, 0.02) << "sigma11 held by the width servo";
  EXPECT_GT(curve.num(last, "sigma22_Pa"), 1.2e5) << "the height carries the deviator";
  // Frames: the start, 0.01 %, 0.16 %, 0.2 %, 0.4 % (the end).
  gs::TrajectoryReader tr(dir / "out" / "kb.h5");
  ASSERT_EQ(tr.frame_count(), 5u);
  const double want[] = {0.0, 0.0001, 0.0016, 0.002, 0.004};
  double h0 = 0;
  for (std::size_t i = 0; i < 5; ++i) {
    const auto f = tr.frame(i);
    EXPECT_TRUE(f.two_d);
    EXPECT_TRUE(f.domain.periodic);
    EXPECT_EQ(f.particles.size(), 150u);
    if (i == 0) h0 = f.domain.cell(1, 1);
    const double e22 = (h0 - f.domain.cell(1, 1)) / h0;
    EXPECT_GE(e22, want[i]) << i;
    EXPECT_LT(e22, want[i] + 1e-5) << i << " (within a few steps of the strain asked for)";
    if (i > 0) {
      EXPECT_EQ(f.domain.velocity_gradient(1, 1), -0.5) << i;  // L22 = −ε̇
    }
  }
  // Void cells of the 0.01 % frame, with the cell's gradient from the file: a torus (Euler 0).
  const auto v = run_cli("analyze voidcells " + (dir / "out" / "kb.h5").string() + " --from 1 -o " +
                             (dir / "cells.h5").string(),
                         dir.path);
  ASSERT_EQ(v.rc, 0) << v.err;
  const hid_t f = H5Fopen((dir / "cells.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  long long euler = -1, faces = 0;
  for (auto [name, out] : {std::pair{"euler", &euler}, std::pair{"faces", &faces}}) {
    const hid_t a = H5Aopen(f, name, H5P_DEFAULT);
    ASSERT_GE(a, 0) << name;
    H5Aread(a, H5T_NATIVE_LLONG, out);
    H5Aclose(a);
  }
  H5Fclose(f);
  EXPECT_EQ(euler, 0);
  EXPECT_GT(faces, 50);
}

TEST(PeriodicBiaxial, BadInputsFailWithOneLine) {
  gs::test::ScratchDir dir("periodic_biaxial_bad");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {scene("", "") + "[cell]\nsize_m = [0.01, 0.01, 0.003]\n",
       "[cell]: the periodic biaxial test makes its own cell; remove [cell]"},
      {replaced(scene(), "uniformity = 1.7", "uniformity = 3.5"), "specimen.uniformity"},
      {scene("two_d = \"rods\"\n"), "specimen.two_d: expected \"disks\" or \"spheres_in_plane\""},
      {replaced(scene(), "max_strain = 0.004", "max_strain = 2.0"), "biaxial_periodic.max_strain"},
      {replaced(scene(), "count = 150", "count = 2"), "specimen.count: must be at least 3"},
      {replaced(scene(), "[specimen]", "[nothing]"), "[nothing]: unknown section"},
      {replaced(scene(), "test = \"biaxial_periodic\"", "test = \"triaxial\""),
       "specimen.count: unknown key"},
      {replaced(scene(), "frame_strains = [0.0001, 0.0016]", "frame_strains = [0.001, -1]"),
       "biaxial_periodic.frame_strains"},
      {scene("", "servo_fraction = 1.5\n"), "biaxial_periodic.servo_fraction: must be at most 1"},
      {scene("size_m = [0.01, 0.01, 0.01]\n"), "specimen.size_m: unknown key"},
      {scene("thickness_m = 0.001\n"), "specimen.thickness_m: not thicker than dmax + skin"},
  };
  gs::test::expect_bad_scenes(dir.path, cases);
}

// Killed once in the preparation and once in the test, resumed: every output equals the
// uninterrupted run's (the cell servo and its base gradient come from the checkpoint).
TEST(PeriodicBiaxial, ResumeIsBitForBitInBothPhases) {
  gs::test::ScratchDir dir("periodic_biaxial_resume");
  std::ofstream(dir / "kb.toml") << scene();
  // (the preparation ends near step 24 600)
  gs::test::expect_resume_bit_for_bit(dir.path, (dir / "kb.toml").string(), {15000, 30000},
                                      {"history.csv", "curve.csv", "preparation.csv"}, "kb.h5");
}
