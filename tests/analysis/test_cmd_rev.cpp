// End-to-end tests of `granoscope analyze rev | shearzone | invariants | fabric | rose | chains
// | walls` on synthetic snapshots with exact answers, their figures (PNG written and not blank),
// and bad input (exit 2, one line, no output file).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "packing_util.hpp"

namespace fs = std::filesystem;
using gs::test::read_attr;
using gs::test::read_doubles;
using gs::test::read_format;
using gs::test::run;

namespace {

constexpr double kPi = std::numbers::pi;

std::string q(const fs::path& p) {
  return p.string();
}

std::size_t lines(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string l; std::getline(in, l);) ++n;
  return n;
}

/// With GS_KEEP_TEST_OUTPUT=DIR the HDF5 outputs are copied there (e.g. to try the figures).
void keep_outputs(const fs::path& dir) {
  const char* keep = std::getenv("GS_KEEP_TEST_OUTPUT");
  if (!keep) return;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".h5")
      fs::copy_file(e.path(), fs::path(keep) / ("rev_cli_" + e.path().filename().string()),
                    fs::copy_options::overwrite_existing);
}

/// `granoscope figures FILE` writes these PNGs, and they are not blank.
void expect_figures(const fs::path& dir, const fs::path& h5, const std::vector<std::string>& png,
                    const std::string& extra = "") {
  const auto out = dir / "figs";
  ASSERT_EQ(run("figures " + q(h5) + " -o " + q(out) + " " + extra, dir / "fig.log"), 0)
      << std::ifstream(dir / "fig.log").rdbuf();
  for (const auto& name : png) {
    const cv::Mat img = cv::imread((out / name).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << name;
    cv::Scalar mean, sd;
    cv::meanStdDev(img, mean, sd);
    EXPECT_GT(sd[0], 10.0) << name << " is blank";
  }
}

TEST(CmdRev, LatticeVoidRatioStressDisplacementAndFigures) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  // Simple-cubic lattice d = 1 mm under isotropic contact forces 3 N (p = 3 MPa) with walls;
  // the second frame is translated by u0.
  const gs::Frame a = gs::test::cubic_lattice(12, 0.5e-3, 3.0, true);
  gs::Frame b = a;
  const Eigen::Vector3d u0(2e-5, -1e-5, 3e-5);
  for (auto& p : b.particles) p.position += u0;
  gs::Trajectory t;
  t.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  ASSERT_EQ(
      run("analyze rev " + q(dir / "run.h5") +
              " --frame 0 --to 1 --region 1.37e-3 1.37e-3 1.37e-3 10.37e-3 10.37e-3 "
              "10.37e-3 -o " +
              q(dir / "rev.h5") + " --vti " + q(dir / "rev.vti") + " --csv " + q(dir / "rev.csv"),
          dir / "log"),
      0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_EQ(read_format(dir / "rev.h5"), "granoscope-rev");
  const auto e = read_doubles(dir / "rev.h5", "/cells/void_ratio");
  ASSERT_EQ(e.size(), 125u);
  for (double x : e) EXPECT_NEAR(x, 6 / kPi - 1, 1e-12);
  const auto p = read_doubles(dir / "rev.h5", "/cells/p");
  for (double x : p) EXPECT_NEAR(x, 3e6, 1e-12 * 3e6);
  const auto s = read_doubles(dir / "rev.h5", "/cells/stress");
  ASSERT_EQ(s.size(), 9 * 125u);
  EXPECT_NEAR(s[8], 3e6, 1e-6);  // sigma_zz of cell 0, compression positive
  const auto u = read_doubles(dir / "rev.h5", "/cells/displacement");
  for (std::size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(u[k], u0[k % 3], 1e-15);
  EXPECT_TRUE(fs::exists(dir / "rev.vti"));
  EXPECT_EQ(lines(dir / "rev.csv"), 126u);
  // A profile along z through the middle: interpolated p = 3 MPa at every point.
  ASSERT_EQ(run("analyze rev " + q(dir / "run.h5") +
                    " --profile 5e-3 5e-3 4e-3 5e-3 5e-3 7e-3 --profile-points 7 --csv " +
                    q(dir / "prof.csv") + " -o " + q(dir / "rev2.h5"),
                dir / "log"),
            0);
  EXPECT_EQ(lines(dir / "prof.csv"), 8u);
  std::ifstream prof(dir / "prof.csv");
  std::string header;
  std::getline(prof, header);
  EXPECT_EQ(header.rfind("distance,point_x,point_y,point_z,void_ratio", 0), 0u) << header;
  // Gaussian coarse-graining on the same region: uniform density and contact stress.
  ASSERT_EQ(run("analyze rev " + q(dir / "run.h5") +
                    " --method gaussian --width-d50 1 --step-d50 0.7 --region 5e-3 5e-3 5e-3 "
                    "6.5e-3 6.5e-3 6.5e-3 -o " +
                    q(dir / "cg.h5"),
                dir / "log"),
            0);
  const auto cp = read_doubles(dir / "cg.h5", "/cells/p");
  for (double x : cp) EXPECT_NEAR(x, 3e6, 2e-4 * 3e6);  // kernel cut-off ripple, see unit test
  expect_figures(dir, dir / "rev.h5", {"rev_stress_zz.png"}, "--field stress_zz");
  // Whole-specimen invariants: Love–Weber and seed 003 eq 14 both give p = 3 MPa, q = 0.
  ASSERT_EQ(run("analyze invariants " + q(dir / "run.h5") + " --frame 0 -o " + q(dir / "i.h5") +
                    " --csv " + q(dir / "i.csv"),
                dir / "log"),
            0);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "p"), 3e6, 1e-6);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "q"), 0.0, 1e-6);
  const auto b14 = read_doubles(dir / "i.h5", "/stress/boundary_eq14");
  EXPECT_NEAR(b14[0], 3e6, 1e-6);
  expect_figures(dir, dir / "i.h5", {"invariants.png"});
  keep_outputs(dir);
  fs::remove_all(dir);
}

