#include <gtest/gtest.h>

#include "grain_size.hpp"

using gs::analysis::diameter_percentile;

TEST(GrainSize, MonodisperseGivesItsDiameter) {
  EXPECT_DOUBLE_EQ(diameter_percentile(std::vector<double>(10, 1e-3), 0.5), 2e-3);
  EXPECT_DOUBLE_EQ(diameter_percentile(std::vector<double>(10, 1e-3), 0.1), 2e-3);
}

TEST(GrainSize, TwoSizesByVolume) {
  // One sphere of r = 2 (volume 8 units) and eight of r = 1 (8 units): cumulative volume at the
  // small diameter (mid-point) is 4/16 = 0.25 and at the large one 12/16 = 0.75, so d50 lies
  // half-way between the diameters 2 and 4.
  std::vector<double> r(8, 1.0);
  r.push_back(2.0);
  EXPECT_DOUBLE_EQ(diameter_percentile(r, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(diameter_percentile(r, 0.25), 2.0);
  EXPECT_DOUBLE_EQ(diameter_percentile(r, 0.9), 4.0);
}

TEST(GrainSize, RejectsEmptyAndBadFraction) {
  EXPECT_THROW(diameter_percentile(std::vector<double>{}, 0.5), std::invalid_argument);
  EXPECT_THROW(diameter_percentile(std::vector<double>{1.0}, 1.5), std::invalid_argument);
}
