// The Verlet neighbour list with mixed sizes: a few particles far larger than the rest stay out
// of the grid (its cells sized for the rest) and search the cells their reach covers. The
// candidate pairs must be exactly those of the criterion |x_b − x_a| < r_a + r_b + skin (brute
// force over all pairs), and a large sphere is paired once with a mesh it reaches.
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <utility>

#include "mesh_walls.hpp"
#include "neighbor_list.hpp"
#include "simulation.hpp"

using namespace gs;
using namespace gs::solver;

namespace {

SimulationConfig config() {
  SimulationConfig c;
  c.material.young_ec = 1e7;
  c.material.stiffness_ratio = 0.3;
  c.material.friction_deg = 20;
  c.material.density = 2500;
  c.dt = 1e-6;
  return c;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> brute_sphere_pairs(const ParticleState& p,
                                                                     double skin) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> out;
  for (std::uint32_t a = 0; a < p.size(); ++a)
    for (std::uint32_t b = a + 1; b < p.size(); ++b) {
      if (p.removed[a] || p.removed[b]) continue;
      if (p.clump.size() == p.size() && p.clump[a] >= 0 && p.clump[a] == p.clump[b]) continue;
      const double reach = p.radius[a] + p.radius[b] + skin;
      if ((p.pos[b] - p.pos[a]).squaredNorm() < reach * reach * (1 + 1e-12)) out.insert({a, b});
    }
  return out;
}

}  // namespace

TEST(NeighborList, MixedSizesGiveTheBruteForcePairs) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Particle> parts;
  // 3 000 grains of r 0.9–1.1 mm in a 40 mm box (overlaps allowed: geometry only), then six
  // spheres of r = 8 mm among them, two of them touching each other, one just above the floor.
  for (int i = 0; i < 3000; ++i) {
    Particle q;
    q.id = i;
    q.radius = 0.0009 + 0.0002 * u(rng);
    q.position = Eigen::Vector3d(0.04 * u(rng), 0.04 * u(rng), 0.001 + 0.04 * u(rng));
    parts.push_back(q);
  }
  const std::vector<Eigen::Vector3d> big = {{0.01, 0.01, 0.0082}, {0.03, 0.01, 0.02},
                                            {0.03, 0.026, 0.02},  {0.01, 0.03, 0.035},
                                            {0.02, 0.02, 0.02},   {0.045, 0.045, 0.045}};
  for (std::size_t k = 0; k < big.size(); ++k) {
    Particle q;
    q.id = 3000 + static_cast<std::int64_t>(k);
    q.radius = 0.008;
    q.position = big[k];
    parts.insert(parts.begin() + 1000 * static_cast<long>(k % 3), q);  // among the grains
  }
  MeshTriangles floor;
  floor.triangles = {
      {Eigen::Vector3d(-0.1, -0.1, 0), Eigen::Vector3d(0.1, -0.1, 0), Eigen::Vector3d(0.1, 0.1, 0)},
      {Eigen::Vector3d(-0.1, -0.1, 0), Eigen::Vector3d(0.1, 0.1, 0),
       Eigen::Vector3d(-0.1, 0.1, 0)}};
  floor.group = {"floor", "floor"};
  const Simulation sim(config(), parts, mesh_walls(floor, MeshContact::Merged));
  const ParticleState& p = sim.particles();
  NeighborList nl;
  nl.skin = 0.00045;
  nl.build(p, sim.walls());
  std::set<std::pair<std::uint32_t, std::uint32_t>> spheres, walls;
  for (const auto& pr : nl.pairs) {
    EXPECT_TRUE((pr.second >= kWallBase ? walls : spheres).insert(pr).second)
        << pr.first << " " << pr.second;  // no pair twice
  }
  const auto expected = brute_sphere_pairs(p, nl.skin);
  EXPECT_EQ(spheres, expected);
  std::size_t with_big = 0;
  for (const auto& pr : expected)
    with_big += p.radius[pr.first] > 0.005 || p.radius[pr.second] > 0.005;
  EXPECT_GT(with_big, 300u);  // the large spheres have many grains in reach
  // The floor: every sphere closer than r + skin, once each (the one large sphere among them).
  std::set<std::pair<std::uint32_t, std::uint32_t>> floor_pairs;
  for (std::uint32_t i = 0; i < p.size(); ++i)
    if (p.pos[i].z() < p.radius[i] + nl.skin) floor_pairs.insert({i, kWallBase});
  EXPECT_EQ(walls, floor_pairs);
  std::size_t big_on_floor = 0;
  for (const auto& pr : walls) big_on_floor += p.radius[pr.first] > 0.005;
  EXPECT_EQ(big_on_floor, 1u);
  // Sorted by (a, b), as every consumer expects.
  EXPECT_TRUE(std::is_sorted(nl.pairs.begin(), nl.pairs.end()));
}
