// End-to-end tests of `granoscope analyze hhd` and `analyze vortices` on synthetic inputs
// (CSV and RUN.h5): vortex centres come back where they were put, the outputs and figures are
// written, bad input exits 2 with one line.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
  return gs::test::temp_dir("gs_hhd_cli");
}

using gs::test::read_array;
using gs::test::run;
using gs::test::slurp;

// A PNG that exists and is not one flat colour: some byte variety in its image data.
void expect_png_not_blank(const fs::path& p) {
  ASSERT_TRUE(fs::exists(p)) << p;
  const std::string s = slurp(p);
  ASSERT_GT(s.size(), 20000u) << p;  // a blank 1000-px PNG compresses to a few kB
  EXPECT_EQ(s.substr(1, 3), "PNG");
}

Eigen::Vector2d lamb_oseen(const Eigen::Vector2d& x, const Eigen::Vector2d& c, double gamma,
                           double rc) {
  const Eigen::Vector2d d = x - c;
  const double r2 = d.squaredNorm();
  const double ut =
      gamma / (2.0 * std::numbers::pi * std::sqrt(r2)) * (1.0 - std::exp(-r2 / (rc * rc)));
  return ut * Eigen::Vector2d(-d.y(), d.x()) / std::sqrt(r2);
}

// Extrema rows of kind `kind` from the CSV output: (x, y, z, magnitude).
std::vector<std::array<double, 4>> extrema_rows(const fs::path& csv, const std::string& kind) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "kind,node,id,x,y,z,value,magnitude,vx,vy,vz");
  std::vector<std::array<double, 4>> out;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string f[11];
    for (auto& x : f) std::getline(s, x, ',');
    if (f[0] == kind)
      out.push_back({std::stod(f[3]), std::stod(f[4]), std::stod(f[5]), std::stod(f[7])});
  }
  return out;
}

std::array<double, 4> strongest(const std::vector<std::array<double, 4>>& rows) {
  std::array<double, 4> best{0, 0, 0, -1};
  for (const auto& r : rows)
    if (r[3] > best[3]) best = r;
  return best;
}

TEST(CmdHhd, Csv2DVortexPairFiguresAndOutputs) {
  const auto dir = temp_dir();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 0.05);  // a 5 cm square, 2500 points
  const Eigen::Vector2d ccw(0.016, 0.031), cw(0.034, 0.018);
  {
    std::ofstream o(dir / "f.csv");
    o << "# a comment\nx,y,ux,uy,extra\n";
    o.precision(17);
    for (int i = 0; i < 2500; ++i) {
      const Eigen::Vector2d x(u(rng), u(rng));
      const Eigen::Vector2d v =
          1e-6 * (lamb_oseen(x, ccw, 1e-2, 4e-3) + lamb_oseen(x, cw, -1e-2, 4e-3));
      o << x.x() << "," << x.y() << "," << v.x() << "," << v.y() << ",7\n";
    }
  }
  ASSERT_EQ(run("analyze hhd --csv " + (dir / "f.csv").string() + " -o " + (dir / "h.h5").string() +
                    " --vtu " + (dir / "h.vtu").string() + " --extrema " + (dir / "e.csv").string(),
                dir / "log"),
            0)
      << slurp(dir / "log");
  EXPECT_EQ(gs::test::read_format(dir / "h.h5"), "granoscope-hhd");
  EXPECT_TRUE(fs::exists(dir / "h.vtu"));
  const double spacing = 0.05 / std::sqrt(2500.0);
  const auto left = strongest(extrema_rows(dir / "e.csv", "left_vortex"));
  const auto right = strongest(extrema_rows(dir / "e.csv", "right_vortex"));
  EXPECT_LE(std::hypot(left[0] - ccw.x(), left[1] - ccw.y()), spacing);
  EXPECT_LE(std::hypot(right[0] - cw.x(), right[1] - cw.y()), spacing);
  const auto v = read_array<double>(dir / "h.h5", "/nodes/v", H5T_NATIVE_DOUBLE);
  EXPECT_EQ(v.size(), 2500u);  // 2D: v_z only
  ASSERT_EQ(
      run("figures " + (dir / "h.h5").string() + " -o " + (dir / "fig").string(), dir / "log"), 0)
      << slurp(dir / "log");
  expect_png_not_blank(dir / "fig" / "hhd_fields.png");
  if (const char* keep = std::getenv("GS_KEEP_TEST_OUTPUT")) {
    fs::copy_file(dir / "h.h5", fs::path(keep) / "hhd_demo_2d.h5",
                  fs::copy_options::overwrite_existing);
  }
  fs::remove_all(dir);
}

