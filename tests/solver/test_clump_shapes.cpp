// The seeds' clump shapes and their measures: the dimer's, in closed form; seed 004 §4.3's
// four-sphere clump against the seed's aspect ratio and convexity indices; uniform random
// orientations; spheres replaced by clumps of equal volume (seed 003 §2.4).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "clump_shapes.hpp"

using namespace gs;
using namespace gs::solver;

// Closed form for two spheres of radius r at distance 1.4 r: the union is 2·V − lens, the
// calipers 3.4 r and 2 r, the enclosing sphere 1.7 r, the hull two hemispheres and a cylinder.
TEST(ClumpShapes, DimerMeasuresInClosedForm) {
  const double r = 1e-3, d = 1.4 * r;
  const ClumpShape s = clump_shape(dimer_clump(r));
  const double lens = M_PI * std::pow(2 * r - d, 2) * (d * d + 4 * d * r) / (12 * d);
  const double v = 2 * 4.0 / 3.0 * M_PI * r * r * r - lens;
  const double hull = 4.0 / 3.0 * M_PI * r * r * r + M_PI * r * r * d;
  EXPECT_NEAR(s.volume, v, 1e-12 * v);
  EXPECT_NEAR(s.max_feret, 3.4 * r, 1e-12 * r);
  EXPECT_NEAR(s.min_feret, 2 * r, 1e-12 * r);
  EXPECT_NEAR(s.aspect_ratio, 1.7, 1e-12);
  EXPECT_NEAR(s.enclosing_radius, 1.7 * r, 1e-15);
  // The hull of 2 × 20 000 surface points: below the exact hull by O(1/points).
  EXPECT_LT(s.hull_volume, hull);
  EXPECT_NEAR(s.hull_volume, hull, 5e-4 * hull);
  std::printf("dimer: V %.6g m^3, AR %.4f, index 1 %.4f, index 2 %.4f (exact %.4f)\n", s.volume,
              s.aspect_ratio, s.convexity_sphere, s.convexity_hull, hull / v);
}

// Seed 004 §4.3: four spheres of 0.5–0.6 D, aspect ratio 1.50, convexity indices 2.07 and 1.16.
TEST(ClumpShapes, AsymmetricFourSphereClumpAgainstTheSeed) {
  const double D = 0.5e-3;
  const auto m = asymmetric_clump4(D);
  ASSERT_EQ(m.size(), 4u);
  for (const auto& s : m) {
    EXPECT_GE(2 * s.radius / D, 0.5);
    EXPECT_LE(2 * s.radius / D, 0.6);
  }
  const ClumpShape s = clump_shape(m);
  std::printf(
      "asymmetric 4-sphere clump, D = %.3g m: AR %.4f (seed 1.50), index 1 %.4f (seed "
      "2.07), index 2 %.4f (seed 1.16), V = %.4f D^3\n",
      D, s.aspect_ratio, s.convexity_sphere, s.convexity_hull, s.volume / (D * D * D));
  EXPECT_NEAR(s.max_feret, D, 1e-9 * D);  // scaled to its diameter
  EXPECT_NEAR(s.aspect_ratio, 1.50, 0.005);
  EXPECT_NEAR(s.convexity_sphere, 2.07, 0.02);
  EXPECT_NEAR(s.convexity_hull, 1.16, 0.03);
  // Asymmetric: no two principal moments equal.
  const auto mp = union_mass_properties(m, 1.0);
  const auto ax = principal_axes(mp.inertia);
  EXPECT_GT(ax.moments[1] / ax.moments[0] - 1, 0.02);
  EXPECT_GT(ax.moments[2] / ax.moments[1] - 1, 0.02);
  EXPECT_LT(mp.centroid.norm(), 1e-6 * D);  // centred on the union's centroid
}

// Shoemake's rotations are uniform: a rotated unit vector has mean 0 and second moment 𝟙/3.
TEST(ClumpShapes, RandomOrientationsAreUniform) {
  std::mt19937_64 rng(4);
  const int n = 40000;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    const Eigen::Quaterniond q = random_orientation(rng);
    ASSERT_NEAR(q.norm(), 1, 1e-15);
    const Eigen::Vector3d u = q * Eigen::Vector3d(0.6, 0, 0.8);
    mean += u / n;
    second += u * u.transpose() / n;
  }
  // Standard errors: 1/sqrt(3n) for the mean, about 0.3/sqrt(n) for the second moments.
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 4 / std::sqrt(3.0 * n));
  EXPECT_LT((second - Eigen::Matrix3d::Identity() / 3).cwiseAbs().maxCoeff(),
            4 * 0.3 / std::sqrt(n));
}

// Each sphere becomes a clump of its own volume, centred where it was, turned at random.
TEST(ClumpShapes, SpheresReplacedByClumpsOfEqualVolume) {
  std::vector<Particle> spheres;
  for (int i = 0; i < 5; ++i) {
    Particle p;
    p.id = i;
    p.position = Eigen::Vector3d(0.01 * i, 0.002, -0.003);
    p.radius = 0.4e-3 + 0.05e-3 * i;
    spheres.push_back(p);
  }
  std::mt19937_64 rng(7);
  const auto rep =
      replace_by_clumps(spheres, asymmetric_clump4(1.0), 2650, ClumpMassModel::Union, rng, 0, 0);
  ASSERT_EQ(rep.clumps.size(), 5u);
  ASSERT_EQ(rep.members.size(), 20u);
  for (std::size_t c = 0; c < 5; ++c) {
    const double r = spheres[c].radius, v = 4.0 / 3.0 * M_PI * r * r * r;
    std::vector<ClumpMember> m;
    for (const auto i : rep.clumps[c].members)
      m.push_back({rep.members[i].position, rep.members[i].radius});
    const auto mp = union_mass_properties(m, 2650);
    EXPECT_NEAR(mp.volume, v, 2e-5 * v) << c;
    EXPECT_NEAR(rep.clumps[c].mass, 2650 * v, 2e-5 * 2650 * v) << c;
    EXPECT_LT((mp.centroid - spheres[c].position).norm(), 1e-5 * r) << c;
    EXPECT_LT((rep.clumps[c].pos - spheres[c].position).norm(), 1e-5 * r) << c;
  }
  // Random orientations: the member-0 → member-1 directions differ from clump to clump.
  for (std::size_t a = 0; a < 5; ++a)
    for (std::size_t b = a + 1; b < 5; ++b) {
      auto dir = [&](std::size_t c) {
        const auto& k = rep.clumps[c].members;
        return (rep.members[k[1]].position - rep.members[k[0]].position).normalized().eval();
      };
      EXPECT_LT(dir(a).dot(dir(b)), 0.999) << a << " " << b;
    }
}
