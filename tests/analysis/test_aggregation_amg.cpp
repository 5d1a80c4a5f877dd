// Smoothed-aggregation AMG (analysis/aggregation_amg.hpp): against a direct solve, symmetry and
// positivity of the V-cycle, a coefficient jump of 1e6, bad input.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>

#include "aggregation_amg.hpp"

namespace gs::analysis {
namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Finite-volume Laplacian on an m³ grid, zero Dirichlet values outside; the face conductance
// is the harmonic mean of the cells' coefficients: 1, or `jump` in the cells with x < m/2.
SpMat grid_laplacian(int m, double jump) {
  auto id = [m](int x, int y, int z) { return (z * m + y) * m + x; };
  auto coef = [&](int x) { return x < m / 2 ? jump : 1.0; };
  std::vector<Eigen::Triplet<double, int>> t;
  for (int z = 0; z < m; ++z)
    for (int y = 0; y < m; ++y)
      for (int x = 0; x < m; ++x) {
        const int i = id(x, y, z);
        double diag = 0.0;
        const int nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z},
                              {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
        for (const auto& q : nb) {
          const double cx = coef(x), cq = (q[0] >= 0 && q[0] < m) ? coef(q[0]) : cx;
          const double c = 2.0 * cx * cq / (cx + cq);
          diag += c;
          if (q[0] < 0 || q[0] >= m || q[1] < 0 || q[1] >= m || q[2] < 0 || q[2] >= m) continue;
          t.emplace_back(i, id(q[0], q[1], q[2]), -c);
        }
        t.emplace_back(i, i, diag);
      }
  SpMat a(m * m * m, m * m * m);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

Eigen::MatrixXd random_columns(Eigen::Index n, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  Eigen::MatrixXd b(n, cols);
  for (Eigen::Index i = 0; i < b.size(); ++i) b.data()[i] = g(rng);
  return b;
}

TEST(AggregationAmg, PcgMatchesADirectSolve) {
  for (const double jump : {1.0, 1e6}) {  // (a huge coefficient ratio across x = m/2)
    const SpMat a = grid_laplacian(24, jump);
    const AmgHierarchy h = build_amg(a);
    ASSERT_GE(h.levels.size(), 2u);
    EXPECT_LT(h.levels[1].a.rows(), a.rows() / 8);  // (it coarsens)
    const Eigen::MatrixXd b = random_columns(a.rows(), 3, 7);
    int its = 0;
    bool ok = false;
    const Eigen::MatrixXd x = amg_pcg(h, b, 1e-12, 500, its, ok);
    EXPECT_TRUE(ok);
    EXPECT_LT(its, 25) << "jump " << jump;  // (17 and 18 here; Jacobi-CG needs hundreds)
    const Eigen::SimplicialLDLT<SpMat> direct(a);
    const Eigen::MatrixXd xd = direct.solve(b);
    EXPECT_LT((x - xd).norm(), 1e-9 * xd.norm()) << "jump " << jump;
    for (int c = 0; c < 3; ++c)
      EXPECT_LE((b.col(c) - a * x.col(c)).norm(), 1e-12 * b.col(c).norm());
  }
}

TEST(AggregationAmg, VcycleIsSymmetricPositiveDefinite) {
  // Conjugate gradients needs a fixed SPD preconditioner: xᵀV(y) = yᵀV(x) and xᵀV(x) > 0.
  const SpMat a = grid_laplacian(16, 1e3);
  const AmgHierarchy h = build_amg(a);
  const Eigen::MatrixXd x = random_columns(a.rows(), 1, 1), y = random_columns(a.rows(), 1, 2);
  const double xvy = x.col(0).dot(amg_vcycle(h, y).col(0));
  const double yvx = y.col(0).dot(amg_vcycle(h, x).col(0));
  EXPECT_NEAR(xvy, yvx, 1e-12 * std::abs(xvy));
  for (unsigned s = 3; s < 8; ++s) {
    const Eigen::MatrixXd z = random_columns(a.rows(), 1, s);
    EXPECT_GT(z.col(0).dot(amg_vcycle(h, z).col(0)), 0.0);
  }
  // Columns are independent: a block of two gives each column's own cycle.
  Eigen::MatrixXd xy(a.rows(), 2);
  xy << x, y;
  const Eigen::MatrixXd both = amg_vcycle(h, xy);
  EXPECT_EQ(Eigen::MatrixXd(both.col(1)), amg_vcycle(h, y));
}

TEST(AggregationAmg, GalerkinCoarseMatricesAndColumnsSolvedAsAlone) {
  const SpMat a = grid_laplacian(20, 1e2);
  const AmgHierarchy h = build_amg(a);
  ASSERT_GE(h.levels.size(), 3u);
  // Every coarse matrix is RAP of the level above (the hand-written sparse products against
  // Eigen's), symmetric, and R = Pᵀ.
  for (std::size_t l = 0; l + 1 < h.levels.size(); ++l) {
    const auto& L = h.levels[l];
    using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
    const RowMat rap = L.r * (L.a * L.p);
    const RowMat next = h.levels[l + 1].a;
    EXPECT_LT((rap - next).norm(), 1e-13 * next.norm()) << "level " << l;
    EXPECT_EQ((RowMat(next.transpose()) - next).norm(), 0.0) << "level " << l;
    EXPECT_EQ((RowMat(L.p.transpose()) - L.r).norm(), 0.0) << "level " << l;
  }
  // Three columns converging at different iterations (one scaled, one from a smooth solution):
  // each column gets the bits and the iteration count of its own solve.
  Eigen::MatrixXd b = random_columns(a.rows(), 3, 11);
  b.col(1) *= 1e-8;
  Eigen::VectorXd smooth(a.rows());
  for (Eigen::Index i = 0; i < a.rows(); ++i) smooth(i) = std::sin(0.001 * static_cast<double>(i));
  b.col(2) = a * smooth;
  int its = 0;
  bool ok = false;
  std::vector<int> column_its;
  const Eigen::MatrixXd x = amg_pcg(h, b, 1e-10, 200, its, ok, &column_its);
  ASSERT_TRUE(ok);
  ASSERT_EQ(column_its.size(), 3u);
  EXPECT_EQ(its, *std::max_element(column_its.begin(), column_its.end()));
  for (int c = 0; c < 3; ++c) {
    int its1 = 0;
    bool ok1 = false;
    const Eigen::MatrixXd x1 = amg_pcg(h, b.col(c), 1e-10, 200, its1, ok1);
    EXPECT_TRUE(ok1);
    EXPECT_EQ(its1, column_its[static_cast<std::size_t>(c)]) << "column " << c;
    EXPECT_EQ(Eigen::VectorXd(x.col(c)), Eigen::VectorXd(x1.col(0))) << "column " << c;
    EXPECT_LE((b.col(c) - a * x.col(c)).norm(), 1e-10 * b.col(c).norm());
  }
}

// The poll (the Python package's Ctrl-C): called every 8 iterations, between two iterations, so
// that it changes no iterate; what it throws ends the solve. A tolerance no solve reaches keeps
// the iterations going to the limit.
TEST(AggregationAmg, PollIsCalledEveryEightIterationsAndMayStopTheSolve) {
  const SpMat a = grid_laplacian(16, 100.0);
  const AmgHierarchy h = build_amg(a);
  ASSERT_GT(h.levels.size(), 1u);
  const Eigen::MatrixXd b = random_columns(a.rows(), 2, 5);
  int its = 0, calls = 0;
  bool ok = true;
  const Eigen::MatrixXd polled = amg_pcg(h, b, 1e-300, 30, its, ok, nullptr, [&] { ++calls; });
  EXPECT_FALSE(ok);
  EXPECT_EQ(its, 30);
  EXPECT_EQ(calls, 3);  // after iterations 8, 16 and 24
  const Eigen::MatrixXd plain = amg_pcg(h, b, 1e-300, 30, its, ok);
  EXPECT_EQ(polled, plain);
  calls = 0;
  EXPECT_THROW(amg_pcg(h, b, 1e-300, 1000000, its, ok, nullptr,
                       [&] {
                         if (++calls == 2) throw std::runtime_error("interrupted");
                       }),
               std::runtime_error);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(its, 16);
}

TEST(AggregationAmg, RowMajorMatrixGivenUpBuildsTheSameHierarchy) {
  // The row-major overload takes the matrix's storage (no copy) and builds what the
  // column-major one builds from the same symmetric matrix, to the bit.
  using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
  const SpMat a = grid_laplacian(20, 1e2);
  const AmgHierarchy h = build_amg(a);
  RowMat rows = a;
  const AmgHierarchy g = build_amg(std::move(rows));
  EXPECT_EQ(rows.nonZeros(), 0);  // (given up)
  ASSERT_EQ(g.levels.size(), h.levels.size());
  for (std::size_t l = 0; l < h.levels.size(); ++l) {
    EXPECT_EQ((g.levels[l].a - h.levels[l].a).norm(), 0.0) << "level " << l;
    EXPECT_EQ((g.levels[l].p - h.levels[l].p).norm(), 0.0) << "level " << l;
    EXPECT_EQ(g.levels[l].omega, h.levels[l].omega) << "level " << l;
  }
  const Eigen::MatrixXd b = random_columns(a.rows(), 2, 5);
  EXPECT_EQ(amg_vcycle(g, b), amg_vcycle(h, b));
  EXPECT_THROW(build_amg(RowMat(3, 4)), std::invalid_argument);
}

TEST(AggregationAmg, MaxLevelsBoundsTheHierarchy) {
  const SpMat a = grid_laplacian(20, 1.0);
  const std::size_t free_levels = build_amg(a).levels.size();
  ASSERT_GE(free_levels, 3u);
  for (int max_levels = 2; max_levels <= static_cast<int>(free_levels); ++max_levels) {
    AmgOptions o;
    o.max_levels = max_levels;
    EXPECT_EQ(build_amg(a, o).levels.size(), static_cast<std::size_t>(max_levels));
  }
  // One level: no coarsening, the V-cycle is the direct solve (8³ unknowns, above `coarsest`).
  const SpMat small = grid_laplacian(8, 1.0);
  ASSERT_GE(build_amg(small).levels.size(), 2u);
  AmgOptions one;
  one.max_levels = 1;
  const AmgHierarchy h = build_amg(small, one);
  ASSERT_EQ(h.levels.size(), 1u);
  const Eigen::MatrixXd b = random_columns(small.rows(), 1, 3);
  const Eigen::MatrixXd x = Eigen::SimplicialLDLT<SpMat>(small).solve(b);
  EXPECT_LT((amg_vcycle(h, b) - x).norm(), 1e-10 * x.norm());
}

TEST(AggregationAmg, VcycleWritesIntoAnyRowMajorBlockOfTheRightSize) {
  const SpMat a = grid_laplacian(20, 1.0);
  const AmgHierarchy h = build_amg(a);
  ASSERT_GE(h.levels.size(), 2u);
  // Three and four columns (the vector row sums) give each column's one-column cycle (the
  // scalar loop), written straight into an N×3 matrix or a block.
  const Eigen::MatrixXd b = random_columns(a.rows(), 4, 21);
  AmgWorkspace w;
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x3(a.rows(), 3);
  amg_vcycle(h, AmgBlock(b.leftCols(3)), x3, w);
  AmgBlock x4(a.rows(), 4);
  amg_vcycle(h, AmgBlock(b), x4, w);
  for (int c = 0; c < 4; ++c) {
    const Eigen::MatrixXd alone = amg_vcycle(h, Eigen::MatrixXd(b.col(c)));
    EXPECT_EQ(Eigen::VectorXd(x4.col(c)), Eigen::VectorXd(alone.col(0))) << "column " << c;
    if (c < 3) {
      EXPECT_EQ(Eigen::VectorXd(x3.col(c)), Eigen::VectorXd(alone.col(0))) << "column " << c;
    }
  }
  AmgBlock wrong(a.rows(), 2);
  EXPECT_THROW(amg_vcycle(h, AmgBlock(b.leftCols(3)), wrong, w), std::invalid_argument);
}

TEST(AggregationAmg, SmallMatrixIsSolvedDirectly) {
  const SpMat a = grid_laplacian(5, 1.0);  // 125 unknowns: below the coarsest size
  const AmgHierarchy h = build_amg(a);
  EXPECT_EQ(h.levels.size(), 1u);
  const Eigen::MatrixXd b = random_columns(a.rows(), 2, 9);
  int its = 0;
  bool ok = false;
  const Eigen::MatrixXd x = amg_pcg(h, b, 1e-14, 10, its, ok);
  EXPECT_TRUE(ok);
  EXPECT_EQ(its, 1);
  EXPECT_LT((a * x - b).norm(), 1e-12 * b.norm());
  // A zero right-hand side is solved by zero, at once.
  const Eigen::MatrixXd x0 = amg_pcg(h, Eigen::MatrixXd::Zero(a.rows(), 1), 1e-10, 10, its, ok);
  EXPECT_TRUE(ok);
  EXPECT_EQ(its, 0);
  EXPECT_EQ(x0.norm(), 0.0);
}

TEST(AggregationAmg, BadInputThrows) {
  EXPECT_THROW(build_amg(SpMat(3, 4)), std::invalid_argument);
  SpMat a = grid_laplacian(4, 1.0);
  a.coeffRef(5, 5) = -1.0;
  EXPECT_THROW(build_amg(a), std::invalid_argument);
  int its = 0;
  bool ok = false;
  EXPECT_THROW(amg_pcg(AmgHierarchy{}, Eigen::MatrixXd::Ones(3, 1), 1e-8, 10, its, ok),
               std::invalid_argument);
}

}  // namespace
}  // namespace gs::analysis
