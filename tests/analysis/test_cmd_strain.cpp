// End-to-end tests of `granoscope analyze strain` / `analyze voidcells` on synthetic RUN.h5
// files: exact affine answers come back through the HDF5 outputs; bad input exits 2.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>

#include "cli_test_util.hpp"
#include "hdf5_trajectory.hpp"
#include "tet_strain.hpp"

namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
  return gs::test::cli_temp_dir("gs_strain_cli");
}

int run(const std::string& args, const fs::path& log) {
  return gs::test::run_granoscope(args, log);
}

using gs::test::read_h5_doubles;
using gs::test::read_h5_format;

TEST(CmdStrain, ThreeDAffineBetweenFramesMatchedById) {
  const auto dir = temp_dir();
  gs::Trajectory t;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 0.01);
  gs::Frame a;
  for (int i = 0; i < 300; ++i) {
    gs::Particle p;
    p.id = 1000 - i;
    p.position = Eigen::Vector3d(u(rng), u(rng), u(rng));
    p.radius = 2e-4;
    a.particles.push_back(p);
  }
  Eigen::Matrix3d h;
  h << 0.01, 0.002, 0, -0.003, -0.02, 0, 0.004, 0.001, 0.005;  // in-plane part independent of z
  gs::Frame b = a;
  b.time = 1.0;
  for (auto& p : b.particles) p.position += h * p.position;
  std::reverse(b.particles.begin(), b.particles.end());  // matched by id, not by order
  b.particles.pop_back();                                // one particle gone
  t.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  ASSERT_EQ(run("analyze strain " + (dir / "run.h5").string() + " --to 1 -o " +
                    (dir / "s.h5").string() + " --vtu " + (dir / "s.vtu").string(),
                dir / "log"),
            0);
  EXPECT_EQ(read_h5_format(dir / "s.h5"), "granoscope-strain");
  const auto mean = read_h5_doubles(dir / "s.h5", "/mean_gradient");
  ASSERT_EQ(mean.size(), 9u);
  for (int i = 0; i < 9; ++i)
    EXPECT_NEAR(mean[static_cast<std::size_t>(i)], h(i / 3, i % 3), 1e-14);
  EXPECT_EQ(read_h5_doubles(dir / "s.h5", "/particles/volumetric_strain").size(), 299u);
  EXPECT_TRUE(fs::exists(dir / "s.vtu"));
  // Slab |z - 5 mm| <= 2 mm projected onto x-y: triangles, in-plane block of h (seed 000 §5).
  ASSERT_EQ(run("analyze strain " + (dir / "run.h5").string() +
                    " --to 1 --slab-origin 0 0 0.005 --slab-normal 0 0 1 --slab-axis 1 0 0"
                    " --slab-thickness 0.004 -o " +
                    (dir / "p.h5").string(),
                dir / "log"),
            0);
  const auto m2 = read_h5_doubles(dir / "p.h5", "/mean_gradient");
  for (int i = 0; i < 9; ++i) {
    const double expect = (i / 3 < 2 && i % 3 < 2) ? h(i / 3, i % 3) : 0.0;
    EXPECT_NEAR(m2[static_cast<std::size_t>(i)], expect, 1e-14) << i;
  }
  const auto n2 = read_h5_doubles(dir / "p.h5", "/particles/volumetric_strain").size();
  EXPECT_GT(n2, 60u);
  EXPECT_LT(n2, 180u);
  if (const char* keep = std::getenv("GS_KEEP_TEST_OUTPUT")) {  // e.g. to try the figures
    fs::copy_file(dir / "s.h5", fs::path(keep) / "strain_demo.h5",
                  fs::copy_options::overwrite_existing);
    fs::copy_file(dir / "s.vtu", fs::path(keep) / "strain_demo.vtu",
                  fs::copy_options::overwrite_existing);
  }
  fs::remove_all(dir);
}

