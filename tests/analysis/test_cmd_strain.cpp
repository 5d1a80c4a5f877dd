// End-to-end tests of `granoscope analyze strain` / `analyze voidcells` on synthetic RUN.h5
// files: exact affine answers come back through the HDF5 outputs; bad input exits 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>

#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "tet_strain.hpp"

namespace fs = std::filesystem;

namespace {

using gs::test::read_array;
using gs::test::read_doubles;
using gs::test::read_format;
using gs::test::run;

fs::path temp_dir() {
  return gs::test::temp_dir("gs_strain_cli");
}

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
  EXPECT_EQ(read_format(dir / "s.h5"), "granoscope-strain");
  const auto mean = read_doubles(dir / "s.h5", "/mean_gradient");
  ASSERT_EQ(mean.size(), 9u);
  for (int i = 0; i < 9; ++i)
    EXPECT_NEAR(mean[static_cast<std::size_t>(i)], h(i / 3, i % 3), 1e-14);
  // The displacement h X is affine: every simplex, and every particle with a good simplex, has
  // the gradient h; volumetric strain tr h; the 299 matched particles (ids 1000 - i, i >= 1).
  const auto ids = read_array<std::int64_t>(dir / "s.h5", "/particles/id", H5T_NATIVE_INT64);
  ASSERT_EQ(ids.size(), 299u);
  for (std::size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(ids[i], 999 - std::int64_t(i));
  const auto valid = read_array<std::uint8_t>(dir / "s.h5", "/particles/valid", H5T_NATIVE_UINT8);
  const auto pg = read_doubles(dir / "s.h5", "/particles/gradient");
  const auto pv = read_doubles(dir / "s.h5", "/particles/volumetric_strain");
  std::size_t n_valid = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!valid[i]) continue;
    ++n_valid;
    EXPECT_NEAR(pv[i], h.trace(), 1e-14) << i;
    for (std::size_t k = 0; k < 9; ++k) EXPECT_NEAR(pg[9 * i + k], h(k / 3, k % 3), 1e-13) << i;
  }
  EXPECT_GT(n_valid, 290u);
  const auto sg = read_doubles(dir / "s.h5", "/simplices/gradient");
  const auto quality = read_doubles(dir / "s.h5", "/simplices/quality");
  const std::size_t tets = quality.size();
  ASSERT_EQ(sg.size(), 9 * tets);
  // Rounding: the displacements come from stored positions (error eps |X| ~ 2e-18 m), divided
  // by an edge l ~ 1.5 mm and amplified by 1/quality q: |H_t - h| <= 1e-14 / q (measured max
  // |H_t - h| q = 1.5e-15; worst simplex q = 0.0011, |H_t - h| = 1.3e-13).
  for (std::size_t t = 0; t < tets; ++t)
    for (std::size_t k = 0; k < 9; ++k)
      EXPECT_NEAR(sg[9 * t + k], h(k / 3, k % 3), 1e-14 / quality[t]) << t << " q " << quality[t];
  // The VTU holds the same mesh (299 points, every tetrahedron) and the uniform strain.
  const std::string piece = gs::test::xml_tag(dir / "s.vtu", "Piece");
  EXPECT_EQ(gs::test::xml_number(piece, "NumberOfPoints"), 299.0);
  EXPECT_EQ(gs::test::xml_number(piece, "NumberOfCells"), double(tets));
  const double qmin = *std::min_element(quality.begin(), quality.end());
  for (const auto& [sec, tol] : {std::pair{"PointData", 1e-14}, {"CellData", 3e-14 / qmin}}) {
    const auto [lo, hi] = gs::test::vtk_range(dir / "s.vtu", sec, "volumetric_strain");
    EXPECT_NEAR(lo, h.trace(), tol) << sec;
    EXPECT_NEAR(hi, h.trace(), tol) << sec;
  }
  const auto [qlo, qhi] = gs::test::vtk_range(dir / "s.vtu", "CellData", "quality");
  EXPECT_EQ(qlo, *std::min_element(quality.begin(), quality.end()));
  EXPECT_EQ(qhi, *std::max_element(quality.begin(), quality.end()));
  // Slab |z - 5 mm| <= 2 mm projected onto x-y: triangles, in-plane block of h (seed 000 §5).
  ASSERT_EQ(run("analyze strain " + (dir / "run.h5").string() +
                    " --to 1 --slab-origin 0 0 0.005 --slab-normal 0 0 1 --slab-axis 1 0 0"
                    " --slab-thickness 0.004 -o " +
                    (dir / "p.h5").string(),
                dir / "log"),
            0);
  const auto m2 = read_doubles(dir / "p.h5", "/mean_gradient");
  for (int i = 0; i < 9; ++i) {
    const double expect = (i / 3 < 2 && i % 3 < 2) ? h(i / 3, i % 3) : 0.0;
    EXPECT_NEAR(m2[static_cast<std::size_t>(i)], expect, 1e-14) << i;
  }
  // The slab holds the matched particles with |z - 5 mm| <= 2 mm in the reference frame.
  std::size_t in_slab = 0;
  for (std::size_t i = 1; i < a.particles.size(); ++i)
    in_slab += std::abs(a.particles[i].position.z() - 0.005) <= 0.002;
  EXPECT_EQ(read_doubles(dir / "p.h5", "/particles/volumetric_strain").size(), in_slab);
  EXPECT_GT(in_slab, 60u);
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
  // Velocities in a fixed periodic cell (images move with their particle): the velocity l x is
  // affine only inside the cell, so the cells that do not cross the boundary (every polygon
  // vertex inside [0, side)^2) have the gradient l exactly; the crossing ones do not.
  ASSERT_EQ(run("analyze voidcells " + (dir / "run.h5").string() + " -o " + (dir / "v.h5").string(),
                dir / "log"),
            0);
  EXPECT_EQ(read_format(dir / "v.h5"), "granoscope-voidcells");
  {
    const auto off = read_array<std::int64_t>(dir / "v.h5", "/cells/offsets", H5T_NATIVE_INT64);
    const auto poly = read_doubles(dir / "v.h5", "/cells/polygon");
    const auto g0 = read_doubles(dir / "v.h5", "/cells/gradient");
    ASSERT_EQ(g0.size(), 4 * (off.size() - 1));
    std::size_t inner = 0, crossing_off = 0;
    for (std::size_t c = 0; c + 1 < off.size(); ++c) {
      bool in = true;
      for (auto k = off[c]; k < off[c + 1]; ++k)
        for (int a = 0; a < 2; ++a) {
          const double x = poly[2 * static_cast<std::size_t>(k) + static_cast<std::size_t>(a)];
          in = in && x >= 0.0 && x < side;
        }
      double err = 0.0;
      for (std::size_t i = 0; i < 4; ++i)
        err = std::max(err, std::abs(g0[4 * c + i] - l(i / 2, i % 2)));
      if (in) {
        ++inner;
        EXPECT_LE(err, 1e-12 * l.norm()) << c;
      } else {
        crossing_off += err > 1e-3 * l.norm();
      }
    }
    EXPECT_GT(inner, 100u);
    EXPECT_GT(crossing_off, 0u);  // the images of a fixed cell do not follow l x
  }
  // With the cell velocity gradient l the image velocities are consistent: exact l per cell.
  ASSERT_EQ(run("analyze voidcells " + (dir / "run.h5").string() +
                    " --cell-velocity-gradient 0 0.02 -0.01 0.005 -o " + (dir / "vl.h5").string(),
                dir / "log"),
            0);
  const auto gl = read_doubles(dir / "vl.h5", "/cells/gradient");
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
  const auto grad = read_doubles(dir / "v2.h5", "/cells/gradient");
  ASSERT_GT(grad.size(), 40u);
  // The displacement is rebuilt from stored positions (x_B - x_A): its rounding, eps |x|, is
  // ~1e-13 of a cell's relative displacement |l| h, amplified in thin cells. The method itself is
  // tested at 1e-12 on exact velocities in test_kuhn_void_cells.cpp; this checks the plumbing.
  for (std::size_t i = 0; i < grad.size(); ++i) {
    EXPECT_NEAR(grad[i], l((i % 4) / 2, i % 2), 1e-10 * l.norm()) << i;
  }
  const auto alpha = read_doubles(dir / "v2.h5", "/cells/alpha");
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
  const auto w = read_doubles(dir / "v3.h5", "/cells/w");
  for (double x : w) EXPECT_TRUE(std::isfinite(x));
  // The VTU holds the cells of the HDF5 output (one polygon each) and the same w and area.
  const auto off3 = read_array<std::int64_t>(dir / "v3.h5", "/cells/offsets", H5T_NATIVE_INT64);
  EXPECT_EQ(gs::test::xml_number(gs::test::xml_tag(dir / "v3.vtu", "Piece"), "NumberOfCells"),
            double(off3.size() - 1));
  for (const char* name : {"w", "area"}) {
    const auto v = read_doubles(dir / "v3.h5", (std::string("/cells/") + name).c_str());
    const auto [lo, hi] = gs::test::vtk_range(dir / "v3.vtu", "CellData", name);
    EXPECT_EQ(lo, *std::min_element(v.begin(), v.end())) << name;
    EXPECT_EQ(hi, *std::max_element(v.begin(), v.end())) << name;
  }
  // The triangle (Bagi eq 4) variant of the same motion: 2D strain with alpha and w.
  ASSERT_EQ(
      run("analyze strain " + (dir / "run3.h5").string() + " --to 1 -o " + (dir / "t3.h5").string(),
          dir / "log"),
      0);
  EXPECT_EQ(read_doubles(dir / "t3.h5", "/simplices/alpha").size(),
            read_doubles(dir / "t3.h5", "/simplices/measure").size());
  // Triangles of the exactly affine motion (run2): every triangle has the gradient l, so
  // alpha = 1 and w = -(l12 - l21) / |l| (eq 18-20 with the local gradient equal to the mean).
  ASSERT_EQ(
      run("analyze strain " + (dir / "run2.h5").string() + " --to 1 -o " + (dir / "t2.h5").string(),
          dir / "log"),
      0);
  const auto tg = read_doubles(dir / "t2.h5", "/simplices/gradient");
  const auto tq = read_doubles(dir / "t2.h5", "/simplices/quality");
  ASSERT_EQ(tg.size(), 9 * tq.size());
  for (std::size_t t = 0; t < tq.size(); ++t)
    for (std::size_t k = 0; k < 9; ++k) {
      const double expect = (k / 3 < 2 && k % 3 < 2) ? l(k / 3, k % 3) : 0.0;
      EXPECT_NEAR(tg[9 * t + k], expect, 1e-12 * l.norm() / tq[t]) << t;
    }
  for (double x : read_doubles(dir / "t2.h5", "/simplices/alpha")) EXPECT_NEAR(x, 1.0, 1e-10);
  for (double x : read_doubles(dir / "t2.h5", "/simplices/w"))
    EXPECT_NEAR(x, -(l(0, 1) - l(1, 0)) / l.norm(), 1e-10);
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

