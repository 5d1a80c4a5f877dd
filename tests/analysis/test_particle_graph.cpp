// Tests of analysis/particle_graph.
#include <gtest/gtest.h>

#include "particle_graph.hpp"

namespace gs::analysis {
namespace {

TEST(ParticleGraph, MergesPairsAndRejectsBadOnes) {
  const std::vector<Eigen::Vector2d> x{{0, 0}, {1, 0}, {0, 1}};
  const auto g = make_particle_graph(x, {{0, 1}, {1, 0}, {2, 0}});
  ASSERT_EQ(g.edges.size(), 2u);
  EXPECT_EQ(g.edges[0].a, 0);
  EXPECT_EQ(g.edges[0].b, 1);
  EXPECT_EQ(g.branch(1), Eigen::Vector2d(0, 1));
  EXPECT_THROW(make_particle_graph(x, {{0, 0}}), std::invalid_argument);
  EXPECT_THROW(make_particle_graph(x, {{0, 3}}), std::invalid_argument);
  EXPECT_THROW(make_particle_graph(x, {{0, 1}}, true, Eigen::Matrix2d::Zero()),
               std::invalid_argument);
  const std::vector<Eigen::Vector2d> dup{{0, 0}, {1, 0}, {1, 0}};
  EXPECT_THROW(make_particle_graph(dup, {{1, 2}}), std::invalid_argument);
  EXPECT_NO_THROW(make_particle_graph(dup, {{0, 1}, {0, 2}}));  // duplicates not in contact
}

TEST(ParticleGraph, PeriodicMinimumImage) {
  Eigen::Matrix2d cell;
  cell << 1.0, 0.2, 0.0, 1.0;  // sheared cell
  const std::vector<Eigen::Vector2d> x{{0.05, 0.05}, {0.95, 0.97}};
  const auto g = make_particle_graph(x, {{0, 1}}, true, cell);
  EXPECT_EQ(g.edges[0].shift, Eigen::Vector2i(-1, -1));
  EXPECT_LT((g.branch(0) - Eigen::Vector2d(-0.3, -0.08)).norm(), 1e-15);
}

TEST(ParticleGraph, FromFrameSkipsWallContacts) {
  Frame f;
  f.two_d = true;
  for (int i = 0; i < 3; ++i) {
    Particle p;
    p.id = 10 + i;
    p.position = Eigen::Vector3d(i, 0.5 * i, 0);
    p.radius = 0.5;
    f.particles.push_back(p);
  }
  Contact c;
  c.id1 = 10;
  c.id2 = 12;
  f.contacts.push_back(c);
  c.id2 = 99;  // a wall
  f.contacts.push_back(c);
  const auto g = particle_graph(f);
  ASSERT_EQ(g.edges.size(), 1u);
  EXPECT_EQ(g.edges[0].b, 2);
  EXPECT_FALSE(g.periodic);
}

}  // namespace
}  // namespace gs::analysis
