// End-to-end tests of `granoscope analyze hhd` and `analyze vortices` on synthetic inputs
// (CSV and RUN.h5): vortex centres come back where they were put, the outputs and figures are
// written, bad input exits 2 with one line.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <utility>

#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "hhd_test_fields.hpp"

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

// Extrema rows of kind `kind` from the CSV output: (x, y, z, magnitude, significant).
std::vector<std::array<double, 5>> extrema_rows(const fs::path& csv, const std::string& kind) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "kind,node,id,x,y,z,value,magnitude,vx,vy,vz,significant");
  std::vector<std::array<double, 5>> out;
  while (std::getline(in, line)) {
    std::stringstream s(line);
    std::string f[12];
    for (auto& x : f) std::getline(s, x, ',');
    if (f[0] == kind) {
      out.push_back(
          {std::stod(f[3]), std::stod(f[4]), std::stod(f[5]), std::stod(f[7]), std::stod(f[11])});
    }
  }
  return out;
}

std::array<double, 5> strongest(const std::vector<std::array<double, 5>>& rows) {
  std::array<double, 5> best{0, 0, 0, -1, 0};
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
  // The VTU holds the mesh of the HDF5 output: the 2500 points, its triangles, the same u.
  const auto tri = read_array<std::int32_t>(dir / "h.h5", "/simplices/vertices", H5T_NATIVE_INT32);
  const std::string piece = gs::test::xml_tag(dir / "h.vtu", "Piece");
  EXPECT_EQ(gs::test::xml_number(piece, "NumberOfPoints"), 2500.0);
  EXPECT_EQ(gs::test::xml_number(piece, "NumberOfCells"), double(tri.size() / 3));
  const auto pu = read_array<double>(dir / "h.h5", "/nodes/u", H5T_NATIVE_DOUBLE);
  const auto [ulo, uhi] = gs::test::vtk_range(dir / "h.vtu", "PointData", "u");
  EXPECT_EQ(ulo, *std::min_element(pu.begin(), pu.end()));
  EXPECT_EQ(uhi, *std::max_element(pu.begin(), pu.end()));
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
  // The VTP: one polyline per tube of two or more nodes (/tubes/offsets).
  const auto off = read_array<std::int64_t>(dir / "h.h5", "/tubes/offsets", H5T_NATIVE_INT64);
  std::size_t long_tubes = 0, tube_nodes = 0;
  for (std::size_t k = 0; k + 1 < off.size(); ++k)
    if (off[k + 1] - off[k] >= 2) ++long_tubes, tube_nodes += std::size_t(off[k + 1] - off[k]);
  EXPECT_GT(long_tubes, 0u);
  const std::string tubes = gs::test::xml_tag(dir / "t.vtp", "Piece");
  EXPECT_EQ(gs::test::xml_number(tubes, "NumberOfLines"), double(long_tubes));
  EXPECT_EQ(gs::test::xml_number(tubes, "NumberOfPoints"), double(tube_nodes));
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
  const auto lefts_all =
      read_array<std::int32_t>(dir / "v.h5", "/series/left_all", H5T_NATIVE_INT32);
  ASSERT_EQ(lefts_all.size(), lefts.size());
  for (std::size_t i = 0; i < lefts.size(); ++i) EXPECT_GE(lefts_all[i], lefts[i]);
  EXPECT_EQ(read_array<double>(dir / "v.h5", "/spectrum/left/period", H5T_NATIVE_DOUBLE).size(),
            4u);
  ASSERT_EQ(run("figures " + (dir / "v.h5").string() + " -o " + (dir / "fv").string(), dir / "log"),
            0)
      << slurp(dir / "log");
  expect_png_not_blank(dir / "fv" / "vortices_counts.png");
  expect_png_not_blank(dir / "fv" / "vortices_spectrum.png");
  fs::remove_all(dir);
}

