// Tests of the seed 000 detection pipeline (analysis/vortex_analysis, vortex_detection,
// ghost_nodes, vortex_series): Lamb–Oseen vortices and a source/sink pair found within one mesh
// spacing with the right sign, vortex tubes along a straight vortex, ghost lattice and Gaussian
// averages, Fourier periods, degenerate input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "ghost_nodes.hpp"
#include "hhd_test_fields.hpp"
#include "vortex_analysis.hpp"
#include "vortex_series.hpp"

namespace gs::analysis {
namespace {

using test::box_mesh;
constexpr double kPi = std::numbers::pi;

// Lamb–Oseen vortex of circulation gamma (> 0: counterclockwise about +z), core radius rc.
Eigen::Vector3d lamb_oseen(const Eigen::Vector3d& x, const Eigen::Vector2d& centre, double gamma,
                           double rc) {
  const Eigen::Vector2d d = x.head<2>() - centre;
  const double r2 = d.squaredNorm();
  if (r2 == 0.0) return Eigen::Vector3d::Zero();
  const double ut = gamma / (2.0 * kPi * std::sqrt(r2)) * (1.0 - std::exp(-r2 / (rc * rc)));
  const Eigen::Vector2d e = Eigen::Vector2d(-d.y(), d.x()) / std::sqrt(r2);
  return Eigen::Vector3d(ut * e.x(), ut * e.y(), 0.0);
}

// Strongest extremum of a kind (largest magnitude), or nullptr.
const Extremum* strongest(const std::vector<Extremum>& ex, ExtremumKind kind) {
  const Extremum* best = nullptr;
  for (const auto& e : ex)
    if (e.kind == kind && (!best || e.magnitude > best->magnitude)) best = &e;
  return best;
}

TEST(Vortex, LambOseenPairFoundWithinOneSpacingWithTheRightSign2D) {
  const int n = 40;  // spacing h = 1/40
  const auto m = box_mesh(2, n, 21);
  const Eigen::Vector2d ccw(0.31, 0.62), cw(0.68, 0.35);
  std::vector<Eigen::Vector3d> u;
  for (const auto& p : m.points)
    u.push_back(lamb_oseen(p, ccw, 1.0, 0.07) + lamb_oseen(p, cw, -0.8, 0.06));
  const auto a = analyze_vortices(m.points, u, 2);
  const auto* left = strongest(a.extrema, ExtremumKind::LeftVortex);
  const auto* right = strongest(a.extrema, ExtremumKind::RightVortex);
  ASSERT_TRUE(left && right);
  const double h = 1.0 / n;
  const double dl = (a.mesh.points[static_cast<std::size_t>(left->node)].head<2>() - ccw).norm();
  const double dr = (a.mesh.points[static_cast<std::size_t>(right->node)].head<2>() - cw).norm();
  std::printf("Lamb-Oseen centres found at %.2f h and %.2f h\n", dl / h, dr / h);
  EXPECT_LE(dl, h);
  EXPECT_LE(dr, h);
  EXPECT_GT(left->value, 0.0);  // v_z maximum: counterclockwise
  EXPECT_LT(right->value, 0.0);
  // A pure rotation field has no sources or sinks of comparable strength: |u| stays at the
  // discretisation level, far below |v| at the centres.
  for (const auto& e : a.extrema)
    if (e.kind == ExtremumKind::Source || e.kind == ExtremumKind::Sink) {
      EXPECT_LT(e.magnitude, 0.05 * left->magnitude);
    }
}

TEST(Vortex, SourceSinkPairFoundWithinOneSpacing2D) {
  const int n = 40;
  const auto m = box_mesh(2, n, 22);
  const Eigen::Vector2d src(0.36, 0.41), snk(0.66, 0.63);
  const double s2 = 0.06 * 0.06;
  std::vector<Eigen::Vector3d> u;
  for (const auto& p : m.points) {
    // ξ = ∇U, U = −exp(−|x−s|²/2σ²) + 0.7 exp(−|x−t|²/2σ²): outward at s, inward at t.
    const Eigen::Vector2d ds = p.head<2>() - src, dt = p.head<2>() - snk;
    const Eigen::Vector2d g = ds / s2 * std::exp(-ds.squaredNorm() / (2 * s2)) -
                              0.7 * dt / s2 * std::exp(-dt.squaredNorm() / (2 * s2));
    u.emplace_back(g.x(), g.y(), 0.0);
  }
  const auto a = analyze_vortices(m.points, u, 2);
  const auto* source = strongest(a.extrema, ExtremumKind::Source);
  const auto* sink = strongest(a.extrema, ExtremumKind::Sink);
  ASSERT_TRUE(source && sink);
  const double h = 1.0 / n;
  const double ds = (a.mesh.points[static_cast<std::size_t>(source->node)].head<2>() - src).norm();
  const double dk = (a.mesh.points[static_cast<std::size_t>(sink->node)].head<2>() - snk).norm();
  std::printf("source and sink found at %.2f h and %.2f h\n", ds / h, dk / h);
  EXPECT_LE(ds, h);
  EXPECT_LE(dk, h);
  EXPECT_LT(source->value, 0.0);
  EXPECT_GT(sink->value, 0.0);
}

TEST(Vortex, StraightVortexTube3D) {
  // A Lamb–Oseen vortex along z through (0.45, 0.55): the strongest |v| maximum lies on the axis
  // (within one spacing), v_z > 0 (counterclockwise about +z: left-handed), and its tube runs
  // along the axis.
  const int n = 14;
  const auto m = box_mesh(3, n, 23);
  const Eigen::Vector2d axis(0.45, 0.55);
  std::vector<Eigen::Vector3d> u;
  for (const auto& p : m.points) u.push_back(lamb_oseen(p, axis, 1.0, 0.12));
  VortexAnalysisOptions o;
  o.tube_delta = 0.25;  // |v| falls to 0 at z = 0, 1 (v = 0 on the hull): a wide δ follows it
  const auto a = analyze_vortices(m.points, u, 3, o);
  const auto* left = strongest(a.extrema, ExtremumKind::LeftVortex);
  ASSERT_TRUE(left);
  const double h = 1.0 / n;
  const auto& c = a.mesh.points[static_cast<std::size_t>(left->node)];
  std::printf("3D vortex centre %.2f h from the axis\n", (c.head<2>() - axis).norm() / h);
  EXPECT_LE((c.head<2>() - axis).norm(), h);
  EXPECT_GT(left->v.z(), 0.0);
  EXPECT_NEAR(left->v.normalized().z(), 1.0, 0.05);
  const auto* right = strongest(a.extrema, ExtremumKind::RightVortex);
  if (right) {
    EXPECT_LT(right->magnitude, 0.2 * left->magnitude);
  }
  const auto it = std::find_if(a.tubes.begin(), a.tubes.end(),
                               [&](const VortexTube& t) { return &a.extrema[t.extremum] == left; });
  ASSERT_NE(it, a.tubes.end());
  double zmin = 1, zmax = 0;
  for (auto i : it->nodes) {
    const auto& p = a.mesh.points[static_cast<std::size_t>(i)];
    // Within the first ring of lattice nodes around the axis (√2 h + jitter < 2 h): the vortex
    // core (r_c = 1.7 h) is flat in |v|, the half-space rule lets the path step sideways there.
    EXPECT_LE((p.head<2>() - axis).norm(), 2.0 * h);
    zmin = std::min(zmin, p.z());
    zmax = std::max(zmax, p.z());
  }
  EXPECT_GE(zmax - zmin, 0.6) << it->nodes.size() << " nodes";
  // δ = 0: only non-decreasing |v| steps; a maximum then has no tube beyond itself.
  o.tube_delta = 0.0;
  const auto a0 = analyze_vortices(m.points, u, 3, o);
  for (const auto& t : a0.tubes) EXPECT_EQ(t.nodes.size(), 1u);
}

TEST(Vortex, DegenerateInputClearMessages) {
  const auto expect_message = [](auto&& f, const std::string& part) {
    try {
      f();
      FAIL() << "accepted, expected: " << part;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  auto m = box_mesh(3, 4, 30);
  std::vector<Eigen::Vector3d> u(m.points.size(), Eigen::Vector3d(1, 0, 0));
  auto dup = m.points;
  dup[9] = dup[4];
  expect_message([&] { analyze_vortices(dup, u, 3); },
                 "duplicate particle centres (points 4 and 9)");
  std::vector<Eigen::Vector3d> flat;
  for (int i = 0; i < 12; ++i) flat.emplace_back(i % 4, i / 4, 0.0);
  const std::vector<Eigen::Vector3d> uf(flat.size(), Eigen::Vector3d(1, 0, 0));
  expect_message([&] { analyze_vortices(flat, uf, 3); }, "coplanar");
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 5; ++i) line.emplace_back(i, 2 * i, 0.0);
  const std::vector<Eigen::Vector3d> u5(5, Eigen::Vector3d(1, 0, 0));
  expect_message([&] { analyze_vortices(line, u5, 2); }, "collinear");
  const std::vector<Eigen::Vector3d> three(m.points.begin(), m.points.begin() + 3);
  expect_message([&] { analyze_vortices(three, u5, 3); }, "one vector per point");
  expect_message(
      [&] {
        analyze_vortices(three, {u5.begin(), u5.begin() + 3}, 3);
      },
      "at least 4 points");
  auto nan = u;
  nan[5].y() = std::nan("");
  expect_message([&] { analyze_vortices(m.points, nan, 3); }, "non-finite vector (point 5)");
  // Nearly coplanar: a 5 x 5 grid, 3 layers 1e-9 apart (slivers of quality ~1e-9, kept). The
  // decomposition of a constant field is still exact: u = v = 0, h = ξ.
  std::vector<Eigen::Vector3d> thin;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) thin.emplace_back(i, j, 1e-9 * ((i + j) % 3));
  const std::vector<Eigen::Vector3d> ut(thin.size(), Eigen::Vector3d(1, 2, 3));
  const auto a = analyze_vortices(thin, ut, 3);
  ASSERT_GT(a.hhd.report.unknowns, 0u);
  EXPECT_LT(a.hhd.norm_grad_u + a.hhd.norm_curl_v, 1e-12 * a.hhd.norm_xi);
  // All nodes on the hull (a flat 2 x 2 x 2 set): nothing to solve for, said so.
  std::vector<Eigen::Vector3d> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  expect_message(
      [&] {
        analyze_vortices(cube, {8, Eigen::Vector3d(1, 0, 0)}, 3);
      },
      "no interior node");
}

TEST(Ghosts, LatticeOutsideTheBoxAwayFromCentresConstantFieldExact) {
  // 3D: 300 random centres in a 40 x 140 x 80 mm box, d50 = 2.5 mm (the paper's specimen).
  std::mt19937_64 rng(40);
  std::uniform_real_distribution<double> ux(0, 0.04), uy(0, 0.14), uz(0, 0.08);
  std::vector<Eigen::Vector3d> x;
  for (int i = 0; i < 300; ++i) x.emplace_back(ux(rng), uy(rng), uz(rng));
  const auto o = paper_ghost_options(2.5e-3, 0.04);
  EXPECT_NEAR(o.spacing, 4.5e-3, 1e-15);
  EXPECT_NEAR(o.min_distance, 4e-3, 1e-15);
  EXPECT_NEAR(o.extent, 0.05, 1e-15);
  EXPECT_NEAR(o.radius, 0.08, 1e-15);
  GhostOptions coarse = o;
  coarse.spacing = 0.02;  // fewer ghosts for the test
  coarse.extent = 0.03;
  coarse.min_distance = 0.012;
  const Eigen::Vector3d c(1e-5, -2e-5, 3e-6);
  const std::vector<Eigen::Vector3d> uc(x.size(), c);
  const auto g = ghost_nodes(x, uc, 3, coarse);
  ASSERT_GT(g.position.size(), 100u);
  Eigen::Vector3d lo = x[0], hi = x[0];
  for (const auto& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  double nearest_pair = 1e9;
  for (std::size_t i = 0; i < g.position.size(); ++i) {
    const auto& p = g.position[i];
    const double d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
    EXPECT_GT(d, 0.0);
    EXPECT_LE(d, coarse.extent * (1 + 1e-12));
    for (const auto& q : x) EXPECT_GE((q - p).norm(), coarse.min_distance);
    EXPECT_LT((g.vector[i] - c).norm(), 1e-14 * c.norm());  // exact up to summation round-off
    for (std::size_t j = 0; j < i; ++j)
      nearest_pair = std::min(nearest_pair, (g.position[j] - p).norm());
  }
  // fcc nearest-neighbour distance, up to the 1e-3 h shift per coordinate (header)
  EXPECT_NEAR(nearest_pair, coarse.spacing, 2 * std::sqrt(3.0) * 1e-3 * coarse.spacing);
  // Linear field: the binned Gaussian average agrees with the node-by-node sum to O((R/8 / R)^2).
  std::vector<Eigen::Vector3d> ul;
  Eigen::Matrix3d grad;
  grad << 1e-3, 2e-3, 0, -1e-3, 5e-4, 3e-4, 0, 1e-3, -2e-3;
  for (const auto& p : x) ul.push_back(grad * p + c);
  const auto gl = ghost_nodes(x, ul, 3, coarse);
  double worst = 0.0, scale = 0.0;
  for (const auto& v : ul) scale = std::max(scale, (v - c).norm());
  for (std::size_t i = 0; i < gl.position.size(); ++i) {
    const auto exact = gaussian_average(x, ul, gl.position[i], coarse.radius, 3);
    worst = std::max(worst, (gl.vector[i] - exact).norm() / scale);
  }
  std::printf("binned Gaussian average: worst deviation %.3g of the field's variation\n", worst);
  EXPECT_LT(worst, 1e-3);
  // 2D: triangular lattice with spacing h, z = 0.
  std::vector<Eigen::Vector3d> x2;
  for (int i = 0; i < 200; ++i) x2.emplace_back(ux(rng), uy(rng), 0.7);
  const std::vector<Eigen::Vector3d> u2(x2.size(), Eigen::Vector3d(1, 2, 0));
  const auto g2 = ghost_nodes(x2, u2, 2, coarse);
  ASSERT_GT(g2.position.size(), 20u);
  double np2 = 1e9;
  for (std::size_t i = 0; i < g2.position.size(); ++i) {
    EXPECT_EQ(g2.position[i].z(), 0.0);
    for (std::size_t j = 0; j < i; ++j)
      np2 = std::min(np2, (g2.position[j] - g2.position[i]).norm());
  }
  EXPECT_NEAR(np2, coarse.spacing, 2 * std::sqrt(2.0) * 1e-3 * coarse.spacing);
  coarse.spacing = 0.0;
  EXPECT_THROW(ghost_nodes(x, uc, 3, coarse), std::invalid_argument);
}

TEST(Ghosts, HullMovesToTheGhostsAndExtremaIgnoreThem) {
  const auto m = box_mesh(2, 20, 41);
  std::vector<Eigen::Vector3d> u;
  for (const auto& p : m.points) u.push_back(lamb_oseen(p, {0.5, 0.5}, 1.0, 0.1));
  VortexAnalysisOptions o;
  o.ghosts = true;
  o.ghost = paper_ghost_options(0.05, 1.0);
  o.ghost.extent = 0.3;
  o.ghost.spacing = 0.09;
  o.ghost.min_distance = 0.08;
  const auto a = analyze_vortices(m.points, u, 2, o);
  ASSERT_GT(a.mesh.points.size(), a.true_nodes);
  for (std::size_t i = 0; i < a.true_nodes; ++i) EXPECT_EQ(a.mesh.dirichlet[i], 0) << i;
  for (const auto& e : a.extrema) EXPECT_LT(static_cast<std::size_t>(e.node), a.true_nodes);
  const auto* left = strongest(a.extrema, ExtremumKind::LeftVortex);
  ASSERT_TRUE(left);
  EXPECT_LE(
      (a.mesh.points[static_cast<std::size_t>(left->node)].head<2>() - Eigen::Vector2d(0.5, 0.5))
          .norm(),
      1.0 / 20);
}

TEST(VortexSeries, FourierPeriodOfACountSignal) {
  // 60 samples, spacing 0.5 % strain, a period of 6 % (seed 000 Fig. 17's dominant period):
  // exactly 5 periods in the window, so the amplitude 2 is found exactly at T = 0.06.
  std::vector<double> x, y;
  for (int i = 0; i < 60; ++i) {
    x.push_back(0.005 * i);
    y.push_back(7.0 + 2.0 * std::sin(2 * kPi * x.back() / 0.06) +
                0.5 * std::cos(2 * kPi * x.back() / 0.015));
  }
  const auto s = amplitude_spectrum(x, y);
  EXPECT_NEAR(s.dominant_period, 0.06, 1e-12);
  ASSERT_EQ(s.amplitude.size(), 30u);
  EXPECT_NEAR(s.amplitude[4], 2.0, 1e-12);   // k = 5
  EXPECT_NEAR(s.amplitude[19], 0.5, 1e-12);  // k = 20, T = 0.015
  for (std::size_t k = 0; k < s.amplitude.size(); ++k)
    if (k != 4 && k != 19) {
      EXPECT_LT(s.amplitude[k], 1e-12) << k;
    }
  EXPECT_THROW(amplitude_spectrum({0, 1, 1, 2}, {1, 2, 3, 4}), std::invalid_argument);
  EXPECT_THROW(amplitude_spectrum({0, 1, 2}, {1, 2, 3}), std::invalid_argument);
}

}  // namespace
}  // namespace gs::analysis
