// The model silo's walls (seed 004 §5.2, Fig 5.2–5.3): side walls of saw-tooth asperities of
// height h_g = R_n·d50 at s_g = 4·h_g with 45° faces, a bottom plate (or its parts beside an
// outlet), front and back planes; and what the geometry refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "silo_flow.hpp"

using namespace gs;
using solver::SiloSpec;
using solver::SiloWalls;

namespace {

/// Extent of the triangles of walls [begin, end) along axis a.
std::pair<double, double> extent(const std::vector<solver::WallSpec>& w, std::size_t begin,
                                 std::size_t end, int a) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (std::size_t k = begin; k < end; ++k)
    for (const auto& f : w[k].facets)
      for (const auto& v : f.vertex) {
        const double x = (w[k].center + (f.offset + v).eigen())[a];
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
  return {lo, hi};
}

}  // namespace

TEST(SiloWalls, SideWallsCarryTheSeedsTeeth) {
  SiloSpec s;  // the seed's 0.2 × 0.5 × 0.0075 m silo, R_n = 1, quasi-static (u = 30 mm)
  SiloWalls idx;
  const double d50 = 1.5e-3, dmax = 2.5e-3;
  const auto w = solver::silo_walls(s, d50, dmax, idx);
  EXPECT_DOUBLE_EQ(idx.tooth_height_m, 1.5e-3);
  EXPECT_DOUBLE_EQ(idx.tooth_spacing_m, 6e-3);
  EXPECT_DOUBLE_EQ(idx.floor_z_m, -(0.03 + 2 * dmax));  // below the bottom by its travel
  // Left wall: from its base plane x = 0 to the tips at x = h_g, over the full depth and from
  // the floor to the top; the right wall mirrors it at x = b_s.
  const auto [lx0, lx1] = extent(w, idx.left_begin, idx.left_end, 0);
  const auto [rx0, rx1] = extent(w, idx.right_begin, idx.right_end, 0);
  EXPECT_NEAR(lx0, 0, 1e-15);
  EXPECT_NEAR(lx1, 1.5e-3, 1e-15);
  EXPECT_NEAR(rx0, 0.2 - 1.5e-3, 1e-15);
  EXPECT_NEAR(rx1, 0.2, 1e-15);
  const auto [ly0, ly1] = extent(w, idx.left_begin, idx.left_end, 1);
  EXPECT_NEAR(ly0, 0, 1e-15);
  EXPECT_NEAR(ly1, 0.0075, 1e-15);
  const auto [lz0, lz1] = extent(w, idx.left_begin, idx.left_end, 2);
  EXPECT_NEAR(lz0, idx.floor_z_m, 1e-15);
  EXPECT_NEAR(lz1, 0.5, 1e-12);
  // Merged regions: each tooth is a rising face, a falling face and a land, every face a flat
  // region; the faces at 45° have normals (±1, 0, ±1)/√2 pointing into the silo.
  int ramps = 0;
  for (std::size_t k = idx.left_begin; k < idx.left_end; ++k) {
    const Eigen::Vector3d n = w[k].facets[0].normal.eigen();
    EXPECT_GT(n.x(), 0) << k;  // into the silo
    if (std::abs(n.z()) > 1e-12) {
      EXPECT_NEAR(std::abs(n.z()), std::sqrt(0.5), 1e-12);
      ++ramps;
    }
    EXPECT_EQ(w[k].group, "left");
  }
  const int teeth = static_cast<int>(std::floor((0.5 - idx.floor_z_m) / 6e-3 + 1e-9));
  EXPECT_EQ(ramps, 2 * teeth);
  ASSERT_EQ(idx.bottom.size(), 1u);
  EXPECT_EQ(w[idx.bottom[0]].shape, solver::WallShape::Box);
  EXPECT_NEAR(w[idx.bottom[0]].center.z() + w[idx.bottom[0]].half_extents.z(), 0.0, 1e-15);
  EXPECT_EQ(w[idx.front].normal, Eigen::Vector3d::UnitY());
  EXPECT_EQ(w[idx.back].normal, -Eigen::Vector3d::UnitY());
  EXPECT_DOUBLE_EQ(w[idx.back].center.y(), 0.0075);
  EXPECT_EQ(w.size(), idx.back + 1);
}