TEST(CmdHhd, PeriodicBoundaryCrossingIsTheMinimumImage) {
  // 400 particles in a periodic 1 cm cell, frame 1 = frame 0 translated by t (4-7 % of the cell)
  // with the particles that left the cell wrapped back (a jump of ~ one cell length). Exact
  // answer: the minimum-image displacement is t at every node, and the decomposition of a
  // uniform field on the mesh is all harmonic (the P1 load of a constant field vanishes at every
  // interior node): u = 0, v = 0, grad u = curl v = 0, h = t in every simplex, to round-off.
  // The same frames read as non-periodic give jumps of a cell length (the check is not vacuous).
  const auto dir = temp_dir();
  const double side = 0.01;
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(0.0, side);
  gs::Frame a;
  a.domain.periodic = true;
  a.domain.hi = Eigen::Vector3d::Constant(side);
  a.domain.cell = side * Eigen::Matrix3d::Identity();
  for (int i = 0; i < 400; ++i) {
    gs::Particle p;
    p.id = 3 * i + 1;
    p.position = Eigen::Vector3d(u(rng), u(rng), u(rng));
    p.radius = 3e-4;
    a.particles.push_back(p);
  }
  const Eigen::Vector3d t(0.04 * side, -0.07 * side, 0.05 * side);
  gs::Frame b = a;
  std::size_t wrapped = 0;
  for (auto& p : b.particles) {
    p.position += t;
    for (int k = 0; k < 3; ++k) {
      const double w = std::floor(p.position[k] / side);
      p.position[k] -= w * side;
      wrapped += w != 0.0;
    }
  }
  EXPECT_GT(wrapped, 50u);
  gs::Trajectory tr;
  tr.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", tr);
  ASSERT_EQ(
      run("analyze hhd " + (dir / "run.h5").string() + " --to 1 -o " + (dir / "h.h5").string(),
          dir / "log"),
      0)
      << slurp(dir / "log");
  const auto vec = read_array<double>(dir / "h.h5", "/nodes/vector", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(vec.size(), 3u * 400u);
  double worst = 0.0;
  for (std::size_t k = 0; k < vec.size(); ++k) worst = std::max(worst, std::abs(vec[k] - t[k % 3]));
  EXPECT_LE(worst, 1e-17);  // x_b - x_a of stored positions ~ 1 cm: rounding 2e-18
  // Potentials and parts relative to |t|: round-off of the P1 sums (eps |t| L per node, measured
  // 7e-17 |t| L) and of their gradients on the simplices (measured 2e-15 |t|).
  const double tn = t.norm();
  for (const char* name : {"/nodes/u", "/nodes/v"}) {
    double m = 0.0;
    for (double x : read_array<double>(dir / "h.h5", name, H5T_NATIVE_DOUBLE))
      m = std::max(m, std::abs(x));
    EXPECT_LE(m, 1e-15 * tn * side) << name;
    std::printf("%s: max |.| = %.3g |t| L\n", name, m / (tn * side));
  }
  const auto hh = read_array<double>(dir / "h.h5", "/simplices/harmonic", H5T_NATIVE_DOUBLE);
  const auto gu = read_array<double>(dir / "h.h5", "/simplices/grad_u", H5T_NATIVE_DOUBLE);
  const auto cv = read_array<double>(dir / "h.h5", "/simplices/curl_v", H5T_NATIVE_DOUBLE);
  const auto measure = read_array<double>(dir / "h.h5", "/simplices/measure", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(hh.size(), 3 * measure.size());
  double worst_h = 0.0, worst_g = 0.0;
  for (std::size_t s = 0; s < measure.size(); ++s) {
    if (!(measure[s] > 0.0)) continue;  // flat in floating point: no part in the decomposition
    for (std::size_t k = 0; k < 3; ++k) {
      worst_h = std::max(worst_h, std::abs(hh[3 * s + k] - t[k]));
      worst_g = std::max({worst_g, std::abs(gu[3 * s + k]), std::abs(cv[3 * s + k])});
    }
  }
  std::printf("max |h - t| = %.3g |t|, max |grad u|, |curl v| = %.3g |t|\n", worst_h / tn,
              worst_g / tn);
  EXPECT_LE(worst_h, 1e-13 * tn);
  EXPECT_LE(worst_g, 1e-13 * tn);
  // Not periodic: the wrapped particles jump by about a cell length.
  for (auto* f : {&tr.frames[0], &tr.frames[1]}) f->domain.periodic = false;
  gs::write_hdf5_trajectory(dir / "plain.h5", tr);
  ASSERT_EQ(
      run("analyze hhd " + (dir / "plain.h5").string() + " --to 1 -o " + (dir / "p.h5").string(),
          dir / "log"),
      0)
      << slurp(dir / "log");
  double jump = 0.0;
  for (double x : read_array<double>(dir / "p.h5", "/nodes/vector", H5T_NATIVE_DOUBLE))
    jump = std::max(jump, std::abs(x));
  EXPECT_GT(jump, 0.9 * side);
  fs::remove_all(dir);
}

// `n` uniformly random points in [0, side)^dim (seeded) and field(point) as a CSV with header
// x,y[,z],ux,uy[,uz] (2D: the field's z is dropped).
template <class Field>
void write_field_csv(const fs::path& path, int dim, int n, unsigned seed, double side,
                     Field field) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, side);
  std::ofstream o(path);
  o << (dim == 3 ? "x,y,z,ux,uy,uz\n" : "x,y,ux,uy\n");
  o.precision(17);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    if (dim == 3) {
      x = Eigen::Vector3d(u(rng), u(rng), u(rng));
    } else {
      const Eigen::Vector2d x2(u(rng), u(rng));
      x.head<2>() = x2;
    }
    const Eigen::Vector3d v = field(x);
    o << x.x() << "," << x.y() << ",";
    if (dim == 3) o << x.z() << ",";
    o << v.x() << "," << v.y();
    if (dim == 3) o << "," << v.z();
    o << "\n";
  }
}

