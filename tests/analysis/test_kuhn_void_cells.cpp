// Tests of analysis/kuhn_void_cells (seed 002): removals, Euler, exact eq 7 / eq 3, eq 18-21.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "kuhn_void_cells.hpp"
#include "tet_strain.hpp"

namespace gs::analysis {
namespace {

// Fig. 4 situations around a 3 x 3 grid framework (4 unit square cells).
ParticleGraph fig4_graph() {
  std::vector<Eigen::Vector2d> x;
  std::vector<std::pair<std::int32_t, std::int32_t>> e;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) x.emplace_back(i, j);  // vertex 3 j + i
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 2; ++i) {
      e.emplace_back(3 * j + i, 3 * j + i + 1);
      e.emplace_back(3 * i + j, 3 * i + j + 3);
    }
  x.emplace_back(10, 10);  // 9: isolated
  x.emplace_back(3, 0);    // 10, 11: pendant chain off vertex 2
  x.emplace_back(4, 0);
  e.emplace_back(2, 10);
  e.emplace_back(10, 11);
  x.emplace_back(0, -1);  // 12, 13, 14: peninsula (triangle) joined to vertex 0 by one edge
  x.emplace_back(-0.5, -2);
  x.emplace_back(0.5, -2);
  e.emplace_back(0, 12);
  e.emplace_back(12, 13);
  e.emplace_back(13, 14);
  e.emplace_back(14, 12);
  x.emplace_back(10, 0);  // 15, 16, 17: island triangle
  x.emplace_back(11, 0);
  x.emplace_back(10.5, 1);
  e.emplace_back(15, 16);
  e.emplace_back(16, 17);
  e.emplace_back(17, 15);
  x.emplace_back(1.4, 1.5);  // 18, 19: pendant pair inside cell, hanging from vertex 4
  x.emplace_back(1.6, 1.6);
  e.emplace_back(4, 18);
  e.emplace_back(18, 19);
  x.emplace_back(0.3, 0.3);  // 20, 21, 22: island triangle floating inside the cell [0,1]^2
  x.emplace_back(0.7, 0.3);
  x.emplace_back(0.5, 0.7);
  e.emplace_back(20, 21);
  e.emplace_back(21, 22);
  e.emplace_back(22, 20);
  return make_particle_graph(x, e);
}

TEST(KuhnVoidCells, Fig4RemovalsAndEuler) {
  const auto g = fig4_graph();
  const auto c = find_void_cells(g);
  EXPECT_EQ(c.removed_isolated, 1);
  EXPECT_EQ(c.removed_pendant, 4);
  EXPECT_EQ(c.removed_peninsular, 3);
  EXPECT_EQ(c.removed_island, 6);
  EXPECT_EQ(c.vertices, 9);
  EXPECT_EQ(c.edges, 12);
  EXPECT_EQ(c.faces, 4);
  EXPECT_EQ(c.euler(), 1);
  EXPECT_EQ(c.expected_euler, 1);
  ASSERT_EQ(c.cells.size(), 4u);
  for (const auto& cell : c.cells) {
    EXPECT_EQ(cell.vertices.size(), 4u);
    EXPECT_DOUBLE_EQ(cell.area, 1.0);
  }
  for (int v = 0; v < 9; ++v) EXPECT_TRUE(c.vertex_active[static_cast<std::size_t>(v)]);
  for (std::size_t v = 9; v < 23; ++v) EXPECT_FALSE(c.vertex_active[v]);
}

// Contacts from a random point set: Delaunay edges shorter than `cut` x mean spacing (a random
// packing with gaps), periodic by 3 x 3 replication of the cell.
ParticleGraph random_packing(std::size_t n, unsigned seed, bool periodic, double cut,
                             const Eigen::Matrix2d& cell) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector2d> x(n);
  for (auto& p : x) p = cell * Eigen::Vector2d(u(rng), u(rng));
  const double spacing = std::sqrt(std::abs(cell.determinant()) / static_cast<double>(n));
  std::vector<Eigen::Vector2d> all;
  std::vector<std::int32_t> owner;
  const int reach = periodic ? 1 : 0;
  for (int j = -reach; j <= reach; ++j)
    for (int i = -reach; i <= reach; ++i)
      for (std::size_t k = 0; k < n; ++k) {
        all.push_back(x[k] + cell * Eigen::Vector2d(i, j));
        owner.push_back(static_cast<std::int32_t>(k));
      }
  std::set<std::pair<std::int32_t, std::int32_t>> pairs;
  for (const auto& t : delaunay_triangles(all)) {
    for (int a = 0; a < 3; ++a) {
      const auto p = static_cast<std::size_t>(t[static_cast<std::size_t>(a)]);
      const auto q = static_cast<std::size_t>(t[static_cast<std::size_t>((a + 1) % 3)]);
      if ((all[q] - all[p]).norm() > cut * spacing) continue;
      const auto i = owner[p], j = owner[q];
      pairs.emplace(std::min(i, j), std::max(i, j));
    }
  }
  return make_particle_graph(x, {pairs.begin(), pairs.end()}, periodic, cell);
}