TEST(CmdStrain, VoidCellsPeriodic2DFromVelocities) {
  const auto dir = temp_dir();
  // Periodic 2D frame, contacts = short Delaunay edges of 3 x 3 replicated points.
  const double side = 0.01;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, side);
  gs::Frame f;
  f.two_d = true;
  f.domain.periodic = true;
  f.domain.hi = Eigen::Vector3d(side, side, 0);
  f.domain.cell = Eigen::Vector3d(side, side, 1).asDiagonal();
  const std::size_t n = 300;
  Eigen::Matrix2d l;
  l << 0.0, 0.02, -0.01, 0.005;
  std::vector<Eigen::Vector2d> all;
  std::vector<std::int64_t> owner;
  for (std::size_t i = 0; i < n; ++i) {
    gs::Particle p;
    p.id = static_cast<std::int64_t>(i);
    p.position = Eigen::Vector3d(u(rng), u(rng), 0);
    p.radius = 2.5e-4;
    p.velocity.head<2>() = l * p.position.head<2>();
    f.particles.push_back(p);
  }
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i)
      for (std::size_t k = 0; k < n; ++k) {
        all.push_back(f.particles[k].position.head<2>() + side * Eigen::Vector2d(i, j));
        owner.push_back(static_cast<std::int64_t>(k));
      }
  std::set<std::pair<std::int64_t, std::int64_t>> pairs;
  for (const auto& tri : gs::analysis::delaunay_triangles(all))
    for (int a = 0; a < 3; ++a) {
      const auto p = static_cast<std::size_t>(tri[static_cast<std::size_t>(a)]);
      const auto q = static_cast<std::size_t>(tri[static_cast<std::size_t>((a + 1) % 3)]);
      if ((all[p] - all[q]).norm() < 1.4 * side / std::sqrt(double(n)))
        pairs.emplace(std::min(owner[p], owner[q]), std::max(owner[p], owner[q]));
    }
  for (auto [a, b] : pairs) {
    gs::Contact c;
    c.id1 = a;
    c.id2 = b;
    f.contacts.push_back(c);
  }
  gs::Trajectory t;
  t.frames = {f};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  // Velocities in a fixed periodic cell (images move with their particle): the command runs
  // and writes its format; exact affine answers through displacements between frames below.
  ASSERT_EQ(run("analyze voidcells " + (dir / "run.h5").string() + " -o " + (dir / "v.h5").string(),
                dir / "log"),
            0);
  EXPECT_EQ(read_h5_format(dir / "v.h5"), "granoscope-voidcells");
  // With the cell velocity gradient l the image velocities are consistent: exact l per cell.
  ASSERT_EQ(run("analyze voidcells " + (dir / "run.h5").string() +
                    " --cell-velocity-gradient 0 0.02 -0.01 0.005 -o " + (dir / "vl.h5").string(),
                dir / "log"),
            0);
  const auto gl = read_h5_doubles(dir / "vl.h5", "/cells/gradient");
  ASSERT_GT(gl.size(), 40u);
  for (std::size_t i = 0; i < gl.size(); ++i) {
    EXPECT_NEAR(gl[i], l((i % 4) / 2, i % 2), 1e-12 * l.norm()) << i;
  }
  // Two frames: the cell deforms with l, particles follow affinely -> every cell has gradient l.
  gs::Frame g = f;
  for (auto& p : g.particles) p.position.head<2>() += l * p.position.head<2>();
  g.domain.cell.topLeftCorner<2, 2>() += l * f.domain.cell.topLeftCorner<2, 2>();
  t.frames = {f, g};
  gs::write_hdf5_trajectory(dir / "run2.h5", t);
  ASSERT_EQ(run("analyze voidcells " + (dir / "run2.h5").string() + " --to 1 -o " +
                    (dir / "v2.h5").string(),
                dir / "log"),
            0);
  const auto grad = read_h5_doubles(dir / "v2.h5", "/cells/gradient");
  ASSERT_GT(grad.size(), 40u);
  // The displacement is rebuilt from stored positions (x_B - x_A): its rounding, eps |x|, is
  // ~1e-13 of a cell's relative displacement |l| h, amplified in thin cells. The method itself is
  // tested at 1e-12 on exact velocities in test_kuhn_void_cells.cpp; this checks the plumbing.
  for (std::size_t i = 0; i < grad.size(); ++i) {
    EXPECT_NEAR(grad[i], l((i % 4) / 2, i % 2), 1e-10 * l.norm()) << i;
  }
  const auto alpha = read_h5_doubles(dir / "v2.h5", "/cells/alpha");
  for (double a : alpha) EXPECT_NEAR(a, 1.0, 1e-10);
  // Non-affine motion for the figures: random particle jitter on top of l.
  std::normal_distribution<double> jitter(0.0, 2e-6);
  for (auto& p : t.frames[1].particles)
    p.position.head<2>() += Eigen::Vector2d(jitter(rng), jitter(rng));
  gs::write_hdf5_trajectory(dir / "run3.h5", t);
  ASSERT_EQ(run("analyze voidcells " + (dir / "run3.h5").string() + " --to 1 -o " +
                    (dir / "v3.h5").string() + " --vtu " + (dir / "v3.vtu").string(),
                dir / "log"),
            0);
  EXPECT_TRUE(fs::exists(dir / "v3.vtu"));
  const auto w = read_h5_doubles(dir / "v3.h5", "/cells/w");
  for (double x : w) EXPECT_TRUE(std::isfinite(x));
  // The triangle (Bagi eq 4) variant of the same motion: 2D strain with alpha and w.
  ASSERT_EQ(
      run("analyze strain " + (dir / "run3.h5").string() + " --to 1 -o " + (dir / "t3.h5").string(),
          dir / "log"),
      0);
  EXPECT_EQ(read_h5_doubles(dir / "t3.h5", "/simplices/alpha").size(),
            read_h5_doubles(dir / "t3.h5", "/simplices/measure").size());
  if (const char* keep = std::getenv("GS_KEEP_TEST_OUTPUT")) {  // e.g. to try the figures
    fs::copy_file(dir / "v3.h5", fs::path(keep) / "voidcells_demo.h5",
                  fs::copy_options::overwrite_existing);
    fs::copy_file(dir / "t3.h5", fs::path(keep) / "triangles_demo.h5",
                  fs::copy_options::overwrite_existing);
    fs::copy_file(dir / "v3.vtu", fs::path(keep) / "voidcells_demo.vtu",
                  fs::copy_options::overwrite_existing);
  }
  fs::remove_all(dir);
}

