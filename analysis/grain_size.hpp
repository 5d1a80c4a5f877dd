// Grain-size statistics of a snapshot.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

/// Diameter below which the given fraction of the solid VOLUME (mass at uniform density) lies,
/// as a sieve curve reports it: d50 = diameter_percentile(frame, 0.5). Linear interpolation of
/// the cumulative volume curve between sorted diameters. A 2D frame (two_d) weighs each particle
/// by its AREA, as the weight of a disk (seed 002 §4's "weight-median diameter"). Throws on an
/// empty frame.
double diameter_percentile(const Frame& frame, double fraction);

/// Same on plain radii, each weighted by r^exponent (3: spheres, 2: disks).
double diameter_percentile(std::vector<double> radii, double fraction, int exponent = 3);

inline double d50(const Frame& frame) {
  return diameter_percentile(frame, 0.5);
}

/// The d50 (m) a granoscope run's scene defined and measured its lengths by, from the run's
/// metadata: "scene.d50_m" (written by the silo and saw-tooth interface shear scenes, whose
/// roughness R_n = h_g/d50 is in units of it), or, in runs written before that key, a positive
/// `d50_m` in the [silo] or [interface_shear] table of the recorded "scene.toml". None when the
/// run records none (the scene took its d50 from the grading by mass, as d50() does). This
/// matters where the scene's d50 is a median by number (seed 004's silo: 1.5 mm of a grading
/// uniform between 0.5 and 2.5 mm, whose median by volume is 2.1 mm).
std::optional<double> recorded_d50(
    const std::vector<std::pair<std::string, std::string>>& parameters);

}  // namespace gs::analysis
