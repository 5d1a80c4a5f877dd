// The spatial order of particles (solver/engine/spatial_order.hpp): Morton codes by hand, the
// order of a scrambled cube of cells, ties, extents beyond 2^21 cells, bad input, and what the
// order is for (neighbours near in memory, a two-thread split into two compact halves).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include "spatial_order.hpp"

using gs::solver::morton_code;
using gs::solver::spatial_order;

TEST(SpatialOrder, MortonCodesByHand) {
  EXPECT_EQ(morton_code(0, 0, 0), 0u);
  EXPECT_EQ(morton_code(1, 0, 0), 1u);
  EXPECT_EQ(morton_code(0, 1, 0), 2u);
  EXPECT_EQ(morton_code(0, 0, 1), 4u);
  EXPECT_EQ(morton_code(1, 1, 1), 7u);
  EXPECT_EQ(morton_code(2, 0, 0), 8u);
  EXPECT_EQ(morton_code(3, 5, 6), 0b110'101'011u);  // x=011 y=101 z=110, interleaved zyx
  EXPECT_EQ(morton_code(0, 0, 1u << 20), 1ull << 62);
  const std::uint32_t top = (1u << 21) - 1;
  EXPECT_EQ(morton_code(top, top, top), (1ull << 63) - 1);
  EXPECT_EQ(morton_code(top, 0, 0), 0x1249249249249249ull);
}

TEST(SpatialOrder, ScrambledCubeOfCellsComesOutInZOrder) {
  // Centres of the 4 x 4 x 4 cells of edge 1 m (at x + 0.5), listed in a shuffled order.
  std::vector<Eigen::Vector3d> c;
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) c.emplace_back(x + 0.5, y + 0.5, z + 0.5);
  std::vector<std::size_t> shuffle(c.size());
  std::iota(shuffle.begin(), shuffle.end(), 0u);
  std::mt19937 rng(7);
  std::shuffle(shuffle.begin(), shuffle.end(), rng);
  std::vector<Eigen::Vector3d> listed(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) listed[i] = c[shuffle[i]];
  // Anchored at the lowest centre (0.5, 0.5, 0.5): cell (x, y, z) holds centre (x+.5, y+.5, z+.5).
  const auto order = spatial_order(listed, 1.0);
  ASSERT_EQ(order.size(), c.size());
  for (std::uint64_t k = 0; k < order.size(); ++k) {
    const Eigen::Vector3d& p = listed[order[k]];
    EXPECT_EQ(morton_code(static_cast<std::uint32_t>(p.x()), static_cast<std::uint32_t>(p.y()),
                          static_cast<std::uint32_t>(p.z())),
              k)
        << k;
  }
  EXPECT_EQ(listed[order[0]], Eigen::Vector3d(0.5, 0.5, 0.5));
  EXPECT_EQ(listed[order[1]], Eigen::Vector3d(1.5, 0.5, 0.5));
  EXPECT_EQ(listed[order[2]], Eigen::Vector3d(0.5, 1.5, 0.5));
  EXPECT_EQ(listed[order[7]], Eigen::Vector3d(1.5, 1.5, 1.5));
  EXPECT_EQ(listed[order[8]], Eigen::Vector3d(2.5, 0.5, 0.5));
}

TEST(SpatialOrder, TiesKeepTheirOrderAndHugeExtentsWidenTheCells) {
  // Four centres in one cell (and two touching spheres at one point): the file's order.
  const std::vector<Eigen::Vector3d> one{
      {0.2, 0.1, 0.1}, {0.1, 0.1, 0.1}, {0.1, 0.1, 0.1}, {0.3, 0.3, 0.3}};
  EXPECT_EQ(spatial_order(one, 1.0), (std::vector<std::uint32_t>{0, 1, 2, 3}));
  // 1 km along x in cells of 1 nm (1e12 of them): widened to fit 21 bits, still ordered along x.
  std::vector<Eigen::Vector3d> line;
  for (int i = 9; i >= 0; --i) line.emplace_back(100.0 * i, 0, 0);
  const auto order = spatial_order(line, 1e-9);
  for (std::uint32_t k = 0; k < 10; ++k) EXPECT_EQ(order[k], 9 - k);
  EXPECT_TRUE(spatial_order({}, 1.0).empty());
  EXPECT_EQ(spatial_order({{1, 2, 3}}, 1.0), (std::vector<std::uint32_t>{0}));
}

