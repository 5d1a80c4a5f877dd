// Bicubic B-spline interpolation of a grey-level image (Unser 1999, Thévenaz et al. 2000).
// The prefilter turns samples into B-spline coefficients so that the interpolant passes exactly
// through every pixel value and reproduces polynomials up to degree 3. Mirror (whole-sample
// symmetric) boundaries. OpenCV's INTER_CUBIC is Keys convolution, not this.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>

namespace gs::dic {

/// Cubic B-spline coefficients of a single-channel image (any depth; computed in double), on up
/// to `threads` threads (the result does not depend on their number).
cv::Mat bspline_prefilter(const cv::Mat& image, int threads = 1);

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
  explicit BSplineImage(const cv::Mat& image, int threads = 1);

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
  /// Value of the interpolant, inline (always) because it is the IC-GN inner loop: its callers
  /// are compiled for AVX2 as well (icgn.cpp). The 4 x 4 coefficient block is combined row by
  /// row with the y weights in 4-vectors (one register each under AVX), then dotted with the x
  /// weights. No fused multiply-adds (-ffp-contract=off under -std=c++20): every instruction
  /// set gives the same bits.
  [[gnu::always_inline]] double value(double x, double y) const {
    using v4d = double __attribute__((vector_size(32)));
    int ix = static_cast<int>(x);  // floor without a libm call (x >= -kInsideTolerance)
    int iy = static_cast<int>(y);
    ix -= x < ix ? 1 : 0;
    iy -= y < iy ? 1 : 0;
    const double tx = x - ix;
    const double ty = y - iy;
    // Cubic B-spline weights as polynomials in t (Horner): w = c0 + t (c1 + t (c2 + t c3)).
    const v4d c0 = {1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 0.0};
    const v4d c1 = {-0.5, 0.0, 0.5, 0.0};
    const v4d c2 = {0.5, -1.0, 0.5, 0.0};
    const v4d c3 = {-1.0 / 6.0, 0.5, -0.5, 1.0 / 6.0};
    const v4d wx = c0 + tx * (c1 + tx * (c2 + tx * c3));
    const v4d wy = c0 + ty * (c1 + ty * (c2 + ty * c3));
    const double* p = base_ + (iy + kPad - 1) * stride_ + (ix + kPad - 1);
    v4d r0, r1, r2, r3;
    __builtin_memcpy(&r0, p, sizeof r0);
    __builtin_memcpy(&r1, p + stride_, sizeof r1);
    __builtin_memcpy(&r2, p + 2 * stride_, sizeof r2);
    __builtin_memcpy(&r3, p + 3 * stride_, sizeof r3);
    const v4d acc = wy[0] * r0 + wy[1] * r1 + wy[2] * r2 + wy[3] * r3;
    const v4d prod = wx * acc;
    return (prod[0] + prod[1]) + (prod[2] + prod[3]);
  }
  Sample sample(double x, double y) const;

  /// Cubic B-spline weights of the four samples around a point at fraction t in [0, 1).
  static void weights(double t, double w[4]) {
    const double s = 1.0 - t;
    const double t2 = t * t;
    const double t3 = t2 * t;
    w[0] = s * s * s * (1.0 / 6.0);
    w[1] = (2.0 / 3.0) - t2 + 0.5 * t3;
    w[2] = (1.0 / 6.0) + 0.5 * (t + t2 - t3);
    w[3] = t3 * (1.0 / 6.0);
  }

 private:
  static constexpr int kPad = 3;
  cv::Mat coef_;                  // CV_64F, padded by kPad on each side (mirror)
  const double* base_ = nullptr;  // coef_ data
  std::ptrdiff_t stride_ = 0;     // coef_ row stride, in doubles
  int rows_ = 0;
  int cols_ = 0;
};

}  // namespace gs::dic
