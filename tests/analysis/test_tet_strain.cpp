// Tests of analysis/tet_strain: exact gradients for affine fields (3D tets, 2D triangles).
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <stdexcept>

#include "delaunay_mesh.hpp"
#include "tet_strain.hpp"

namespace gs::analysis {
namespace {

std::vector<Eigen::Vector3d> random_points(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1e-2);  // a 1 cm box
  std::vector<Eigen::Vector3d> p(n);
  for (auto& x : p) x = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

double rel(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return (a - b).norm() / b.norm();
}

TEST(TetStrain, AffineFieldExactInEveryTetAndAverage) {
  const auto x = random_points(2000, 1);
  Eigen::Matrix3d h;
  h << 0.01, -0.02, 0.003, 0.015, -0.007, 0.002, -0.004, 0.006, 0.011;
  const Eigen::Vector3d u0(1e-3, -2e-3, 5e-4);
  std::vector<Eigen::Vector3d> u(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) u[i] = u0 + h * x[i];
  const auto r = tet_strain(x, u);
  ASSERT_GT(r.simplices.size(), 5000u);
  std::size_t checked = 0;
  for (std::size_t t = 0; t < r.simplices.size(); ++t) {
    EXPECT_GT(r.measure[t], 0.0);
    if (r.sliver[t]) continue;  // documented criterion: slivers (q < 0.02) are not trusted
    EXPECT_LT(rel(r.gradient[t], h), 1e-12) << "tet " << t << " quality " << r.quality[t];
    ++checked;
  }
  EXPECT_GT(checked, r.simplices.size() * 9 / 10);
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_TRUE(r.particle_valid[i]) << i;
    EXPECT_LT(rel(r.particle_gradient[i], h), 1e-12);
  }
  EXPECT_LT(rel(r.mean_gradient, h), 1e-12);
  // Volumes of the Delaunay tets fill the convex hull: sum > 0.9 of the box.
  double v = 0.0;
  for (double m : r.measure) v += m;
  EXPECT_GT(v, 0.9e-6);
  EXPECT_LE(v, 1e-6 * (1 + 1e-12));
}

TEST(TetStrain, RigidRotationZeroStrainUniformRotation) {
  const auto x = random_points(500, 2);
  const Eigen::Vector3d omega(0.3, -0.2, 0.5);  // rad/s
  std::vector<Eigen::Vector3d> v(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) v[i] = omega.cross(x[i]);
  const auto r = tet_strain(x, v);
  Eigen::Matrix3d w;  // v = W x
  w << 0, -omega.z(), omega.y(), omega.z(), 0, -omega.x(), -omega.y(), omega.x(), 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const auto m = strain_measures(r.particle_gradient[i]);
    EXPECT_LT(m.strain.norm(), 1e-12 * w.norm());
    EXPECT_LT((m.rotation - w).norm(), 1e-12 * w.norm());
    EXPECT_LT(std::abs(m.volumetric), 1e-12 * w.norm());
    EXPECT_LT(m.equivalent_shear, 1e-12 * w.norm());
  }
}

TEST(TetStrain, StrainMeasuresOfKnownTensors) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  h(0, 0) = 0.01;
  h(1, 1) = 0.01;
  h(2, 2) = 0.01;
  auto m = strain_measures(h);
  EXPECT_DOUBLE_EQ(m.volumetric, 0.03);
  EXPECT_NEAR(m.equivalent_shear, 0.0, 1e-18);
  h.setZero();
  h(0, 1) = 0.02;  // simple shear gamma = 0.02: von Mises equivalent gamma / sqrt(3)
  m = strain_measures(h);
  EXPECT_NEAR(m.equivalent_shear, 0.02 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(m.rotation(0, 1), 0.01, 1e-18);
  EXPECT_NEAR(m.volumetric, 0.0, 1e-18);
  // 2D pure shear a: maximum tensor shear strain a.
  h.setZero();
  h(0, 0) = 0.005;
  h(1, 1) = -0.005;
  EXPECT_NEAR(strain_measures(h, 2).equivalent_shear, 0.005, 1e-16);
}

TEST(TetStrain, SingleTetGradient) {
  const std::array<Eigen::Vector3d, 4> x{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                         Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  const std::array<Eigen::Vector3d, 4> u{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3),
                                         Eigen::Vector3d(4, 5, 6), Eigen::Vector3d(7, 8, 9)};
  Eigen::Matrix3d expect;
  expect << 1, 4, 7, 2, 5, 8, 3, 6, 9;
  EXPECT_EQ(tet_gradient(x, u), expect);
  auto flat = x;
  flat[3] = Eigen::Vector3d(0.3, 0.3, 0.0);
  EXPECT_THROW(tet_gradient(flat, u), std::invalid_argument);
}

