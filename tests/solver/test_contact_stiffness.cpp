#include <gtest/gtest.h>

#include <cmath>

#include "contact_stiffness.hpp"

using gs::solver::contact_stiffness;
using gs::solver::RollingRadius;

TEST(ContactStiffness, HandComputedPair) {
  // Ec = 300 MPa, nu_c = 0.3, beta = 0.7, RA = 1 mm, RB = 3 mm.
  const auto k = contact_stiffness(3e8, 0.3, 0.7, 1e-3, 3e-3, RollingRadius::Mean);
  EXPECT_DOUBLE_EQ(k.kn, 3e8 * 2 * 3e-6 / 4e-3);  // 450 000 N/m
  EXPECT_DOUBLE_EQ(k.ks, 0.3 * 450000.0);
  EXPECT_DOUBLE_EQ(k.kr, 0.7 * 135000.0 * 3e-6);
  EXPECT_DOUBLE_EQ(k.rolling_radius_m, 2e-3);
  EXPECT_DOUBLE_EQ(
      contact_stiffness(3e8, 0.3, 0.7, 1e-3, 3e-3, RollingRadius::Min).rolling_radius_m, 1e-3);
}

TEST(ContactStiffness, WallConventionEqualRadii) {
  // Sphere–box: both radii = R gives Kn = Ec·R and Kr = beta·Ks·R².
  const double R = 2e-3;
  const auto k = contact_stiffness(3e7, 0.3, 0.7, R, R, RollingRadius::Min);
  EXPECT_DOUBLE_EQ(k.kn, 3e7 * R);
  EXPECT_DOUBLE_EQ(k.kr, 0.7 * 0.3 * 3e7 * R * R * R);
}

TEST(ContactStiffness, RejectsDegenerateInput) {
  EXPECT_THROW(contact_stiffness(3e8, 0.3, 0.7, 0.0, 1e-3, RollingRadius::Min),
               std::invalid_argument);
  EXPECT_THROW(contact_stiffness(3e8, 0.3, 0.7, -1e-3, 1e-3, RollingRadius::Min),
               std::invalid_argument);
  EXPECT_THROW(contact_stiffness(0.0, 0.3, 0.7, 1e-3, 1e-3, RollingRadius::Min),
               std::invalid_argument);
  EXPECT_THROW(contact_stiffness(3e8, 0.3, 0.7, std::nan(""), 1e-3, RollingRadius::Min),
               std::invalid_argument);
}