TEST(CmdHhd, ToleranceOfTheIterativeSolver) {
  // --solver cg --tolerance TOL: each system stops at the relative residual ||K u - b|| / ||b||
  // <= TOL (Eigen's CG criterion), so the eq 17 residual the command reports is at most TOL,
  // and a tighter tolerance takes more iterations and ends with a smaller residual.
  const auto dir = temp_dir();
  write_field_csv(dir / "f.csv", 2, 800, 9, 0.05, [](const Eigen::Vector3d& p) {
    const Eigen::Vector2d x = p.head<2>();
    const Eigen::Vector2d v = 1e-6 * (lamb_oseen(x, {0.02, 0.03}, 1e-2, 5e-3) +
                                      Eigen::Vector2d(x.x() - 0.025, 0.5 * (x.y() - 0.02)));
    return Eigen::Vector3d(v.x(), v.y(), 0.0);
  });
  double last_residual = 1.0, last_iterations = 0.0;
  for (const double tol : {1e-3, 1e-6, 1e-12}) {
    SCOPED_TRACE(tol);
    const auto out = dir / "h.h5";
    char opt[64];
    std::snprintf(opt, sizeof opt, " --solver cg --tolerance %.0e", tol);
    ASSERT_EQ(run("analyze hhd --csv " + (dir / "f.csv").string() + opt + " -o " + out.string(),
                  dir / "log"),
              0)
        << slurp(dir / "log");
    EXPECT_EQ(gs::test::read_attr(out, "/", "converged"), 1.0);
    const double res = gs::test::read_attr(out, "/", "residual_eq17");
    const double it = gs::test::read_attr(out, "/", "iterations_u");
    std::printf("tolerance %.0e: residual eq 17 %.3g in %.0f iterations\n", tol, res, it);
    EXPECT_LE(res, tol);
    EXPECT_LT(res, last_residual);
    EXPECT_GT(it, last_iterations);
    last_residual = res;
    last_iterations = it;
    fs::remove(out);
  }
  fs::remove_all(dir);
}

TEST(CmdHhd, ProjectionDefaultAndSignificantExtrema3D) {
  // Issue 20's field (vortex across the hull + Gaussian source + translation) on 1 500 random
  // points: the default 3D solver is eq 18's projection, with orthogonal parts; one source is
  // counted, though u has many noise-level strict extrema (all in the CSV, flagged).
  const auto dir = temp_dir();
  write_field_csv(dir / "f.csv", 3, 1500, 12, 1.0, gs::test::vortex_source_translation);
  const auto analyze = [&](const std::string& extra) {
    const std::string cmd = "analyze hhd --csv " + (dir / "f.csv").string() + " -o " +
                            (dir / "h.h5").string() + " --extrema " + (dir / "e.csv").string() +
                            extra;
    EXPECT_EQ(run(cmd, dir / "log"), 0) << slurp(dir / "log");
    return slurp(dir / "log");
  };
  std::string log = analyze("");
  EXPECT_NE(log.find("solver projection"), std::string::npos) << log;
  const auto h5 = dir / "h.h5";
  EXPECT_EQ(gs::test::read_attr(h5, "/", "tolerance"), 1e-7);
  const double dch = gs::test::read_attr(h5, "/", "dot_curl_harmonic");
  const double nc = gs::test::read_attr(h5, "/", "norm_curl_v");
  const double nh = gs::test::read_attr(h5, "/", "norm_harmonic");
  EXPECT_LT(std::abs(dch) / (nc * nh), 1e-8);
  const auto sources = extrema_rows(dir / "e.csv", "source");
  const auto sinks = extrema_rows(dir / "e.csv", "sink");
  const auto src = strongest(sources);
  EXPECT_LT((Eigen::Vector3d(src[0], src[1], src[2]) - Eigen::Vector3d(0.3, 0.6, 0.4)).norm(),
            2.0 / std::cbrt(1500.0));
  // The flag is the rule: magnitude >= 5 % of the strongest source or sink.
  double top = 0.0;
  std::size_t significant = 0;
  for (const auto* rows : {&sources, &sinks})
    for (const auto& r : *rows) top = std::max(top, r[3]);
  for (const auto* rows : {&sources, &sinks})
    for (const auto& r : *rows) {
      EXPECT_EQ(r[4], r[3] >= 0.05 * top ? 1.0 : 0.0);
      significant += r[4] == 1.0 ? 1 : 0;
    }
  EXPECT_EQ(significant, 1u);
  EXPECT_GT(sources.size() + sinks.size(), 10u);  // the noise extrema are still reported
  const auto sig = read_array<std::uint8_t>(h5, "/extrema/significant", H5T_NATIVE_UINT8);
  EXPECT_EQ(std::count(sig.begin(), sig.end(), 1), 2);  // the source and the vortex
  char expect[128];
  std::snprintf(expect, sizeof expect, "sources 1, sinks 0");
  EXPECT_NE(log.find(expect), std::string::npos) << log;
  // --significance 0 counts every strict extremum; an absolute floor above the source none.
  log = analyze(" --significance 0");
  std::snprintf(expect, sizeof expect, "sources %zu, sinks %zu", sources.size(), sinks.size());
  EXPECT_NE(log.find(expect), std::string::npos) << log;
  log = analyze(" --significance-abs " + std::to_string(2.0 * src[3]));
  EXPECT_NE(log.find("sources 0, sinks 0"), std::string::npos) << log;
  fs::remove_all(dir);
}

