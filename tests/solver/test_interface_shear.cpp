// The interface shear box of seed 004 §4.3–4.4 (interface_shear.hpp): the surface under the
// frame (saw-tooth, sinusoid, flat), its crest, mean and trough heights, its extent beyond the
// frame's travel, the box walls and the bad inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "interface_shear.hpp"

namespace {

using gs::solver::InterfaceShearGeometry;
using gs::solver::InterfaceShearWalls;
using gs::solver::InterfaceSurfaceSpec;
using gs::solver::WallShape;
using gs::solver::WallSpec;

InterfaceShearGeometry box() {
  InterfaceShearGeometry g;
  g.length_m = 0.03;
  g.width_m = 0.005;
  g.height_m = 0.01;
  g.travel_m = 0.007;
  g.wall_thickness_m = 0.002;
  g.platen_z_m = 0.02;
  g.frame_top_m = 0.025;
  return g;
}

// Lowest and highest z and x of the surface's triangles (global coordinates).
struct Extent {
  double zlo = HUGE_VAL, zhi = -HUGE_VAL, xlo = HUGE_VAL, xhi = -HUGE_VAL;
};
Extent surface_extent(const std::vector<WallSpec>& w, const InterfaceShearWalls& idx) {
  Extent e;
  for (std::size_t k = idx.surface_begin; k < idx.surface_end; ++k)
    for (const auto& f : w[k].facets)
      for (const auto& v : f.vertex) {
        const Eigen::Vector3d p = w[k].center + f.offset.eigen() + v.eigen();
        e.zlo = std::min(e.zlo, p.z());
        e.zhi = std::max(e.zhi, p.z());
        e.xlo = std::min(e.xlo, p.x());
        e.xhi = std::max(e.xhi, p.x());
      }
  return e;
}

double top(const WallSpec& w) {
  return w.center.z() + w.half_extents.z();
}
double bottom(const WallSpec& w) {
  return w.center.z() - w.half_extents.z();
}

}  // namespace

TEST(InterfaceShearWalls, SawToothCrestMeanAndExtent) {
  // R_n = 1 at d50 = 1 mm: h_g = 1 mm; isosceles 45° teeth, s_g = 2·h_g: contiguous triangles,
  // so half the band [0, h_g] is tooth: the mean surface is at h_g/2.
  InterfaceSurfaceSpec s;
  s.kind = "saw_tooth";
  s.roughness = 1.0;
  s.d50_m = 0.001;
  auto g = box();
  InterfaceShearWalls idx;
  const auto w = gs::solver::interface_shear_walls(s, g, 0.0014, idx);
  EXPECT_DOUBLE_EQ(g.crest_z_m, 0.001);
  EXPECT_DOUBLE_EQ(g.trough_z_m, 0.0);
  EXPECT_NEAR(g.mean_z_m, 0.0005, 1e-15);
  const Extent e = surface_extent(w, idx);
  EXPECT_NEAR(e.zlo, 0.0, 1e-15);
  EXPECT_NEAR(e.zhi, 0.001, 1e-15);
  // The surface reaches past the frame's start and past its end of travel, by whole teeth.
  EXPECT_LE(e.xlo, -(g.wall_thickness_m + 2 * 0.0014));
  EXPECT_GE(e.xhi, g.length_m + g.travel_m + g.wall_thickness_m + 2 * 0.0014);
  const double teeth = (e.xhi - e.xlo) / 0.002;
  EXPECT_NEAR(teeth, std::round(teeth), 1e-6);
  // Two faces a tooth, each one quad (two triangles).
  EXPECT_EQ(g.surface_triangles, static_cast<std::size_t>(4 * std::round(teeth)));
  // The frame's lower edge: one largest grain above the crests; the closers shut that gap.
  EXPECT_NEAR(bottom(w[idx.frame[0]]), 0.001 + 0.0014, 1e-15);
  EXPECT_NEAR(bottom(w[idx.frame[1]]), 0.001 + 0.0014, 1e-15);
  EXPECT_LE(bottom(w[idx.closer[0]]), g.crest_z_m);
  EXPECT_GT(top(w[idx.closer[0]]), bottom(w[idx.frame[0]]));
  EXPECT_NEAR(bottom(w[idx.platen]), g.platen_z_m, 1e-15);
  for (std::size_t k = idx.surface_begin; k < idx.surface_end; ++k)
    EXPECT_EQ(w[k].shape, WallShape::Facets);
}