/// `n` particles at random in the periodic cube [0, side)^3 (ids 10 + i).
gs::Frame periodic_cloud(std::size_t n, double side, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, side), ur(1.5e-4, 3e-4);
  gs::Frame f;
  f.domain.periodic = true;
  f.domain.lo = Eigen::Vector3d::Zero();
  f.domain.hi = Eigen::Vector3d::Constant(side);
  f.domain.cell = side * Eigen::Matrix3d::Identity();
  for (std::size_t i = 0; i < n; ++i) {
    gs::Particle p;
    p.id = static_cast<std::int64_t>(10 + i);
    p.position = Eigen::Vector3d(u(rng), u(rng), u(rng));
    p.radius = ur(rng);
    f.particles.push_back(p);
  }
  return f;
}

/// The frame after the affine motion x -> (I + h) x + t of the particles and the cell, every
/// particle wrapped back into the new cell; returns how many were wrapped.
std::size_t move_and_wrap(gs::Frame& f, const Eigen::Matrix3d& h, const Eigen::Vector3d& t) {
  f.domain.cell = (Eigen::Matrix3d::Identity() + h) * f.domain.cell;
  const Eigen::Matrix3d inv = f.domain.cell.inverse();
  std::size_t wrapped = 0;
  for (auto& p : f.particles) {
    p.position += h * p.position + t;
    const Eigen::Vector3d s = inv * p.position;
    const Eigen::Vector3d k = s.array().floor().matrix();
    if (k.norm() > 0) ++wrapped;
    p.position -= f.domain.cell * k;
  }
  return wrapped;
}

