// Exact sphere–box volume and disc–rectangle area: analytic special cases, partitions of space
// (volumes of all boxes of a grid sum to the ball), and Monte Carlo on random boxes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "sphere_box_volume.hpp"

using gs::disc_rectangle_area;
using gs::sphere_box_volume;
using gs::sphere_octant_volume;

namespace {

constexpr double kPi = std::numbers::pi;
const double kBig = 1e3;

double ball(double r) {
  return 4.0 / 3.0 * kPi * r * r * r;
}
double cap(double r, double h) {  // volume of {x > h} in the ball, |h| <= r
  return kPi * (r - h) * (r - h) * (2.0 * r + h) / 3.0;
}

TEST(SphereBoxVolume, AnalyticSpecialCases) {
  const Eigen::Vector3d c(0.3, -0.2, 1.1);
  const double r = 0.7;
  const Eigen::Vector3d big(kBig, kBig, kBig);
  EXPECT_NEAR(sphere_box_volume(c, r, c - big, c + big), ball(r), 1e-15 * ball(r));
  // Touching the box from outside and inside: no overlap / whole ball.
  EXPECT_EQ(sphere_box_volume(c, r, c + Eigen::Vector3d(r, -1, -1), c + big), 0.0);
  EXPECT_NEAR(sphere_box_volume(c, r, c - Eigen::Vector3d(r, r, r), c + Eigen::Vector3d(r, r, r)),
              ball(r), 1e-15 * ball(r));
  // Half, quarter, octant: planes through the centre.
  EXPECT_NEAR(sphere_box_volume(c, r, c - big, c + Eigen::Vector3d(0, kBig, kBig)), ball(r) / 2,
              1e-15 * ball(r));
  EXPECT_NEAR(sphere_box_volume(c, r, c - big, c + Eigen::Vector3d(0, 0, kBig)), ball(r) / 4,
              1e-15 * ball(r));
  EXPECT_NEAR(sphere_box_volume(c, r, c, c + big), ball(r) / 8, 1e-15 * ball(r));
  EXPECT_NEAR(sphere_box_volume(c, r, c - big, c), ball(r) / 8, 1e-15 * ball(r));
  // One plane at any offset: the cap; on every axis and from both sides.
  for (double h : {-0.69, -0.5, -0.1, 0.0, 0.2, 0.55, 0.699}) {
    for (int d = 0; d < 3; ++d) {
      Eigen::Vector3d lo = c - big, hi = c + big;
      lo[d] = c[d] + h;
      EXPECT_NEAR(sphere_box_volume(c, r, lo, hi), cap(r, h), 2e-15 * ball(r)) << h << " " << d;
      lo[d] = c[d] - kBig;
      hi[d] = c[d] - h;
      EXPECT_NEAR(sphere_box_volume(c, r, lo, hi), cap(r, h), 2e-15 * ball(r)) << h << " " << d;
    }
  }
  // Slab through the middle: ball minus two caps.
  EXPECT_NEAR(sphere_box_volume(c, r, c - Eigen::Vector3d(0.3, kBig, kBig),
                                c + Eigen::Vector3d(0.4, kBig, kBig)),
              ball(r) - cap(r, 0.3) - cap(r, 0.4), 2e-15 * ball(r));
  // Octant function: symmetric in its arguments (to round-off of its 2 pi terms, a few ulps);
  // quarter cap for one offset.
  EXPECT_NEAR(sphere_octant_volume(1.0, 0.1, 0.2, 0.3), sphere_octant_volume(1.0, 0.3, 0.1, 0.2),
              2e-15);
  EXPECT_NEAR(sphere_octant_volume(1.0, 0.1, 0.2, 0.3), sphere_octant_volume(1.0, 0.2, 0.3, 0.1),
              2e-15);
  EXPECT_NEAR(sphere_octant_volume(2.0, 0.0, 0.0, 0.5), cap(2.0, 0.5) / 4, 1e-14);
  EXPECT_EQ(sphere_octant_volume(1.0, 0.6, 0.6, 0.6), 0.0);  // corner outside the ball
  // Degenerate boxes.
  EXPECT_EQ(sphere_box_volume(c, r, c, c), 0.0);
  EXPECT_EQ(sphere_box_volume(c, r, c + big, c - big), 0.0);
}

TEST(SphereBoxVolume, GridPartitionSumsToTheBall) {
  // Any grid of planes partitions space; the volumes of all its boxes (bounded and unbounded)
  // must add up to the ball exactly (to round-off), whatever the planes cut.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  for (int trial = 0; trial < 50; ++trial) {
    const double r = 1.0;
    std::vector<double> planes[3];
    for (auto& p : planes) {
      p = {-kBig, kBig};
      for (int k = 0; k < 4; ++k) p.push_back(u(rng));
      std::sort(p.begin(), p.end());
    }
    double sum = 0.0, sum2d = 0.0;
    for (std::size_t i = 0; i + 1 < planes[0].size(); ++i)
      for (std::size_t j = 0; j + 1 < planes[1].size(); ++j) {
        sum2d += disc_rectangle_area(Eigen::Vector2d::Zero(), r,
                                     Eigen::Vector2d(planes[0][i], planes[1][j]),
                                     Eigen::Vector2d(planes[0][i + 1], planes[1][j + 1]));
        for (std::size_t k = 0; k + 1 < planes[2].size(); ++k)
          sum += sphere_box_volume(
              Eigen::Vector3d::Zero(), r, Eigen::Vector3d(planes[0][i], planes[1][j], planes[2][k]),
              Eigen::Vector3d(planes[0][i + 1], planes[1][j + 1], planes[2][k + 1]));
      }
    EXPECT_NEAR(sum, ball(r), 1e-13) << trial;
    EXPECT_NEAR(sum2d, kPi, 1e-13) << trial;
  }
}