// surface_contact = "yade": YADE's facets, one wall (one contact) per triangle with the facet's
// 2R stiffness, as the thesis's YADE surfaces; "merged" (the default): one wall per tooth face
// with a plane wall's. The same triangles either way.
TEST(InterfaceShearWalls, SurfaceContactYadeGivesOneWallPerTriangle) {
  InterfaceSurfaceSpec s;
  s.kind = "saw_tooth";
  s.roughness = 1.0;
  s.d50_m = 0.001;
  auto gm = box(), gy = box();
  InterfaceShearWalls im, iy;
  const auto wm = gs::solver::interface_shear_walls(s, gm, 0.0014, im);
  s.contact = "yade";
  const auto wy = gs::solver::interface_shear_walls(s, gy, 0.0014, iy);
  ASSERT_EQ(gm.surface_triangles, gy.surface_triangles);
  // Merged: a face is one flat region of two triangles; yade: each triangle its own wall.
  EXPECT_EQ(im.surface_end - im.surface_begin, gm.surface_triangles / 2);
  EXPECT_EQ(iy.surface_end - iy.surface_begin, gy.surface_triangles);
  for (std::size_t k = im.surface_begin; k < im.surface_end; ++k) EXPECT_TRUE(wm[k].plane_radii);
  for (std::size_t k = iy.surface_begin; k < iy.surface_end; ++k) {
    EXPECT_FALSE(wy[k].plane_radii);
    EXPECT_EQ(wy[k].facets.size(), 1u);
  }
  const Extent em = surface_extent(wm, im), ey = surface_extent(wy, iy);
  EXPECT_NEAR(em.zhi, ey.zhi, 1e-15);
  EXPECT_NEAR(em.xlo, ey.xlo, 1e-15);
  EXPECT_NEAR(em.xhi, ey.xhi, 1e-15);
  // The box walls after the surface are the same walls.
  EXPECT_EQ(wm.size() - im.surface_end, wy.size() - iy.surface_end);
}

TEST(InterfaceShearWalls, SinusoidSpansTheDepthAboutTheMidPlane) {
  // §4.4: l = 15 mm, d/l = 0.24: d = 3.6 mm, h = ±1.8 mm; whole wavelengths.
  InterfaceSurfaceSpec s;
  s.kind = "sinusoid";
  s.depth_ratio = 0.24;
  s.wavelength_m = 0.015;
  s.segments_per_wavelength = 32;
  auto g = box();
  InterfaceShearWalls idx;
  const auto w = gs::solver::interface_shear_walls(s, g, 0.0014, idx);
  EXPECT_NEAR(g.crest_z_m, 0.0018, 1e-15);
  EXPECT_NEAR(g.trough_z_m, -0.0018, 1e-15);
  EXPECT_EQ(g.mean_z_m, 0.0);
  const Extent e = surface_extent(w, idx);
  // 32 segments a wavelength put nodes on the crest (u = l/4) and the trough (3l/4).
  EXPECT_NEAR(e.zhi, 0.0018, 1e-12);
  EXPECT_NEAR(e.zlo, -0.0018, 1e-12);
  const double waves = (e.xhi - e.xlo) / 0.015;
  EXPECT_NEAR(waves, std::round(waves), 1e-9);
  EXPECT_NEAR(e.xlo / 0.015, std::round(e.xlo / 0.015), 1e-9);  // in phase with x = 0
  EXPECT_EQ(g.surface_triangles, static_cast<std::size_t>(2 * 32 * std::round(waves)));
}

TEST(InterfaceShearWalls, FlatIsOnePlateTopAtZero) {
  // "flat", and a sinusoid of depth 0 (Table 4.8's d/l = 0 in a sweep over d/l).
  for (const double depth : {-1.0, 0.0}) {
    InterfaceSurfaceSpec s;
    s.kind = depth < 0 ? "flat" : "sinusoid";
    s.depth_ratio = std::max(depth, 0.0);
    s.wavelength_m = 0.015;
    auto g = box();
    InterfaceShearWalls idx;
    const auto w = gs::solver::interface_shear_walls(s, g, 0.0014, idx);
    ASSERT_EQ(idx.surface_end - idx.surface_begin, 1u);
    EXPECT_EQ(w[idx.surface_begin].shape, WallShape::Box);
    EXPECT_NEAR(top(w[idx.surface_begin]), 0.0, 1e-15);
    EXPECT_EQ(g.crest_z_m, 0.0);
    EXPECT_EQ(g.mean_z_m, 0.0);
  }
}

TEST(InterfaceShearWalls, BadSurfacesNameKeyAndValue) {
  auto expect_error = [](InterfaceSurfaceSpec s, const std::string& what) {
    auto g = box();
    InterfaceShearWalls idx;
    try {
      (void)gs::solver::interface_shear_walls(s, g, 0.0014, idx);
      ADD_FAILURE() << "no error for " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), what);
    }
  };
  InterfaceSurfaceSpec s;
  s.kind = "saw_tooth";
  s.d50_m = 0.001;
  s.roughness = 0.00048828125;  // 2⁻¹¹: h_g ≈ 0.49 µm < 1e-3·d50
  expect_error(s, "interface_shear.roughness: gives teeth below 1e-3·d50 (0.00048828125)");
  s.roughness = 1.0;
  s.tooth_spacing_ratio = 1.5;  // 45° teeth are 2·h_g wide
  expect_error(s, "interface_shear.tooth_spacing_ratio: teeth wider than their spacing (1.5)");
  s.tooth_spacing_ratio = 2.0;
  s.contact = "facets";
  expect_error(s, "interface_shear.surface_contact: expected \"merged\" or \"yade\" (facets)");
  s = {};
  s.kind = "sinusoid";
  s.wavelength_m = 0.015;
  s.depth_ratio = 1.2;
  expect_error(s, "interface_shear.depth_ratio: outside [0, 1) (1.2)");
  s.depth_ratio = -0.125;
  expect_error(s, "interface_shear.depth_ratio: outside [0, 1) (-0.125)");
  s.kind = "waves";
  expect_error(s,
               "interface_shear.surface: expected \"saw_tooth\", \"sinusoid\" or \"flat\" (waves)");
}
