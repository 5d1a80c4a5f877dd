// Synthetic speckle images with exactly known motion: a Boolean model of random discs (Poisson
// centres, random radii and grey levels) in reference coordinates, rendered under a known inverse
// map X = M^-1(x) with supersampling, an optional Gaussian optical blur in
// the image plane and additive Gaussian noise. Used by tests and bench/.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

namespace gs::dic {

struct SpeckleParams {
  double mean_radius_px = 2.5;  // mean disc radius
  double radius_spread = 0.3;   // radius uniform in mean*(1 ± spread)
  double coverage = 0.5;        // area fraction covered by the union of discs
  double background = 40.0;     // grey level outside discs (0..255 scale)
  double level_lo = 140.0;      // disc grey levels uniform in [lo, hi]
  double level_hi = 230.0;
  std::uint64_t seed = 1;
};

struct Disc {
  Eigen::Vector2d centre;
  double radius = 0.0;
  double level = 0.0;
};

/// A disc pattern covering [x0, x1] x [y0, y1] (reference coordinates, px) with a lookup grid.
class SpecklePattern {
 public:
  SpecklePattern(double x0, double y0, double x1, double y1, const SpeckleParams& params);
  /// Grey level at reference point X (the topmost disc covering it, else the background).
  double intensity(const Eigen::Vector2d& X) const;
  const std::vector<Disc>& discs() const { return discs_; }

 private:
  std::vector<Disc> discs_;
  std::vector<std::vector<int>> cells_;
  double x0_, y0_, cell_;
  int nx_, ny_;
  double background_;
};

/// Inverse map: current-image point x -> reference point X.
using InverseMap = std::function<Eigen::Vector2d(const Eigen::Vector2d&)>;

struct RenderParams {
  int supersample = 5;       // s x s samples per pixel (box-filter antialiasing)
  double blur_sigma = 0.6;   // Gaussian optical blur in the image plane (px); 0 = none
  double noise_sigma = 0.0;  // additive Gaussian noise, grey levels
  std::uint64_t noise_seed = 7;
  bool quantize_8bit = false;  // round and clip to 0..255
};

/// Renders a rows x cols CV_64F image g(x) = f(X(x)) of the pattern.
cv::Mat render_speckle(const SpecklePattern& pattern, int rows, int cols, const InverseMap& inverse,
                       const RenderParams& params);

}  // namespace gs::dic