TEST(TetStrain, SliversFlaggedAndExcluded) {
  // Random points in a cube: hull tets include slivers; exactly those below the threshold are
  // flagged and they never enter the averages.
  auto x = random_points(400, 3);
  std::vector<Eigen::Vector3d> u(x.size(), Eigen::Vector3d::Zero());
  SimplexStrainOptions opt;
  opt.min_quality = 0.1;
  const auto r = tet_strain(x, u, opt);
  std::size_t slivers = 0;
  for (std::size_t t = 0; t < r.simplices.size(); ++t) {
    EXPECT_EQ(r.sliver[t] != 0, r.quality[t] < 0.1);
    EXPECT_LE(r.quality[t], 1.0 + 1e-12);
    slivers += r.sliver[t];
  }
  EXPECT_GT(slivers, 0u);
  double good = 0.0;
  for (std::size_t t = 0; t < r.simplices.size(); ++t)
    if (!r.sliver[t]) good += r.measure[t];
  EXPECT_DOUBLE_EQ(r.total_measure, good);
  // The regular tetrahedron has quality 1.
  const std::vector<Eigen::Vector3d> reg{Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, -1, -1),
                                         Eigen::Vector3d(-1, 1, -1), Eigen::Vector3d(-1, -1, 1)};
  const auto rr = tet_strain(reg, std::vector<Eigen::Vector3d>(4, Eigen::Vector3d::Zero()));
  ASSERT_EQ(rr.quality.size(), 1u);
  EXPECT_NEAR(rr.quality[0], 1.0, 1e-14);
}

TEST(TetStrain, DegenerateInputGivesClearErrors) {
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 10; ++i) plane.emplace_back(i % 3, i / 3, 0.0);
  const std::vector<Eigen::Vector3d> zero(plane.size(), Eigen::Vector3d::Zero());
  EXPECT_THROW(tet_strain(plane, zero), std::invalid_argument);
  auto x = random_points(20, 4);
  x[7] = x[3];
  try {
    delaunay_tetrahedra(x);
    FAIL() << "duplicate centres accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("points 3 and 7"), std::string::npos) << e.what();
  }
  EXPECT_THROW(delaunay_tetrahedra(random_points(3, 5)), std::invalid_argument);
  auto y = random_points(20, 6);
  std::vector<Eigen::Vector3d> u(20, Eigen::Vector3d::Zero());
  u[2].x() = std::nan("");
  EXPECT_THROW(tet_strain(y, u), std::invalid_argument);
}

TEST(TriangleStrain, AffineFieldExactBagiEq4) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ud(0.0, 0.05);
  std::vector<Eigen::Vector2d> x(1500);
  for (auto& p : x) p = Eigen::Vector2d(ud(rng), ud(rng));
  Eigen::Matrix2d l;
  l << -0.02, 0.013, 0.031, 0.008;
  std::vector<Eigen::Vector2d> v(x.size());
  // Translation of the order of l x: the rounding of the input velocities (eps |v|) then stays
  // far below 1e-12 |l| h, so the test measures the method, not the data's representation.
  for (std::size_t i = 0; i < x.size(); ++i) v[i] = Eigen::Vector2d(1e-3, -3e-3) + l * x[i];
  const auto r = triangle_strain(x, v);
  Eigen::Matrix3d l3 = Eigen::Matrix3d::Zero();
  l3.topLeftCorner<2, 2>() = l;
  for (std::size_t t = 0; t < r.simplices.size(); ++t) {
    if (r.sliver[t]) continue;
    EXPECT_LT(rel(r.gradient[t], l3), 1e-12) << t;
  }
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_LT(rel(r.particle_gradient[i], l3), 1e-12);
  EXPECT_LT(rel(r.mean_gradient, l3), 1e-12);
  // Collinear and duplicate input.
  std::vector<Eigen::Vector2d> line{{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  EXPECT_THROW(triangle_strain(line, line), std::invalid_argument);
  auto dup = x;
  dup[10] = dup[11];
  EXPECT_THROW(delaunay_triangles(dup), std::invalid_argument);
}

TEST(TetStrain, RegularTriangulationWeightedByRadius) {
  auto x = random_points(1500, 12);
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> ur(1e-4, 4e-4);
  std::vector<double> radii(x.size());
  for (auto& r : radii) r = ur(rng);
  Eigen::Matrix3d h;
  h << 0.002, -0.001, 0.004, 0.003, 0.001, -0.002, 0.0, 0.005, -0.003;
  std::vector<Eigen::Vector3d> u(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) u[i] = h * x[i];
  SimplexStrainOptions opt;
  opt.radii = radii;
  const auto r = tet_strain(x, u, opt);
  const auto d = delaunay_tetrahedra(x);
  EXPECT_NE(r.simplices, d);  // the weights change the mesh
  for (std::size_t t = 0; t < r.simplices.size(); ++t) {
    if (!r.sliver[t]) {
      EXPECT_LT(rel(r.gradient[t], h), 1e-12);
    }
  }
  EXPECT_LT(rel(r.mean_gradient, h), 1e-12);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (r.particle_valid[i]) {
      EXPECT_LT(rel(r.particle_gradient[i], h), 1e-12);
    }
  }
  opt.radii[3] = -1.0;
  EXPECT_THROW(tet_strain(x, u, opt), std::invalid_argument);
  radii.pop_back();
  EXPECT_THROW(regular_tetrahedra(x, radii), std::invalid_argument);
}

