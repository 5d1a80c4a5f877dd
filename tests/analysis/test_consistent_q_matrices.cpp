// Tests of analysis/consistent_q_matrices: seed 002 Table 1 and eq 7 exactness.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "consistent_q_matrices.hpp"
#include "kuhn_void_cells.hpp"

namespace gs::analysis {
namespace {

TEST(ConsistentQ, Table1) {
  // Seed 002 Table 1, by directed separation q - p (mod m). The printed m = 5, separation 4
  // entry (-3/5) contradicts antisymmetry (Q^5(1) = 9/5) and exactness; -9/5 is used.
  const std::vector<std::vector<double>> table{{0, 3.0 / 3, -3.0 / 3},
                                               {0, 6.0 / 4, 0, -6.0 / 4},
                                               {0, 9.0 / 5, 3.0 / 5, -3.0 / 5, -9.0 / 5},
                                               {0, 12.0 / 6, 6.0 / 6, 0, -6.0 / 6, -12.0 / 6}};
  for (int m = 3; m <= 6; ++m) {
    const auto& row = table[static_cast<std::size_t>(m - 3)];
    const auto q = consistent_q_matrix(m);
    for (int p = 0; p < m; ++p) {
      for (int qq = 0; qq < m; ++qq) {
        const double expect = row[static_cast<std::size_t>(((qq - p) % m + m) % m)];
        EXPECT_NEAR(q(p, qq), expect, 4e-16) << "m " << m << " p " << p << " q " << qq;
      }
    }
  }
  EXPECT_TRUE(consistent_q_matrix(2).isZero());
  EXPECT_THROW(consistent_q_matrix(1), std::invalid_argument);
}

TEST(ConsistentQ, ClosedFormAndAntisymmetry) {
  for (int m = 3; m <= 20; ++m) {
    const auto q = consistent_q_separations(m);
    for (int s = 1; s < m; ++s) {
      EXPECT_NEAR(q[static_cast<std::size_t>(s)], 3.0 * (m - 2 * s) / m, 1e-13) << m << " " << s;
    }
    const auto qm = consistent_q_matrix(m);
    EXPECT_LT((qm + qm.transpose()).norm(), 1e-13);
  }
}

TEST(ConsistentQ, Eq7ExactOnRandomPolygons) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int m = 3; m <= 12; ++m) {
    // Star-shaped polygon around the origin, counterclockwise, radius 1 mm +- 30 %.
    std::vector<Eigen::Vector2d> x(static_cast<std::size_t>(m)), v(x.size());
    for (int k = 0; k < m; ++k) {
      const double a = 2 * M_PI * (k + 0.3 * u(rng) + 0.5) / m;
      const double r = 1e-3 * (1.0 + 0.3 * u(rng));
      x[static_cast<std::size_t>(k)] = Eigen::Vector2d(5e-3 + r * std::cos(a), r * std::sin(a));
    }
    Eigen::Matrix2d l;
    l << u(rng), u(rng), u(rng), u(rng);
    const Eigen::Vector2d v0(u(rng), u(rng));
    for (std::size_t k = 0; k < x.size(); ++k) v[k] = v0 + l * x[k];
    const auto g = void_cell_gradient(x, v);
    EXPECT_LT((g - l).norm(), 1e-12 * l.norm()) << "m " << m;
  }
}

}  // namespace
}  // namespace gs::analysis