TEST(CmdHhd, DemIncrementPartsOrthogonalWithTheDefault) {
  // Issue 20's acceptance on a DEM increment: the plane-strain demo (the shipped tiny scene,
  // loaded to 4 % strain), its last increment decomposed in 3D. The default (eq 18's
  // projection) gives cos(∇×v, h) and cos(∇u, h) below 1e-8; path (b) does not (so the check
  // can fail) and its ∇u is the same.
  const auto dir = temp_dir();
  std::string scene = slurp(fs::path(GS_TEST_DATA_DIR) / "scenes" / "plane_strain_tiny.toml");
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"max_strain = 0.01", "max_strain = 0.04"},
        {"frame_every_strain = 0.005", "frame_every_strain = 0.004"}}) {
    const auto at = scene.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    scene.replace(at, from.size(), to);
  }
  std::ofstream(dir / "ps.toml") << scene;
  ASSERT_EQ(run("simulate " + (dir / "ps.toml").string() + " -q -o " + (dir / "run").string(),
                dir / "log"),
            0)
      << slurp(dir / "log");
  const std::string run_h5 = (dir / "run" / "plane_strain.h5").string();
  const auto attr = [](const fs::path& h5, const char* name) {
    return gs::test::read_attr(h5, "/", name);
  };
  const auto cosines = [&](const fs::path& h5) {
    return std::array<double, 3>{
        std::abs(attr(h5, "dot_curl_harmonic")) /
            (attr(h5, "norm_curl_v") * attr(h5, "norm_harmonic")),
        std::abs(attr(h5, "dot_grad_harmonic")) /
            (attr(h5, "norm_grad_u") * attr(h5, "norm_harmonic")),
        std::abs(attr(h5, "dot_grad_curl")) / (attr(h5, "norm_grad_u") * attr(h5, "norm_curl_v"))};
  };
  for (const char* pair : {" --from 1 --to 2", " --from 9 --to 10"}) {
    SCOPED_TRACE(pair);
    ASSERT_EQ(run("analyze hhd " + run_h5 + pair + " -o " + (dir / "p.h5").string(), dir / "log"),
              0)
        << slurp(dir / "log");
    ASSERT_EQ(
        run("analyze hhd " + run_h5 + pair + " --solver cholmod -o " + (dir / "b.h5").string(),
            dir / "log"),
        0)
        << slurp(dir / "log");
    const auto p = cosines(dir / "p.h5");
    const auto b = cosines(dir / "b.h5");
    for (double c : p) EXPECT_LT(c, 1e-8);
    EXPECT_GT(b[0], 1e-3);
    EXPECT_LT(b[1], 1e-8);
    EXPECT_EQ(attr(dir / "p.h5", "converged"), 1.0);
    // The same u (eq 17): by AMG-preconditioned CG to 1e-10 in the default, by the factor here.
    EXPECT_NEAR(attr(dir / "p.h5", "norm_grad_u"), attr(dir / "b.h5", "norm_grad_u"),
                1e-9 * attr(dir / "b.h5", "norm_grad_u"));
  }
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
  const std::string ok =
      csv("ok3.csv", "x,y,ux,uy\n0,0,1,1\n1,0,1,1\n0,1,1,1\n1,1,1,1\n0.5,0.4,0,0\n");
  expect_rejected(ok + " --significance 1.5", dir, "--significance must be in [0, 1] (1.5)");
  expect_rejected(ok + " --significance-abs -1", dir, "--significance-abs must be >= 0 (-1)");
  expect_rejected(ok + " --tolerance 0", dir, "--tolerance must be in (0, 1) (0)");
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