TEST(KuhnVoidCells, EulerOnRandomPeriodicPackings) {
  Eigen::Matrix2d cell;
  cell << 0.02, 0.004, 0.0, 0.015;  // sheared periodic cell, m
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const auto g = random_packing(600, seed, true, 1.4, cell);
    const auto c = find_void_cells(g);
    EXPECT_EQ(c.expected_euler, 0);
    EXPECT_EQ(c.euler(), 0) << "seed " << seed << ": L " << c.faces << " M " << c.edges << " N "
                            << c.vertices;
    EXPECT_EQ(static_cast<std::int64_t>(c.cells.size()), c.faces);
    EXPECT_GT(c.removed_pendant + c.removed_isolated, 0);
    double area = 0.0;
    std::set<std::size_t> valences;
    for (const auto& vc : c.cells) {
      area += vc.area;
      valences.insert(vc.vertices.size());
    }
    EXPECT_NEAR(area, cell.determinant(), 1e-12 * cell.determinant());  // cells tile the torus
    EXPECT_GE(valences.size(), 4u);  // polygons of several valences, not only triangles
  }
}

TEST(KuhnVoidCells, AffineFieldExactPeriodic) {
  Eigen::Matrix2d cell;
  cell << 0.02, 0.004, 0.0, 0.015;
  const auto g = random_packing(800, 9, true, 1.3, cell);
  const auto c = find_void_cells(g);
  Eigen::Matrix2d l;
  l << 0.013, -0.021, 0.007, -0.009;
  std::vector<Eigen::Vector2d> v(g.position.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = l * g.position[i];
  const auto d = void_cell_deformation(g, c, v, 1e-3, l * cell);
  for (std::size_t i = 0; i < c.cells.size(); ++i) {
    EXPECT_LT((d.gradient[i] - l).norm(), 1e-12 * l.norm()) << i;
    EXPECT_NEAR(d.alpha[i], 1.0, 1e-12);
  }
  EXPECT_LT((d.mean - l).norm(), 1e-12 * l.norm());
  for (std::size_t k = 0; k < v.size(); ++k) EXPECT_LT(d.relative_velocity[k].norm(), 1e-10);
}

TEST(KuhnVoidCells, AffineAndRotationBounded) {
  const auto g = random_packing(700, 21, false, 1.5, Eigen::Matrix2d::Identity() * 0.03);
  const auto c = find_void_cells(g);
  EXPECT_EQ(c.euler(), 1);
  Eigen::Matrix2d l;
  l << -0.01, 0.002, 0.004, 0.02;
  const Eigen::Vector2d v0(5e-4, -2.5e-4);  // of the order of l x (see test_tet_strain.cpp)
  std::vector<Eigen::Vector2d> v(g.position.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = v0 + l * g.position[i];
  const double d50 = 1e-3;
  auto d = void_cell_deformation(g, c, v, d50);
  for (const auto& gi : d.gradient) EXPECT_LT((gi - l).norm(), 1e-12 * l.norm());
  EXPECT_LT((d.mean - l).norm(), 1e-12 * l.norm());
  // eq 21: only the translation remains, scaled by D50 |L22|.
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!c.vertex_active[k]) continue;
    EXPECT_LT((d.relative_velocity[k] - v0 / (d50 * 0.02)).norm(), 1e-9);
  }
  // Rigid rotation: zero strain, w = sqrt(2) sign(omega) in every cell (eq 20), alpha = 1.
  const double omega = -0.7;
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = omega * Eigen::Vector2d(-g.position[i].y(), g.position[i].x());
  d = void_cell_deformation(g, c, v, d50);
  for (std::size_t i = 0; i < c.cells.size(); ++i) {
    const Eigen::Matrix2d s = 0.5 * (d.gradient[i] + d.gradient[i].transpose());
    EXPECT_LT(s.norm(), 1e-12 * std::abs(omega));
    EXPECT_NEAR(d.w[i], -std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(d.alpha[i], 1.0, 1e-12);
  }
}

TEST(KuhnVoidCells, TriangleEq7EqualsBagiEq4) {
  const std::array<Eigen::Vector2d, 3> x{Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(1.3, 0.1),
                                         Eigen::Vector2d(0.4, 0.9)};
  const std::array<Eigen::Vector2d, 3> v{Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(1.1, 0.5),
                                         Eigen::Vector2d(-0.6, 0.4)};
  const auto a = bagi_triangle_gradient(x, v);
  const auto b = void_cell_gradient({x.begin(), x.end()}, {v.begin(), v.end()});
  EXPECT_LT((a - b).norm(), 1e-13 * a.norm());
  EXPECT_THROW(bagi_triangle_gradient({x[0], x[2], x[1]}, v), std::invalid_argument);
}

TEST(KuhnVoidCells, DegenerateInput) {
  // Collinear chain: everything is pendant, no cell -> clear error.
  const std::vector<Eigen::Vector2d> line{{0, 0}, {1, 0}, {2, 0}, {3, 0}};
  const auto g = make_particle_graph(line, {{0, 1}, {1, 2}, {2, 3}});
  EXPECT_THROW(find_void_cells(g), std::invalid_argument);
  // Zero velocity field: alpha, w, relative velocity are 0, never NaN.
  const auto g2 = fig4_graph();
  const auto c = find_void_cells(g2);
  const auto d =
      void_cell_deformation(g2, c, std::vector<Eigen::Vector2d>(23, Eigen::Vector2d::Zero()), 1.0);
  for (std::size_t i = 0; i < c.cells.size(); ++i) {
    EXPECT_EQ(d.alpha[i], 0.0);
    EXPECT_EQ(d.w[i], 0.0);
  }
  EXPECT_THROW(void_cell_deformation(g2, c, std::vector<Eigen::Vector2d>(3), 1.0),
               std::invalid_argument);
  EXPECT_THROW(void_cell_gradient({{0, 0}, {1, 0}, {2, 0}}, {{0, 0}, {0, 0}, {0, 0}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace gs::analysis
