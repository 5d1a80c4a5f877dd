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

TEST(GrainSize, TwoSizesByAreaIn2D) {
  // 2D (disks, weight ∝ r²): one disk of r = 2 (4 units) and four of r = 1 (4 units): the same
  // half-way d50 = 3 by area, while by volume the small ones weigh 4 of 12 units (d50 = 10/3 by
  // interpolation between the mid-points 2/12 and 8/12).
  std::vector<double> r(4, 1.0);
  r.push_back(2.0);
  EXPECT_DOUBLE_EQ(diameter_percentile(r, 0.5, 2), 3.0);
  EXPECT_DOUBLE_EQ(diameter_percentile(r, 0.5, 3), 2.0 + 2.0 * (0.5 - 2.0 / 12) / (0.5));
  gs::Frame f;
  for (std::size_t i = 0; i < r.size(); ++i) {
    gs::Particle p;
    p.id = static_cast<std::int64_t>(i);
    p.radius = r[i];
    p.position = Eigen::Vector3d(10.0 * static_cast<double>(i), 0, 0);
    f.particles.push_back(p);
  }
  f.two_d = true;
  EXPECT_DOUBLE_EQ(diameter_percentile(f, 0.5), 3.0);
  f.two_d = false;
  EXPECT_DOUBLE_EQ(diameter_percentile(f, 0.5), diameter_percentile(r, 0.5, 3));
  EXPECT_THROW(diameter_percentile(r, 0.5, 4), std::invalid_argument);
}

TEST(GrainSize, TheD50ARunsSceneRecorded) {
  using P = std::vector<std::pair<std::string, std::string>>;
  // The key the silo and interface shear scenes write wins over the scene file.
  EXPECT_EQ(gs::analysis::recorded_d50(
                P{{"scene.toml", "[silo]\nd50_m = 0.002\n"}, {"scene.d50_m", "0.0015"}}),
            0.0015);
  // Runs written before the key: the scene file's [silo] or [interface_shear] d50_m, not one
  // of another table; a zero (the grading's d50 by mass) or an unreadable value is none.
  const std::string silo =
      "[fill]\nd50_m = 0.003\ndmin_m = 0.0005\n\n[silo]\nbottom_travel_m = "
      "0.006\nd50_m = 0.0015\ndepth_m = 0.0075\n";
  EXPECT_EQ(gs::analysis::recorded_d50(P{{"scene.toml", silo}}), 0.0015);
  EXPECT_EQ(gs::analysis::recorded_d50(P{{"scene.toml", "[interface_shear]\nd50_m = 0.001\n"}}),
            0.001);
  EXPECT_FALSE(gs::analysis::recorded_d50(P{{"scene.toml", "[fill]\nd50_m = 0.003\n"}}));
  EXPECT_FALSE(gs::analysis::recorded_d50(P{{"scene.toml", "[silo]\nd50_m = 0.0\n"}}));
  EXPECT_FALSE(gs::analysis::recorded_d50(P{{"scene.d50_m", "x"}}));
  EXPECT_FALSE(gs::analysis::recorded_d50(P{{"scene.d50_m", "-1"}}));
  EXPECT_FALSE(gs::analysis::recorded_d50(P{{"scene.name", "silo"}}));
  EXPECT_FALSE(gs::analysis::recorded_d50(P{}));
}