TEST(CmdRev, ShearZoneOfAPlaneStrainBand) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  // 4 x 14 cm-like section scaled to d50 = 1 mm: a band at 60 deg to the horizontal.
  const gs::Frame f = gs::test::band_lattice(40, 6, 70, 1e-3, 60.0, 2.5e-3,
                                             Eigen::Vector3d(19.5e-3, 2.5e-3, 34.5e-3));
  gs::Trajectory t;
  t.frames = {f};
  gs::write_hdf5_trajectory(dir / "band.h5", t);
  ASSERT_EQ(run("analyze shearzone " + q(dir / "band.h5") + " -o " + q(dir / "sz.h5") + " --csv " +
                    q(dir / "sz.csv"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_EQ(read_format(dir / "sz.h5"), "granoscope-shearzone");
  EXPECT_NEAR(read_attr(dir / "sz.h5", "/", "inclination_deg"), 60.0, 0.5);
  const double th = read_attr(dir / "sz.h5", "/", "thickness_d50");
  EXPECT_GT(th, 5.0);  // 2 sigma = 5 d50 widened by the REV cell: ~6 d50 (see test_shear_zone)
  EXPECT_LT(th, 7.0);
  EXPECT_NEAR(read_attr(dir / "sz.h5", "/", "thickness_mm"), th, 1e-12);  // d50 = 1 mm
  EXPECT_GT(lines(dir / "sz.csv"), 10u);
  std::ifstream log(dir / "log");
  std::string line;
  std::getline(log, line);
  EXPECT_NE(line.find("inclination 60."), std::string::npos) << line;
  expect_figures(dir, dir / "sz.h5", {"shearzone.png"});
  keep_outputs(dir);
  fs::remove_all(dir);
}

TEST(CmdRev, ContactAnalysesAndFigures) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  const gs::Frame a = gs::test::random_packing(9, 1e-3, 17);
  gs::Frame b = a;
  Eigen::Matrix3d h;
  h << 1.01, 0.002, 0, 0, 0.995, 0.003, 0.001, 0, 0.98;
  for (auto& p : b.particles) p.position = h * p.position;
  gs::Trajectory t;
  t.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const std::string in = q(dir / "run.h5") + " --frame 0 ";
  ASSERT_EQ(run("analyze fabric " + in + "-o " + q(dir / "f.h5") + " --csv " + q(dir / "f.csv"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  const double contacts = read_attr(dir / "f.h5", "/", "contacts");
  EXPECT_NEAR(read_attr(dir / "f.h5", "/", "omega"),
              2 * contacts / read_attr(dir / "f.h5", "/", "particles"), 1e-12);
  ASSERT_EQ(run("analyze rose " + in + "--3d -o " + q(dir / "r.h5") + " --csv " + q(dir / "r.csv"),
                dir / "log"),
            0);
  double sum = 0.0, sum3 = 0.0;
  for (double c : read_doubles(dir / "r.h5", "/rose2d/count")) sum += c;
  for (double c : read_doubles(dir / "r.h5", "/rose3d/count")) sum3 += c;
  EXPECT_DOUBLE_EQ(sum, contacts);  // every particle contact once (n and -n half each)
  EXPECT_DOUBLE_EQ(sum3, contacts);
  EXPECT_EQ(lines(dir / "r.csv"), 37u);
  ASSERT_EQ(run("analyze chains " + in + "-o " + q(dir / "c.h5") + " --vtp " + q(dir / "c.vtp"),
                dir / "log"),
            0);
  EXPECT_TRUE(fs::exists(dir / "c.vtp"));
  EXPECT_GT(read_attr(dir / "c.h5", "/", "strong"), 0.0);
  ASSERT_EQ(run("analyze walls " + in + "-o " + q(dir / "w.h5") + " --csv " + q(dir / "w.csv"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_GT(read_attr(dir / "w.h5", "/", "P"), 0.0);
  EXPECT_GT(read_attr(dir / "w.h5", "/", "G"), 0.0);
  // Deformation gradient of the affine motion between the frames, exactly.
  ASSERT_EQ(run("analyze invariants " + in + "--to 1 -o " + q(dir / "i.h5"), dir / "log"), 0);
  const auto F = read_doubles(dir / "i.h5", "/strain/F");
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(F[static_cast<std::size_t>(k)], h(k / 3, k % 3), 1e-12);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/strain", "eps_v"), 1 - h.determinant(), 1e-12);
  expect_figures(dir, dir / "f.h5", {"fabric.png"});
  expect_figures(dir, dir / "r.h5", {"rose.png", "rose_3d.png"});
  expect_figures(dir, dir / "c.h5", {"chains.png"});
  expect_figures(dir, dir / "w.h5", {"walls.png"});
  keep_outputs(dir);
  fs::remove_all(dir);
}

TEST(CmdRev, BadInputExitsTwoWithOneLine) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  gs::Trajectory t;
  t.frames = {gs::test::cubic_lattice(6, 0.5e-3, 1.0, false)};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const std::string in = q(dir / "run.h5");
  const std::string out = " -o " + q(dir / "o.h5");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"analyze rev " + q(dir / "missing.h5") + out, "missing.h5"},
      {"analyze rev " + in + " --cell-d50 0" + out, "--cell"},
      {"analyze rev " + in + " --cell -1e-3" + out, "--cell"},
      {"analyze rev " + in + " --step nan" + out, "--step"},
      {"analyze rev " + in + " --cell 1" + out, "smaller than one cell"},
      {"analyze rev " + in + " --method voronoi" + out, "--method"},
      {"analyze rev " + in + " --method gaussian --width-d50 -2" + out, "--width"},
      {"analyze rev " + in + " --frame 5" + out, "frame"},
      {"analyze rev " + in + " --slab-origin 0 1 0" + out, "no particle cuts the slab"},
      {"analyze rev " + in + " --profile 0 0 0 1 1 1" + out, "--csv"},
      {"analyze shearzone " + in + " --field shear" + out, "--to"},
      {"analyze fabric " + in + " --region 1 1 1 2 2 2" + out, "empty selection"},
      {"analyze fabric " + in + " --region 0 0 0 -1 1 1" + out, "--region"},
      {"analyze rose " + in + " --bin-deg 7" + out, "--bin-deg"},
      {"analyze chains " + in + " --threshold -3" + out, "--threshold"},
      {"analyze walls " + in + out, "no particle-wall contact"},
      {"analyze walls " + in + " --up 0 0 0" + out, "up"},
      {"analyze invariants --gradient 1 0 0 0 1 0 0 0 -1" + out, "det F"},
      {"analyze invariants --stress 1 0 0 0 nan 0 0 0 1" + out, "--stress"},
  };
  for (const auto& [args, what] : cases) {
    EXPECT_EQ(run(args, dir / "log"), 2) << args;
    std::ifstream log(dir / "log");
    std::string line, rest;
    std::getline(log, line);
    EXPECT_EQ(line.rfind("error: ", 0), 0u) << args << ": " << line;
    EXPECT_NE(line.find(what), std::string::npos) << args << ": " << line;
    EXPECT_FALSE(std::getline(log, rest)) << args << ": " << rest;
    EXPECT_FALSE(fs::exists(dir / "o.h5")) << args;
    fs::remove(dir / "o.h5");
  }
  fs::remove_all(dir);
}

}  // namespace