TEST(CmdStrain, PeriodicBoundaryCrossingIsTheMinimumImage) {
  // 400 particles in a periodic 1 cm cell. Frame 1: a uniform translation t (5-8 % of the
  // cell) with the particles that leave the cell wrapped back (a jump of ~ one cell length).
  // Frame 2: the affine motion x -> (I + h) x + t of particles and cell, wrapped into the
  // deformed cell. Exact answers: the minimum-image displacements are t and h X + t, so every
  // tetrahedron has the gradient 0 and h (to round-off), as without crossing.
  const auto dir = temp_dir();
  const double side = 0.01;
  const gs::Frame a = periodic_cloud(400, side, 8);
  const Eigen::Vector3d t(0.05 * side, -0.08 * side, 0.06 * side);
  Eigen::Matrix3d h;
  h << 0.01, 0.004, 0.0, 0.0, -0.008, 0.002, 0.003, 0.0, 0.006;
  gs::Frame b = a, c = a;
  EXPECT_GT(move_and_wrap(b, Eigen::Matrix3d::Zero(), t), 40u);
  EXPECT_GT(move_and_wrap(c, h, t), 40u);
  gs::Trajectory tr;
  tr.frames = {a, b, c};
  gs::write_hdf5_trajectory(dir / "run.h5", tr);
  for (const auto& [to, expect] : {std::pair{1, Eigen::Matrix3d::Zero().eval()}, {2, h}}) {
    SCOPED_TRACE(to);
    const auto out = dir / (std::to_string(to) + "s.h5");
    ASSERT_EQ(run("analyze strain " + (dir / "run.h5").string() + " --to " + std::to_string(to) +
                      " -o " + out.string(),
                  dir / "log"),
              0)
        << gs::test::slurp(dir / "log");
    const auto sg = read_doubles(out, "/simplices/gradient");
    const auto q = read_doubles(out, "/simplices/quality");
    ASSERT_EQ(sg.size(), 9 * q.size());
    double worst = 0.0;
    for (std::size_t s = 0; s < q.size(); ++s)
      for (std::size_t k = 0; k < 9; ++k) {
        const double e = std::abs(sg[9 * s + k] - expect(k / 3, k % 3));
        EXPECT_LE(e, 1e-14 / q[s]) << s;  // rounding bound as in the non-periodic test
        worst = std::max(worst, e);
      }
    const auto mean = read_doubles(out, "/mean_gradient");
    for (std::size_t k = 0; k < 9; ++k) EXPECT_NEAR(mean[k], expect(k / 3, k % 3), 1e-14);
    std::printf("periodic crossing, frame %d: max |H_t - H| = %.3g\n", to, worst);
  }
  fs::remove_all(dir);
}