TEST(SpatialOrder, BadInputThrows) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Eigen::Vector3d> good{{0, 0, 0}, {1, 1, 1}};
  for (const double cell : {0.0, -1.0, nan, inf})
    EXPECT_THROW(spatial_order(good, cell), std::invalid_argument) << cell;
  EXPECT_THROW(spatial_order({{0, 0, 0}, {nan, 0, 0}}, 1.0), std::invalid_argument);
  EXPECT_THROW(spatial_order({{0, 0, 0}, {0, inf, 0}}, 1.0), std::invalid_argument);
}

// What the order is for. 4 096 spheres of a jittered 16^3 lattice (spacing h = 1), listed in
// random order: along the file's order the next sphere is on average ~0.66·16 h away, along the
// Morton order within a couple of h; and split into two halves (two threads' shares), the
// Morton order's first half is exactly the lattice's lower eight planes, so the only lattice
// neighbours cut apart are the 256 pairs across the middle plane (of 11 520), where the file's
// order cuts about half of them.
TEST(SpatialOrder, NeighboursNearInMemoryAndTwoCompactHalves) {
  const int n = 16;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<Eigen::Vector3d> lattice;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        lattice.emplace_back(x + jitter(rng), y + jitter(rng), z + jitter(rng));
  lattice[0] =
      Eigen::Vector3d::Constant(-0.25);  // the grid's corner: site (x, y, z) in cell (x, y, z)
  std::vector<std::size_t> shuffle(lattice.size());
  std::iota(shuffle.begin(), shuffle.end(), 0u);
  std::shuffle(shuffle.begin(), shuffle.end(), rng);
  std::vector<Eigen::Vector3d> listed(lattice.size());
  std::vector<std::size_t> site(lattice.size());  // listed index -> lattice index
  for (std::size_t i = 0; i < lattice.size(); ++i) {
    listed[i] = lattice[shuffle[i]];
    site[i] = shuffle[i];
  }
  const auto order = spatial_order(listed, 1.0);
  std::vector<std::size_t> rank(listed.size());  // listed index -> new index
  for (std::size_t k = 0; k < order.size(); ++k) rank[order[k]] = k;
  double step_file = 0, step_spatial = 0;
  for (std::size_t k = 1; k < listed.size(); ++k) {
    step_file += (listed[k] - listed[k - 1]).norm();
    step_spatial += (listed[order[k]] - listed[order[k - 1]]).norm();
  }
  step_file /= static_cast<double>(listed.size() - 1);
  step_spatial /= static_cast<double>(listed.size() - 1);
  EXPECT_GT(step_file, 8.0);
  EXPECT_LT(step_spatial, 2.0);
  std::vector<std::size_t> where(lattice.size());  // lattice index -> listed index
  for (std::size_t i = 0; i < listed.size(); ++i) where[site[i]] = i;
  const std::size_t half = listed.size() / 2;
  std::size_t pairs = 0, cut_file = 0, cut_spatial = 0;
  auto at = [n](int x, int y, int z) { return static_cast<std::size_t>((z * n + y) * n + x); };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        for (const auto& [dx, dy, dz] : {std::array{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}) {
          if (x + dx >= n || y + dy >= n || z + dz >= n) continue;
          const std::size_t i = where[at(x, y, z)], j = where[at(x + dx, y + dy, z + dz)];
          ++pairs;
          cut_file += (i < half) != (j < half);
          cut_spatial += (rank[i] < half) != (rank[j] < half);
        }
  EXPECT_EQ(pairs, 3u * 16 * 16 * 15);
  EXPECT_GT(cut_file, pairs * 4 / 10);
  EXPECT_EQ(cut_spatial, 16u * 16);
}