// Two frames whose displacement is a Lamb–Oseen vortex along z through `axis` (3D).
gs::Trajectory vortex_trajectory(int frames, unsigned seed, double amplitude_step) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 0.02);
  gs::Trajectory t;
  gs::Frame a;
  a.time = 0.0;
  for (int i = 0; i < 1500; ++i) {
    gs::Particle p;
    p.id = 5000 - i;
    p.position = Eigen::Vector3d(u(rng), u(rng), u(rng));
    p.radius = 4e-4;
    a.particles.push_back(p);
  }
  t.frames.push_back(a);
  for (int k = 1; k < frames; ++k) {
    gs::Frame b = t.frames.back();
    b.time = k;
    // A vortex whose strength varies from frame to frame, and a slow compression along z.
    const double g = 2e-5 * (1.0 + amplitude_step * std::sin(2.0 * std::numbers::pi * k / 4.0));
    for (auto& p : b.particles) {
      const Eigen::Vector2d d = lamb_oseen(p.position.head<2>(), {0.009, 0.011}, g, 4e-3);
      p.position += Eigen::Vector3d(d.x(), d.y(), -1e-3 * p.position.z());
    }
    t.frames.push_back(b);
  }
  return t;
}

TEST(CmdHhd, Trajectory3DTubesSliceAndSeries) {
  const auto dir = temp_dir();
  const auto traj = vortex_trajectory(10, 4, 0.5);
  gs::write_hdf5_trajectory(dir / "run.h5", traj);
  const std::string run_h5 = (dir / "run.h5").string();
  ASSERT_EQ(
      run("analyze hhd " + run_h5 + " --from 1 --to 2 -o " + (dir / "h.h5").string() + " --tubes " +
              (dir / "t.vtp").string() + " --extrema " + (dir / "e.csv").string() + " --delta 0.2",
          dir / "log"),
      0)
      << slurp(dir / "log");
  const double spacing = 0.02 / std::cbrt(1500.0);
  const auto left = strongest(extrema_rows(dir / "e.csv", "left_vortex"));
  EXPECT_LE(std::hypot(left[0] - 0.009, left[1] - 0.011), spacing);
  EXPECT_TRUE(fs::exists(dir / "t.vtp"));
  // δ = 0: every centre is a one-node tube; the VTP then holds no line (and is still written).
  ASSERT_EQ(run("analyze hhd " + run_h5 + " --from 1 --to 2 -o " + (dir / "h0.h5").string() +
                    " --tubes " + (dir / "t0.vtp").string() + " --delta 0",
                dir / "log"),
            0)
      << slurp(dir / "log");
  EXPECT_NE(slurp(dir / "t0.vtp").find("NumberOfLines=\"0\""), std::string::npos);
  EXPECT_GT(read_array<std::int64_t>(dir / "h.h5", "/tubes/offsets", H5T_NATIVE_INT64).size(), 1u);
  ASSERT_EQ(
      run("figures " + (dir / "h.h5").string() + " -o " + (dir / "fig").string(), dir / "log"), 0)
      << slurp(dir / "log");
  expect_png_not_blank(dir / "fig" / "hhd_tubes_3d.png");
  // Slice mode: a 5 d50 slab at mid-depth projected on x-y -> 2D, the same vortex.
  ASSERT_EQ(run("analyze hhd " + run_h5 + " --from 1 --to 2 --slice --solver bicgstab -o " +
                    (dir / "s.h5").string() + " --extrema " + (dir / "s.csv").string(),
                dir / "log"),
            0)
      << slurp(dir / "log");
  const auto sl = strongest(extrema_rows(dir / "s.csv", "left_vortex"));
  // In-plane coordinates are relative to the slab origin, the centre of the spheres' box.
  const auto [lo, hi] = gs::particle_bounds(traj.frames[1]);
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  EXPECT_LE(std::hypot(sl[0] - (0.009 - mid.x()), sl[1] - (0.011 - mid.y())), spacing);
  // With ghost nodes (paper defaults scaled to d50 = 0.8 mm, width 2 cm, coarser here).
  ASSERT_EQ(run("analyze hhd " + run_h5 +
                    " --from 1 --to 2 --ghosts --ghost-extent 0.004 "
                    "--ghost-spacing 0.0025 -o " +
                    (dir / "g.h5").string(),
                dir / "log"),
            0)
      << slurp(dir / "log");
  const auto ghost = read_array<std::uint8_t>(dir / "g.h5", "/nodes/ghost", H5T_NATIVE_UINT8);
  std::size_t ng = 0;
  for (auto g : ghost) ng += g;
  EXPECT_GT(ng, 100u);
  // Series over the trajectory: counts per increment, spectrum against strain.
  ASSERT_EQ(
      run("analyze vortices " + run_h5 + " --every 1 -o " + (dir / "v.h5").string(), dir / "log"),
      0)
      << slurp(dir / "log");
  EXPECT_EQ(gs::test::read_format(dir / "v.h5"), "granoscope-vortices");
  const auto strain = read_array<double>(dir / "v.h5", "/series/strain", H5T_NATIVE_DOUBLE);
  const auto lefts = read_array<std::int32_t>(dir / "v.h5", "/series/left", H5T_NATIVE_INT32);
  ASSERT_EQ(strain.size(), 9u);
  EXPECT_EQ(strain[0], 0.0);
  // Strain = relative shortening of the spheres' extent along z (centres ± r) from frame 0.
  const auto height = [&](std::size_t k) {
    const auto [lo, hi] = gs::particle_bounds(traj.frames[k]);
    return hi.z() - lo.z();
  };
  for (std::size_t i = 1; i < strain.size(); ++i) {
    EXPECT_NEAR(strain[i], 1.0 - height(i) / height(0), 1e-14);
    EXPECT_GT(strain[i], strain[i - 1]);
  }
  for (auto l : lefts) EXPECT_GE(l, 1);
  EXPECT_EQ(read_array<double>(dir / "v.h5", "/spectrum/left/period", H5T_NATIVE_DOUBLE).size(),
            4u);
  ASSERT_EQ(run("figures " + (dir / "v.h5").string() + " -o " + (dir / "fv").string(), dir / "log"),
            0)
      << slurp(dir / "log");
  expect_png_not_blank(dir / "fv" / "vortices_counts.png");
  expect_png_not_blank(dir / "fv" / "vortices_spectrum.png");
  fs::remove_all(dir);
}