TEST(TetStrain, SameResultForAnyThreadCount) {
  const auto x = random_points(3000, 8);
  std::vector<Eigen::Vector3d> u(x.size());
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0.0, 1e-5);
  for (auto& v : u) v = Eigen::Vector3d(g(rng), g(rng), g(rng));
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto a = tet_strain(x, u);
  omp_set_num_threads(4);
  const auto b = tet_strain(x, u);
  omp_set_num_threads(saved);
  ASSERT_EQ(a.simplices, b.simplices);
  for (std::size_t t = 0; t < a.gradient.size(); ++t) ASSERT_EQ(a.gradient[t], b.gradient[t]);
  for (std::size_t i = 0; i < x.size(); ++i)
    ASSERT_EQ(a.particle_gradient[i], b.particle_gradient[i]);
  EXPECT_EQ(a.mean_gradient, b.mean_gradient);
}

}  // namespace
}  // namespace gs::analysis

namespace gs::analysis {
namespace {

TEST(DelaunayMesh, VertexRingsAreTheEdgesOfTheSimplices) {
  // Against a brute-force edge set, 2D and 3D, with a trailing vertex in no simplex.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int dim : {2, 3}) {
    std::vector<Eigen::Vector3d> p3;
    std::vector<Eigen::Vector2d> p2;
    for (int i = 0; i < 300; ++i) {
      p3.emplace_back(u(rng), u(rng), u(rng));
      p2.emplace_back(p3.back().head<2>());
    }
    const DelaunayMesh m = dim == 3 ? delaunay_mesh(p3) : delaunay_mesh(p2);
    const std::size_t n = 301;
    const VertexRings r = vertex_rings(dim, m.simplices, n);
    std::vector<std::vector<std::int32_t>> edges(n);
    for (const auto& s : m.simplices)
      for (int a = 0; a <= dim; ++a)
        for (int b = 0; b <= dim; ++b)
          if (a != b)
            edges[static_cast<std::size_t>(s[static_cast<std::size_t>(a)])].push_back(
                s[static_cast<std::size_t>(b)]);
    ASSERT_EQ(r.offset.size(), n + 1);
    for (std::size_t i = 0; i < n; ++i) {
      auto& e = edges[i];
      std::sort(e.begin(), e.end());
      e.erase(std::unique(e.begin(), e.end()), e.end());
      const std::vector<std::int32_t> ring(r.index.begin() + r.offset[i],
                                           r.index.begin() + r.offset[i + 1]);
      EXPECT_EQ(ring, e) << "dim " << dim << " vertex " << i;
    }
    EXPECT_EQ(r.size(300), 0u);
  }
}

TEST(DelaunayMesh, SameMeshForAnyThreadCountAndOrientedTetrahedra) {
  // Above 20 000 points CGAL inserts on the threads (TBB): the same tetrahedra in the same
  // canonical order as one thread, for random points and for an exact lattice (cospherical
  // points everywhere: CGAL's symbolic perturbation decides, whatever the insertion order).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> random, lattice;
  for (int i = 0; i < 25000; ++i) random.emplace_back(u(rng), u(rng), u(rng));
  for (int z = 0; z < 30; ++z)
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 30; ++x) lattice.emplace_back(x, y, z);
  const int threads = omp_get_max_threads();
  for (const auto* p : {&random, &lattice}) {
    omp_set_num_threads(1);
    const DelaunayMesh one = delaunay_mesh(*p);
    omp_set_num_threads(2);
    const DelaunayMesh two = delaunay_mesh(*p);
    omp_set_num_threads(threads);
    EXPECT_EQ(one.simplices, two.simplices);
    EXPECT_EQ(one.on_hull, two.on_hull);
    double volume = 0.0;
    for (const auto& s : one.simplices) {
      const Eigen::Vector3d &a = (*p)[static_cast<std::size_t>(s[0])],
                            &b = (*p)[static_cast<std::size_t>(s[1])],
                            &c = (*p)[static_cast<std::size_t>(s[2])],
                            &d = (*p)[static_cast<std::size_t>(s[3])];
      const double v = (b - a).dot((c - a).cross(d - a)) / 6.0;
      EXPECT_GE(v, 0.0);  // (positively oriented; lattice tetrahedra may be flat)
      volume += v;
      EXPECT_LT(s[0], std::min({s[1], s[2], s[3]}));  // the canonical form
      EXPECT_LT(s[1], std::min(s[2], s[3]));
    }
    if (p == &lattice) {
      EXPECT_NEAR(volume, 29.0 * 29.0 * 29.0, 1e-6);  // the hull's volume
    }
    EXPECT_TRUE(std::is_sorted(one.simplices.begin(), one.simplices.end()));
  }
}