TEST(CmdStrain, BadInputExitsTwoWithOneLine) {
  const auto dir = temp_dir();
  EXPECT_EQ(
      run("analyze strain " + (dir / "missing.h5").string() + " -o " + (dir / "o.h5").string(),
          dir / "log"),
      2);
  std::ifstream in(dir / "log");
  std::string line, rest;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("error: ", 0), 0u) << line;
  EXPECT_NE(line.find("missing.h5"), std::string::npos);
  EXPECT_FALSE(std::getline(in, rest));
  EXPECT_FALSE(fs::exists(dir / "o.h5"));
  // A 3D frame given to voidcells, and a coplanar 3D frame given to strain.
  gs::Frame f;
  for (int i = 0; i < 10; ++i) {
    gs::Particle p;
    p.id = i;
    p.position = Eigen::Vector3d(i % 4, i / 4, 0) * 1e-3;
    p.radius = 1e-4;
    f.particles.push_back(p);
  }
  gs::Trajectory t;
  t.frames = {f};
  gs::write_hdf5_trajectory(dir / "flat.h5", t);
  EXPECT_EQ(
      run("analyze voidcells " + (dir / "flat.h5").string() + " -o " + (dir / "o.h5").string(),
          dir / "log"),
      2);
  EXPECT_EQ(run("analyze strain " + (dir / "flat.h5").string() + " -o " + (dir / "o.h5").string(),
                dir / "log"),
            2);
  std::ifstream in2(dir / "log");
  std::getline(in2, line);
  EXPECT_NE(line.find("coplanar"), std::string::npos) << line;
  EXPECT_EQ(
      run("analyze strain " + (dir / "flat.h5").string() + " --to 7 -o " + (dir / "o.h5").string(),
          dir / "log"),
      2);
  EXPECT_FALSE(fs::exists(dir / "o.h5"));
  fs::remove_all(dir);
}

}  // namespace