// One line "error: ..." naming `part`, exit 2, no output file.
void expect_rejected(const std::string& args, const fs::path& dir, const std::string& part) {
  EXPECT_EQ(run(args + " -o " + (dir / "o.h5").string(), dir / "log"), 2) << args;
  const std::string log = slurp(dir / "log");
  EXPECT_EQ(log.rfind("error: ", 0), 0u) << log;
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  EXPECT_NE(log.find(part), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "o.h5"));
}

TEST(CmdHhd, BadInputExitsTwoWithOneLine) {
  const auto dir = temp_dir();
  const auto csv = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return "analyze hhd --csv " + (dir / name).string();
  };
  expect_rejected("analyze hhd " + (dir / "missing.h5").string(), dir, "missing.h5");
  expect_rejected(csv("nan.csv", "x,y,ux,uy\n0,0,1,1\n1,0,nan,1\n0,1,1,1\n1,1,0,0\n"), dir,
                  "line 3: non-finite value in ux");
  expect_rejected(csv("col.csv", "x,y,z,ux,uy\n0,0,0,1,1\n"), dir, "missing column in header (uz)");
  expect_rejected(csv("short.csv", "x,y,ux,uy\n0,0,1,1\n1,0\n"), dir, "line 3: expected 4 fields");
  expect_rejected(csv("few.csv", "x,y,ux,uy\n0,0,1,1\n1,0,1,1\n"), dir, "at least 3 points");
  expect_rejected(csv("line.csv", "x,y,ux,uy\n0,0,1,1\n1,1,1,1\n2,2,1,1\n3,3,0,0\n"), dir,
                  "collinear");
  expect_rejected(csv("flat.csv",
                      "x,y,z,ux,uy,uz\n0,0,0,1,1,1\n1,0,0,1,1,1\n0,1,0,1,1,1\n1,1,0,1,1,1\n"
                      "2,1,0,1,1,1\n"),
                  dir, "coplanar");
  expect_rejected(
      csv("dup.csv", "x,y,ux,uy\n0,0,1,1\n1,0,1,1\n0,1,1,1\n1,1,1,1\n0.5,0.5,0,0\n1,0,2,2\n"), dir,
      "duplicate particle centres (points 1 and 5)");
  expect_rejected(csv("ok.csv", "x,y,ux,uy\n0,0,1,1\n1,0,1,1\n0,1,1,1\n1,1,1,1\n0.5,0.4,0,0\n") +
                      " --solver gmres",
                  dir, "unknown solver");
  expect_rejected(
      csv("ok2.csv", "x,y,ux,uy\n0,0,1,1\n1,0,1,1\n0,1,1,1\n1,1,1,1\n0.5,0.4,0,0\n") + " --ghosts",
      dir, "give --d50");
  gs::write_hdf5_trajectory(dir / "run.h5", vortex_trajectory(2, 5, 0.0));
  const std::string run_h5 = (dir / "run.h5").string();
  expect_rejected("analyze hhd " + run_h5 + " --to 7", dir, "target frame out of range 0..1 (7)");
  expect_rejected("analyze hhd " + run_h5 + " --csv " + (dir / "ok.csv").string(), dir,
                  "either RUN.h5 or --csv");
  expect_rejected("analyze vortices " + run_h5 + " --every 3", dir, "no frame pair");
  fs::remove_all(dir);
}

}  // namespace
