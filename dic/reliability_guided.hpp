// Subset DIC over a grid of points of interest (POIs): ZNCC integer seeds, IC-GN refinement and
// reliability-guided propagation (each new POI starts from its best-correlated solved
// neighbour). Propagation runs in fronts: all POIs of one front are solved in parallel from
// guesses fixed by earlier fronts, so the result does not depend on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "icgn.hpp"

namespace gs::dic {

/// Regular POI grid: x = x0 + i*step, y = y0 + j*step; index j*nx + i.
struct PoiGrid {
  int nx = 0;
  int ny = 0;
  int x0 = 0;
  int y0 = 0;
  int step = 1;
  std::vector<std::uint8_t> in_roi;  // POIs to correlate
  int x(int idx) const { return x0 + (idx % nx) * step; }
  int y(int idx) const { return y0 + (idx / nx) * step; }
  int size() const { return nx * ny; }
};

/// Grid of POIs whose whole subset lies inside an image of rows x cols. `roi` (optional,
/// CV_8U, same size) selects POIs whose centre pixel is non-zero. Throws std::invalid_argument
/// when no POI fits (image smaller than a subset, empty ROI).
PoiGrid make_grid(int rows, int cols, int radius, int step, const cv::Mat& roi = {});

struct DicOptions {
  int radius = 15;         // subset half-width: subset = 2*radius+1 px
  int search = 30;         // integer seed search half-width, px
  int seeds_per_axis = 3;  // seed candidates on a seeds_per_axis^2 lattice over the grid
  double zncc_min = 0.9;   // POIs below this are marked invalid and do not propagate
  int threads = 1;
  IcgnOptions icgn;
  /// Called on the calling thread before each propagation front (and never inside a parallel
  /// region); it may throw to abandon the correlation (the Python package: Ctrl-C).
  std::function<void()> poll;
};

struct DicField {
  PoiGrid grid;
  std::vector<Shape> p;
  std::vector<double> zncc;
  std::vector<std::uint8_t> valid;
  std::vector<std::uint8_t> solved;  // reached by propagation (valid or not)
  int seeds = 0;                     // valid seeds
  // Wall-clock seconds of the stages: B-spline prefilters and reference gradients, seed search
  // (integer ZNCC + IC-GN), reliability-guided propagation (IC-GN).
  double seconds_prefilter = 0.0, seconds_seeds = 0.0, seconds_propagation = 0.0;
  long long icgn_iterations = 0;  // summed over the solved POIs
};

/// Correlates `deformed` against `reference` (same size, CV_64F or convertible) over `grid`.
/// Throws std::runtime_error when no seed reaches zncc_min.
DicField correlate(const cv::Mat& reference, const cv::Mat& deformed, const PoiGrid& grid,
                   const DicOptions& options);

}  // namespace gs::dic
