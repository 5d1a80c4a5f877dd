// Inverse-compositional Gauss–Newton (IC-GN) subset matching with the ZNSSD criterion (Pan, Li &
// Tong 2013) and a first-order (affine) or second-order (quadratic) shape function (Gao, Pan et
// al. 2015, "High-accuracy and high-efficiency second-order IC-GN"). The reference subset's
// Hessian is precomputed; each iteration interpolates the deformed subset with the bicubic
// B-spline.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "bspline_interpolation.hpp"

namespace gs::dic {

/// Shape function p = (u, ux, uy, v, vx, vy, uxx, uxy, uyy, vxx, vxy, vyy): a reference point
/// x0 + d maps to x0 + d + (U, V) in the deformed image, with
///   U = u + ux dx + uy dy + uxx dx^2/2 + uxy dx dy + uyy dy^2/2, V likewise.
/// First-order (affine) subsets use the first six entries and keep the last six zero.
using Shape = Eigen::Matrix<double, 12, 1>;

/// The shape function of a neighbouring subset centre (x0 + ddx, y0 + ddy): its Taylor shift.
/// For first-order shapes this is u + (ux ddx + uy ddy) with the gradients unchanged.
Shape shift_shape(const Shape& p, double ddx, double ddy);

struct IcgnOptions {
  /// 1: affine subsets (6 parameters); 2: quadratic subsets (12 parameters), which follow
  /// displacement fields that curve within a subset (short wavelengths) at some noise cost.
  int order = 1;
  int max_iterations = 20;
  /// Stop when sqrt(du^2 + dv^2 + R^2 (dux^2 + duy^2 + dvx^2 + dvy^2)
  ///                + R^4 (duxx^2/4 + duxy^2 + duyy^2/4 + dvxx^2/4 + dvxy^2 + dvyy^2/4)) <
  ///                tolerance
  /// (px), R = subset half-width: the largest displacement change over the subset.
  double tolerance = 1e-3;
  /// Threads that build the reference's B-spline and gradients in the constructor.
  int threads = 1;
};

struct IcgnResult {
  Shape p = Shape::Zero();
  double zncc = -1.0;  // zero-normalised cross-correlation (= 1 - ZNSSD/2) at the solution
  int iterations = 0;
  bool converged = false;
  bool ok = false;  // false: subset textureless or left the deformed image
};

/// IC-GN over square subsets of half-width `radius` (subset = 2*radius+1 px).
class IcgnSolver {
 public:
  /// `reference` is sampled at whole pixels; `deformed` through its B-spline interpolant.
  IcgnSolver(const cv::Mat& reference, const BSplineImage& deformed, int radius,
             IcgnOptions options = {});
  int radius() const { return radius_; }
  /// Refines `guess` for the subset centred at integer pixel (x0, y0) of the reference.
  IcgnResult solve(int x0, int y0, const Shape& guess) const;
  /// Whether `solve` runs the AVX2 build of the loop (x86-64 CPUs that have it). Both builds
  /// give the same bits; `use_avx2(false)` forces the generic one (tests compare them).
  bool avx2() const { return avx2_; }
  void use_avx2(bool on);

 private:
  cv::Mat ref_;  // CV_64F
  cv::Mat gx_;   // B-spline gradient of the reference at the pixels
  cv::Mat gy_;
  const BSplineImage& def_;
  int radius_;
  IcgnOptions options_;
  bool avx2_ = false;
  IcgnResult solve_impl(int x0, int y0, const Shape& guess) const;
  IcgnResult solve_impl2(int x0, int y0, const Shape& guess) const;
  IcgnResult solve_avx2(int x0, int y0, const Shape& guess) const;
  IcgnResult solve_generic(int x0, int y0, const Shape& guess) const;
};

}  // namespace gs::dic
