// Grain-size statistics of a snapshot.
#pragma once

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

}  // namespace gs::analysis
