#include "icgn.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace gs::dic {

IcgnSolver::IcgnSolver(const cv::Mat& reference, const BSplineImage& deformed, int radius,
                       IcgnOptions options)
    : def_(deformed), radius_(radius), options_(options) {
  if (radius < 1) throw std::invalid_argument("IcgnSolver: subset radius must be >= 1");
  reference.convertTo(ref_, CV_64F);
  if (ref_.rows != deformed.rows() || ref_.cols != deformed.cols())
    throw std::invalid_argument("IcgnSolver: reference and deformed images differ in size");
  const BSplineImage spline(ref_);
  gx_.create(ref_.rows, ref_.cols, CV_64F);
  gy_.create(ref_.rows, ref_.cols, CV_64F);
  for (int r = 0; r < ref_.rows; ++r)
    for (int c = 0; c < ref_.cols; ++c) {
      const Sample s = spline.sample(c, r);
      gx_.at<double>(r, c) = s.dx;
      gy_.at<double>(r, c) = s.dy;
    }
}

IcgnResult IcgnSolver::solve(int x0, int y0, const Shape& guess) const {
  IcgnResult res;
  res.p = guess;
  const int R = radius_;
  if (x0 - R < 0 || y0 - R < 0 || x0 + R >= ref_.cols || y0 + R >= ref_.rows) return res;
  const int side = 2 * R + 1;
  const auto n = static_cast<std::size_t>(side) * static_cast<std::size_t>(side);
  std::vector<double> f(n);
  std::vector<Shape> J(n);
  std::vector<double> g(n);
  double fsum = 0.0;
  std::size_t k = 0;
  for (int dy = -R; dy <= R; ++dy) {
    const double* fr = ref_.ptr<double>(y0 + dy);
    const double* gxr = gx_.ptr<double>(y0 + dy);
    const double* gyr = gy_.ptr<double>(y0 + dy);
    for (int dx = -R; dx <= R; ++dx, ++k) {
      const int c = x0 + dx;
      f[k] = fr[c];
      fsum += fr[c];
      J[k] << gxr[c], gxr[c] * dx, gxr[c] * dy, gyr[c], gyr[c] * dx, gyr[c] * dy;
    }
  }
  const double fmean = fsum / static_cast<double>(n);
  double fss = 0.0;
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (k = 0; k < n; ++k) {
    f[k] -= fmean;
    fss += f[k] * f[k];
    H.selfadjointView<Eigen::Lower>().rankUpdate(J[k]);
  }
  H = H.selfadjointView<Eigen::Lower>();
  const double df = std::sqrt(fss);
  // Textureless subset: grey-level std below 0.1% of a 255 range is noise, not speckle.
  if (df < 0.255 * std::sqrt(static_cast<double>(n))) return res;
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> Hinv(H);
  if (Hinv.info() != Eigen::Success || !Hinv.isPositive()) return res;

  Eigen::Matrix3d W;
  auto to_matrix = [](const Shape& p) {
    Eigen::Matrix3d M;
    M << 1.0 + p[1], p[2], p[0], p[4], 1.0 + p[5], p[3], 0.0, 0.0, 1.0;
    return M;
  };
  W = to_matrix(res.p);
  const double R2 = static_cast<double>(R) * R;
  for (int it = 1; it <= options_.max_iterations; ++it) {
    res.iterations = it;
    // Deformed subset.
    double gsum = 0.0;
    k = 0;
    for (int dy = -R; dy <= R; ++dy) {
      const double bx = x0 + W(0, 2) + W(0, 1) * dy;
      const double by = y0 + W(1, 2) + W(1, 1) * dy;
      for (int dx = -R; dx <= R; ++dx, ++k) {
        const double x = bx + W(0, 0) * dx;
        const double y = by + W(1, 0) * dx;
        if (!def_.inside(x, y)) return res;
        g[k] = def_.value(x, y);
        gsum += g[k];
      }
    }
    const double gmean = gsum / static_cast<double>(n);
    double gss = 0.0;
    double fg = 0.0;
    for (k = 0; k < n; ++k) {
      g[k] -= gmean;
      gss += g[k] * g[k];
      fg += f[k] * g[k];
    }
    const double dg = std::sqrt(gss);
    if (dg <= 0.0) return res;
    res.zncc = fg / (df * dg);
    const double ratio = df / dg;
    Shape b = Shape::Zero();
    for (k = 0; k < n; ++k) b.noalias() += J[k] * (f[k] - ratio * g[k]);
    const Shape dp = -Hinv.solve(b);
    // W <- W o W(dp)^-1
    W = W * to_matrix(dp).inverse();
    const double norm =
        std::sqrt(dp[0] * dp[0] + dp[3] * dp[3] +
                  R2 * (dp[1] * dp[1] + dp[2] * dp[2] + dp[4] * dp[4] + dp[5] * dp[5]));
    if (!std::isfinite(norm)) return res;
    if (norm < options_.tolerance) {
      res.converged = true;
      break;
    }
  }
  res.p << W(0, 2), W(0, 0) - 1.0, W(0, 1), W(1, 2), W(1, 0), W(1, 1) - 1.0;
  res.ok = true;
  return res;
}

}  // namespace gs::dic
