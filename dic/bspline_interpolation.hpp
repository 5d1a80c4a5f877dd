// Bicubic B-spline interpolation of a grey-level image (Unser 1999, Thévenaz et al. 2000).
// The prefilter turns samples into B-spline coefficients so that the interpolant passes exactly
// through every pixel value and reproduces polynomials up to degree 3. Mirror (whole-sample
// symmetric) boundaries. OpenCV's INTER_CUBIC is Keys convolution, not this.
#pragma once

#include <opencv2/core.hpp>

namespace gs::dic {

/// Cubic B-spline coefficients of a single-channel image (any depth; computed in double).
cv::Mat bspline_prefilter(const cv::Mat& image);

/// Value and first derivatives of the interpolant.
struct Sample {
  double value = 0.0;
  double dx = 0.0;
  double dy = 0.0;
};

/// Bicubic B-spline interpolant of an image. Coordinates in px: (x, y) = (column, row), pixel
/// centres at integers. Valid for 0 <= x <= cols-1, 0 <= y <= rows-1 (callers check `inside`).
class BSplineImage {
 public:
  explicit BSplineImage(const cv::Mat& image);

  /// How far (px) outside the pixel centres `inside` still accepts a point. Warps composed in
  /// floating point put the border samples of a subset that did not move at -1e-17 px, not 0;
  /// the mirror-padded coefficients make the interpolant well defined there.
  static constexpr double kInsideTolerance = 1e-6;

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  bool inside(double x, double y) const {
    constexpr double e = kInsideTolerance;
    return x >= -e && y >= -e && x <= cols_ - 1.0 + e && y <= rows_ - 1.0 + e;
  }
  double value(double x, double y) const;
  Sample sample(double x, double y) const;

 private:
  static constexpr int kPad = 3;
  cv::Mat coef_;  // CV_64F, padded by kPad on each side (mirror)
  int rows_ = 0;
  int cols_ = 0;
};

}  // namespace gs::dic