TEST(CmdStrain, WeightedIsTheRegularTriangulation) {
  // --weighted: the regular triangulation with weights r^2. With equal radii it is the Delaunay
  // triangulation (the same tetrahedra as without --weighted); with unequal radii it differs,
  // and an affine motion still gives every tetrahedron the gradient h.
  const auto dir = temp_dir();
  gs::Frame a = periodic_cloud(300, 0.01, 21);
  a.domain.periodic = false;
  Eigen::Matrix3d h;
  h << -0.01, 0.003, 0.0, 0.002, 0.005, -0.004, 0.0, 0.001, 0.007;
  const auto tets = [&](const std::string& input, const std::string& name, const std::string& opt) {
    const auto out = dir / (name + ".h5");
    EXPECT_EQ(run("analyze strain " + (dir / (input + "_run.h5")).string() + " --to 1 " + opt +
                      " -o " + out.string(),
                  dir / "log"),
              0)
        << gs::test::slurp(dir / "log");
    const auto v = read_array<std::int32_t>(out, "/simplices/vertices", H5T_NATIVE_INT32);
    std::set<std::array<std::int32_t, 4>> set;
    for (std::size_t s = 0; s + 3 < v.size(); s += 4) {
      std::array<std::int32_t, 4> t{v[s], v[s + 1], v[s + 2], v[s + 3]};
      std::sort(t.begin(), t.end());
      set.insert(t);
    }
    EXPECT_EQ(set.size(), v.size() / 4);
    return set;
  };
  for (const bool equal : {true, false}) {
    gs::Frame f = a;
    if (equal)
      for (auto& p : f.particles) p.radius = 2e-4;
    gs::Frame g = f;
    for (auto& p : g.particles) p.position += h * p.position;
    gs::Trajectory tr;
    tr.frames = {f, g};
    const std::string name = equal ? "eq" : "poly";
    gs::write_hdf5_trajectory(dir / (name + "_run.h5"), tr);
    const auto plain = tets(name, name + "_d", ""),
               weighted = tets(name, name + "_w", "--weighted");
    EXPECT_EQ(gs::test::read_attr(dir / (name + "_w.h5"), "/", "weighted"), 1.0);
    EXPECT_EQ(gs::test::read_attr(dir / (name + "_d.h5"), "/", "weighted"), 0.0);
    if (equal) {
      EXPECT_EQ(plain, weighted);
    } else {
      EXPECT_NE(plain, weighted);
    }
    const auto sg = read_doubles(dir / (name + "_w.h5"), "/simplices/gradient");
    const auto q = read_doubles(dir / (name + "_w.h5"), "/simplices/quality");
    for (std::size_t s = 0; s < q.size(); ++s)
      for (std::size_t k = 0; k < 9; ++k)
        EXPECT_NEAR(sg[9 * s + k], h(k / 3, k % 3), 1e-14 / q[s]) << name << " " << s;
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