TEST(SphereBoxVolume, MonteCarloOnRandomCuts) {
  // Random boxes whose faces cut the unit ball by 0 to 6 planes (some axes left uncut on one
  // side), including boxes smaller than the ball. Reference: 2e6 uniform samples in the
  // box ∩ [-1, 1]^3; tolerance 5 standard deviations of the estimate (~1e-3 of the ball volume).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.2, 1.2), s(-1.0, 1.0);
  const int samples = 2000000;
  for (int trial = 0; trial < 12; ++trial) {
    Eigen::Vector3d lo, hi;
    for (int d = 0; d < 3; ++d) {
      double a = u(rng), b = u(rng);
      if (trial % 4 == d) a = -kBig;  // leave some axes uncut on one side
      lo[d] = std::min(a, b);
      hi[d] = std::max(a, b);
    }
    const Eigen::Vector3d blo = lo.cwiseMax(-1.0), bhi = hi.cwiseMin(1.0);
    const double box = (bhi - blo).prod();
    std::uniform_real_distribution<double> ux(blo.x(), bhi.x()), uy(blo.y(), bhi.y()),
        uz(blo.z(), bhi.z());
    long hits = 0;
    for (int k = 0; k < samples; ++k) {
      const Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
      hits += p.squaredNorm() < 1.0;
    }
    const double pr = static_cast<double>(hits) / samples;
    const double mc = pr * box;
    const double sigma = box * std::sqrt(std::max(pr * (1 - pr), 1.0 / samples) / samples);
    const double exact = sphere_box_volume(Eigen::Vector3d::Zero(), 1.0, lo, hi);
    EXPECT_NEAR(exact, mc, 5 * sigma) << trial;
    // 2D: the same with the disc and the (x, y) rectangle.
    long hits2 = 0;
    for (int k = 0; k < samples; ++k) {
      const Eigen::Vector2d p(ux(rng), uy(rng));
      hits2 += p.squaredNorm() < 1.0;
    }
    const double box2 = (bhi - blo).head<2>().prod();
    const double pr2 = static_cast<double>(hits2) / samples;
    const double sigma2 = box2 * std::sqrt(std::max(pr2 * (1 - pr2), 1.0 / samples) / samples);
    EXPECT_NEAR(disc_rectangle_area(Eigen::Vector2d::Zero(), 1.0, lo.head<2>(), hi.head<2>()),
                pr2 * box2, 5 * sigma2)
        << trial;
  }
}

TEST(SphereBoxVolume, ScaleAndTranslationInvariant) {
  // vol(k B(c, r) ∩ k box) = k^3 vol(B ∩ box): the formula has no absolute length scale.
  const Eigen::Vector3d lo(-0.3, 0.1, -0.8), hi(0.5, 0.9, 0.2);
  const double v = sphere_box_volume(Eigen::Vector3d::Zero(), 1.0, lo, hi);
  for (double k : {1e-4, 2.5e-3, 7.0}) {
    const Eigen::Vector3d shift(3.0 * k, -1.0 * k, 0.5 * k);
    EXPECT_NEAR(sphere_box_volume(shift, k, k * lo + shift, k * hi + shift), v * k * k * k,
                1e-12 * k * k * k);
  }
}

}  // namespace
