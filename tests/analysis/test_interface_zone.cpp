// The interface shear zone (analysis/interface_zone.hpp) on hand-made frames: a rotation profile
// whose inflection is known (a logistic step: its inflection is its centre) and displacements
// known layer by layer.
#include <gtest/gtest.h>

#include <cmath>

#include "interface_zone.hpp"

namespace {

// Particles on a grid: x = 1 … 9 mm (17 columns), heights h = 0.25 … 9.75 mm (layers 0.5 mm
// apart) above the surface at z = −1 mm; the rotation about y of a layer is rot(h), its x
// displacement since `ref` is dx(h).
template <class Rot, class Dx>
std::pair<gs::Frame, gs::Frame> column(Rot rot, Dx dx) {
  gs::Frame f, ref;
  std::int64_t id = 0;
  for (int k = 0; k < 20; ++k) {
    const double h = 0.25e-3 + 0.5e-3 * k;
    for (int i = 0; i < 17; ++i) {
      gs::Particle p;
      p.id = id++;
      p.radius = 0.2e-3;
      p.position = Eigen::Vector3d(1e-3 + 0.5e-3 * i, 0.5e-3 * (i % 3), h - 1e-3);
      ref.particles.push_back(p);
      p.position.x() += dx(h);
      p.rotation = Eigen::Vector3d(0.3, rot(h), -0.2);  // (only y counts)
      f.particles.push_back(p);
    }
  }
  return {f, ref};
}

}  // namespace

TEST(InterfaceZone, ZoneEndsAtTheRotationProfilesInflection) {
  // rot(h) = 0.5 / (1 + exp((h − 3 mm)/0.6 mm)): largest at the surface, inflection at 3 mm.
  const auto [f, ref] = column([](double h) { return 0.5 / (1 + std::exp((h - 3e-3) / 0.6e-3)); },
                               [](double h) { return h < 0.5e-3 ? 0.5e-3 : 2e-3; });
  gs::analysis::InterfaceZoneOptions o;
  o.surface_z = -1e-3;
  o.bin = 0.5e-3;
  o.reference = &ref;
  const auto z = gs::analysis::interface_zone(f, o);
  ASSERT_EQ(z.height.size(), 20u);
  EXPECT_NEAR(z.height[0], 0.25e-3, 1e-12);
  EXPECT_NEAR(z.rotation[6], 0.5 / (1 + std::exp((3.25e-3 - 3e-3) / 0.6e-3)), 1e-12);
  // The range is the upper half's extent, moved 2 mm: [2.8, 11.2] mm; the lowest layer (moved
  // 0.5 mm: columns at 1.5 + 0.5·i mm) has 14 columns in it, the top layers all 17.
  EXPECT_EQ(z.count[0], 14.0);
  EXPECT_EQ(z.count[19], 17.0);
  EXPECT_NEAR(z.peak_height, 0.25e-3, 1e-12);
  EXPECT_EQ(z.lower, 0.0);  // no inflection below the peak: the zone starts at the surface
  // The smoothed logistic's inflection: at its centre, to a tenth of a bin.
  EXPECT_NEAR(z.upper, 3e-3, 0.05e-3);
  EXPECT_NEAR(z.thickness, z.upper, 1e-15);
  // Displacements: 2 mm at the top, 0.5 mm in the lowest layer: slip ratio 1/4.
  EXPECT_NEAR(z.u_top, 2e-3, 1e-12);
  EXPECT_NEAR(z.u_surface, 0.5e-3, 1e-12);
  EXPECT_NEAR(z.slip_ratio, 0.25, 1e-9);
  EXPECT_NEAR(z.x_lo, 1e-3 - 0.2e-3 + 2e-3, 1e-12);  // the upper half's extent (moved 2 mm)
}

TEST(InterfaceZone, PeakAboveTheSurfaceHasTwoBoundaries) {
  // A bump centred 4 mm up: exp(−(h − 4 mm)²/(2·(1 mm)²)) has inflections at 3 and 5 mm.
  const auto [f, ref] =
      column([](double h) { return -std::exp(-std::pow(h - 4e-3, 2) / (2 * 1e-6)); },
             [](double) { return 0.0; });
  gs::analysis::InterfaceZoneOptions o;
  o.surface_z = -1e-3;
  o.bin = 0.5e-3;
  const auto z = gs::analysis::interface_zone(f, o);
  EXPECT_NEAR(z.peak_height, 4e-3 - 0.25e-3, 0.26e-3);  // the bin next to the peak
  // Smoothing by [1 2 1]/4 widens a Gaussian of σ to √(σ² + bin²/2): inflections at 4 ∓ 1.06.
  const double s = std::sqrt(1e-6 + 0.5 * 0.25e-6);
  EXPECT_NEAR(z.lower, 4e-3 - s, 0.1e-3);
  EXPECT_NEAR(z.upper, 4e-3 + s, 0.1e-3);
  EXPECT_NEAR(z.thickness, 2 * s, 0.15e-3);
  EXPECT_TRUE(std::isnan(z.slip_ratio));  // no reference frame
}

TEST(InterfaceZone, BadOptionsAreErrors) {
  const auto [f, ref] = column([](double) { return 0.0; }, [](double) { return 0.0; });
  gs::analysis::InterfaceZoneOptions o;
  EXPECT_THROW(gs::analysis::interface_zone(f, o), std::invalid_argument);  // bin 0
  o.bin = 1e-3;
  o.x_inset = 5e-3;  // wider than half the specimen
  EXPECT_THROW(gs::analysis::interface_zone(f, o), std::invalid_argument);
  EXPECT_THROW(gs::analysis::interface_zone(gs::Frame{}, {0, 1e-3, 0, nullptr}),
               std::invalid_argument);
}