// Gravitational mode (Fig 5.4): outlet '1' (30 mm, centred) leaves a bottom plate on each side;
// '3' (60 mm at the right wall) one on the left; the opening spans exactly b.
TEST(SiloWalls, OutletsOpenWhereTheSeedPutsThem) {
  SiloSpec s;
  s.mode = "gravitational";
  s.roughness = 0.01;  // the smooth wall: 15 µm teeth
  SiloWalls idx;
  auto w = solver::silo_walls(s, 1.5e-3, 2.5e-3, idx);
  EXPECT_DOUBLE_EQ(idx.floor_z_m, 0.0);
  ASSERT_EQ(idx.bottom.size(), 2u);
  auto x_lo = [&](std::size_t k) { return w[k].center.x() - w[k].half_extents.x(); };
  auto x_hi = [&](std::size_t k) { return w[k].center.x() + w[k].half_extents.x(); };
  EXPECT_NEAR(x_hi(idx.bottom[0]), 0.085, 1e-15);
  EXPECT_NEAR(x_lo(idx.bottom[1]), 0.115, 1e-15);
  EXPECT_NEAR(x_lo(idx.outlet), 0.085, 1e-15);
  EXPECT_NEAR(x_hi(idx.outlet), 0.115, 1e-15);
  s.outlet = "right";
  s.outlet_width_m = 0.06;
  w = solver::silo_walls(s, 1.5e-3, 2.5e-3, idx);
  ASSERT_EQ(idx.bottom.size(), 1u);
  EXPECT_NEAR(x_hi(idx.bottom[0]), 0.14, 1e-15);
  EXPECT_NEAR(x_lo(idx.outlet), 0.14, 1e-15);
  EXPECT_GT(x_hi(idx.outlet), 0.2);  // (under the right wall too)
  // R_n = 0.01: h_g = 15 µm, s_g = 60 µm, 8333 teeth on each 0.5 m wall.
  const int teeth = static_cast<int>(std::floor(0.5 / 60e-6 + 1e-9));
  int ramps = 0;
  for (std::size_t k = idx.left_begin; k < idx.left_end; ++k)
    ramps += std::abs(w[k].facets[0].normal.eigen().z()) > 1e-12;
  EXPECT_EQ(ramps, 2 * teeth);
}

// Flat side walls (R_n = 0) are planes; what the geometry refuses, naming the key and value.
TEST(SiloWalls, BadGeometryNamesTheKey) {
  SiloSpec s;
  s.roughness = 0;
  SiloWalls idx;
  auto w = solver::silo_walls(s, 1.5e-3, 2.5e-3, idx);
  EXPECT_EQ(idx.left_end - idx.left_begin, 1u);
  EXPECT_EQ(w[idx.left_begin].shape, solver::WallShape::Plane);
  auto fails = [&](SiloSpec x, const std::string& what) {
    try {
      solver::silo_walls(x, 1.5e-3, 2.5e-3, idx);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  SiloSpec x;
  x.roughness = 5e-4;  // 0.75 µm teeth
  fails(x, "silo.roughness: gives teeth below 1e-3·d50 (0.0005");
  x = SiloSpec();
  x.mode = "gravitational";
  x.outlet_width_m = 0.3;
  fails(x, "silo.outlet_width_m: outside the bottom (0.29999");
  x.outlet_width_m = 0.002;
  fails(x, "silo.outlet_width_m: not wider than the largest grain (0.002");
  x.outlet_width_m = 0.03;
  x.outlet = "left";
  fails(x, "silo.outlet: expected \"centre\" or \"right\" (left)");
  x = SiloSpec();
  x.tooth_spacing_ratio = 1.5;
  fails(x, "silo.tooth_spacing_ratio: teeth wider than their spacing (1.5)");
  x = SiloSpec();
  x.depth_m = 0;
  fails(x, "silo.depth_m: must be positive (0)");
}