TEST(DelaunayMesh, HilbertOrderIsAPermutationThatKeepsNeighboursClose) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 20000; ++i) p.emplace_back(u(rng), u(rng), u(rng));
  for (int dim : {2, 3}) {
    const auto order = hilbert_order(p, dim);
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);  // (3D from 20 000 points: CGAL's parallel split on the threads)
    const auto order1 = hilbert_order(p, dim);
    omp_set_num_threads(3);
    const auto order3 = hilbert_order(p, dim);
    omp_set_num_threads(threads);
    EXPECT_EQ(order, order1) << "dim " << dim;
    EXPECT_EQ(order, order3) << "dim " << dim;
    std::vector<std::int32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i)
      ASSERT_EQ(sorted[i], static_cast<std::int32_t>(i));
    // Consecutive points along the curve are at about the mean spacing (N^(-1/dim)); in input
    // order they are at the mean distance of two random points (~0.66 in 3D, ~0.52 in 2D).
    double along = 0.0;
    for (std::size_t i = 1; i < order.size(); ++i)
      along += (p[static_cast<std::size_t>(order[i])] - p[static_cast<std::size_t>(order[i - 1])])
                   .head(dim)
                   .norm();
    along /= static_cast<double>(order.size() - 1);
    const double spacing = std::pow(20000.0, -1.0 / dim);
    EXPECT_LT(along, 2.0 * spacing) << "dim " << dim;
  }
}

TEST(DelaunayMesh, VertexSimplicesInSimplexOrderOnAnyNumberOfThreads) {
  // Each vertex's simplices in increasing order with the vertex's place in them, the same
  // lists for 1 and 3 threads (1.3e5 tetrahedra: the threads' counting sort).
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 20000; ++i) p.emplace_back(u(rng), u(rng), u(rng));
  const DelaunayMesh m = delaunay_mesh(p);
  ASSERT_GE(m.simplices.size(), 100000u);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const VertexSimplices one = vertex_simplices(3, m.simplices, p.size());
  omp_set_num_threads(3);
  const VertexSimplices three = vertex_simplices(3, m.simplices, p.size());
  omp_set_num_threads(threads);
  EXPECT_EQ(one.offset, three.offset);
  EXPECT_EQ(one.simplex, three.simplex);
  EXPECT_EQ(one.vertex, three.vertex);
  ASSERT_EQ(one.offset.size(), p.size() + 1);
  EXPECT_EQ(one.offset.back(), static_cast<std::int64_t>(4 * m.simplices.size()));
  for (std::size_t i = 0; i < p.size(); ++i)
    for (auto e = one.offset[i]; e < one.offset[i + 1]; ++e) {
      const auto k = static_cast<std::size_t>(one.simplex[static_cast<std::size_t>(e)]);
      ASSERT_EQ(m.simplices[k][static_cast<std::size_t>(one.vertex[static_cast<std::size_t>(e)])],
                static_cast<std::int32_t>(i));
      if (e > one.offset[i]) {
        ASSERT_LT(one.simplex[static_cast<std::size_t>(e - 1)],
                  one.simplex[static_cast<std::size_t>(e)]);
      }
    }
}

}  // namespace
}  // namespace gs::analysis
