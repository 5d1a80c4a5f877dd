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
  /// 4 doubles in one vector (one AVX register; two SSE2 registers elsewhere).
  using v4d = double __attribute__((vector_size(32)));

  /// Value of the interpolant, inline (always) because it is the IC-GN inner loop: its callers
  /// are compiled for AVX2 as well (icgn.cpp). The 4 x 4 coefficient block is combined row by
  /// row with the y weights in 4-vectors, then multiplied by the x weights and summed as
  /// (p0 + p1) + (p2 + p3). No fused multiply-adds (-ffp-contract=off under -std=c++20): every
  /// instruction set gives the same bits.
  [[gnu::always_inline]] double value(double x, double y) const {
    v4d p;
    products(x, y, p);
    return (p[0] + p[1]) + (p[2] + p[3]);
  }
  /// Values at four points, out[k] bit-identical to value(x[k], y[k]): the four horizontal sums
  /// are done together by two rounds of shuffles.
  [[gnu::always_inline]] void value4(const double (&x)[4], const double (&y)[4], v4d& out) const {
    v4d p0, p1, p2, p3;
    products(x[0], y[0], p0);
    products(x[1], y[1], p1);
    products(x[2], y[2], p2);
    products(x[3], y[3], p3);
    using m4 = long long __attribute__((vector_size(32)));
    // s01 = (p0_0 + p0_1, p1_0 + p1_1, p0_2 + p0_3, p1_2 + p1_3), s23 likewise.
    const v4d s01 =
        __builtin_shuffle(p0, p1, m4{0, 4, 2, 6}) + __builtin_shuffle(p0, p1, m4{1, 5, 3, 7});
    const v4d s23 =
        __builtin_shuffle(p2, p3, m4{0, 4, 2, 6}) + __builtin_shuffle(p2, p3, m4{1, 5, 3, 7});
    out = __builtin_shuffle(s01, s23, m4{0, 1, 4, 5}) + __builtin_shuffle(s01, s23, m4{2, 3, 6, 7});
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
  // wx * (sum_j wy_j row_j) over the 4 x 4 coefficient block of (x, y): the four terms whose sum
  // is the value.
  [[gnu::always_inline]] void products(double x, double y, v4d& prod) const {
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
    prod = wx * (wy[0] * r0 + wy[1] * r1 + wy[2] * r2 + wy[3] * r3);
  }

  static constexpr int kPad = 3;
  cv::Mat coef_;                  // CV_64F, padded by kPad on each side (mirror)
  const double* base_ = nullptr;  // coef_ data
  std::ptrdiff_t stride_ = 0;     // coef_ row stride, in doubles
  int rows_ = 0;
  int cols_ = 0;
};

}  // namespace gs::dic
