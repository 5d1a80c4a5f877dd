// Shear zone (shear band) geometry from a 2D REV map of a localisation indicator (particle
// rotation or shear strain): inclination and thickness.
//
// Inclination: the band maximum is located along every row of the map (sub-cell by a parabola
// through the three values around the largest; rows whose peak does not stand out, by less than
// a quarter of the best row's peak over its median, are skipped), then a line is fitted to these
// ridge points with iterative 3-sigma trimming (sigma from the median absolute residual). The
// same is done along the columns; the line along which the map's mean value is larger is kept
// (rows suit bands steeper than 45 deg, as in plane-strain compression, seed 000 §3; columns
// flat bands, as in direct shear, seed 004 §4.2). The angle is measured from the map's first
// axis (the horizontal), counter-clockwise, in [0, 180); `inclination` is the acute angle.
//
// Thickness (seed 004 §4.2.3: "an inflection point in the distribution of sphere rotation around
// the maximum defined the lower and the upper boundary of the shear zone"): the profile across the
// band is the mean of the map (bilinear) along lines parallel to the fitted one, one step apart,
// smoothed by the binomial [1 2 1] / 4 against particle-scale noise; from its maximum near the
// line, the first sign change of the second difference on each side, found by linear
// interpolation, gives the two boundaries; the thickness is their distance. The
// profile is that of the map: the band widened by the REV cell (for a Gaussian band of standard
// deviation s0, about sqrt(s0^2 + L^2/12) per side, L the cell size).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace gs::analysis {

/// A scalar field on a regular 2D grid: value[i + nu * j] at (u0 + i step, v0 + j step); NaN for
/// no data.
struct ScalarMap {
  int nu = 0, nv = 0;
  double u0 = 0.0, v0 = 0.0, step = 0.0;
  std::vector<double> value;
};

struct ShearZone {
  bool by_rows = true;
  std::vector<Eigen::Vector2d> ridge;  // ridge points (u, v)
  std::vector<std::uint8_t> inlier;    // kept by the trimmed fit
  Eigen::Vector2d point = Eigen::Vector2d::Zero(), direction = Eigen::Vector2d::UnitX();
  double angle_deg = 0.0, inclination_deg = 0.0;
  double line_mean = 0.0;                        // mean of the map along the line
  std::vector<double> profile_d, profile_value;  // signed distance (m), mean value
  double peak_d = 0.0, peak_value = 0.0;
  double lower_d = 0.0, upper_d = 0.0, thickness = 0.0;  // m; NaN when not found
};

/// Throws std::invalid_argument when the map is degenerate or no band can be located.
ShearZone shear_zone(const ScalarMap& map);

/// The first inflection of a profile `v` sampled every `bin` (m): from index `from` towards
/// `step` = ±1, where the second difference first changes sign, interpolated linearly; the
/// distance (m) from index 0. NaN when it does not (or fewer than 3 samples).
double profile_inflection(const std::vector<double>& v, int from, int step, double bin);

}  // namespace gs::analysis
