#include "bspline_interpolation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace gs::dic {
namespace {

// In-place cubic B-spline prefilter along the columns c0 <= col < c1 of a CV_64F image, each
// column a line with mirror boundaries (Thévenaz et al. 2000, "Interpolation revisited",
// Appendix). Pole z = sqrt(3) - 2, overall gain 6. The recursions run down the rows with the
// columns side by side, so the inner loops walk contiguous memory (and vectorise).
void prefilter_columns(cv::Mat& c, int c0, int c1) {
  const int n = c.rows;
  if (n < 2 || c1 <= c0) return;
  const auto w = static_cast<std::size_t>(c1 - c0);
  const auto row = [&](int r) { return c.ptr<double>(r) + c0; };
  const double z = std::sqrt(3.0) - 2.0;
  const double gain = (1.0 - z) * (1.0 - 1.0 / z);
  for (int r = 0; r < n; ++r) {
    double* p = row(r);
    for (std::size_t i = 0; i < w; ++i) p[i] *= gain;
  }
  // Causal initialisation: truncated geometric sum (exact to double precision).
  const int horizon = std::min(n, static_cast<int>(std::ceil(std::log(1e-16) / std::log(-z))));
  std::vector<double> sum(row(0), row(0) + w);
  double zk = z;
  if (horizon < n) {
    for (int k = 1; k < horizon; ++k) {
      const double* p = row(k);
      for (std::size_t i = 0; i < w; ++i) sum[i] += zk * p[i];
      zk *= z;
    }
  } else {  // full mirror sum for short lines
    const double zn = std::pow(z, n - 1);
    double z2n = zn * zn / z;
    const double* last = row(n - 1);
    for (std::size_t i = 0; i < w; ++i) sum[i] += zn * last[i];
    for (int k = 1; k <= n - 2; ++k) {
      const double* p = row(k);
      const double f = zk + z2n;
      for (std::size_t i = 0; i < w; ++i) sum[i] += f * p[i];
      zk *= z;
      z2n /= z;
    }
    for (std::size_t i = 0; i < w; ++i) sum[i] /= (1.0 - zn * zn);
  }
  std::copy(sum.begin(), sum.end(), row(0));
  for (int k = 1; k < n; ++k) {
    double* p = row(k);
    const double* q = row(k - 1);
    for (std::size_t i = 0; i < w; ++i) p[i] += z * q[i];
  }
  // Anticausal initialisation.
  {
    double* p = row(n - 1);
    const double* q = row(n - 2);
    for (std::size_t i = 0; i < w; ++i) p[i] = (z / (z * z - 1.0)) * (z * q[i] + p[i]);
  }
  for (int k = n - 2; k >= 0; --k) {
    double* p = row(k);
    const double* q = row(k + 1);
    for (std::size_t i = 0; i < w; ++i) p[i] = z * (q[i] - p[i]);
  }
}

// All columns, in blocks of 64 (one block's rows stay in cache) spread over the threads.
void prefilter_all_columns(cv::Mat& c, int threads) {
  constexpr int kBlock = 64;
  const int blocks = (c.cols + kBlock - 1) / kBlock;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads))
  for (int b = 0; b < blocks; ++b)
    prefilter_columns(c, b * kBlock, std::min(c.cols, (b + 1) * kBlock));
}

}  // namespace

cv::Mat bspline_prefilter(const cv::Mat& image, int threads) {
  if (image.empty() || image.channels() != 1)
    throw std::invalid_argument("bspline_prefilter: need a non-empty single-channel image");
  cv::Mat c;
  image.convertTo(c, CV_64F);
  // Along the rows (as the columns of the transpose), then along the columns.
  cv::Mat t = c.t();
  prefilter_all_columns(t, threads);
  c = t.t();
  prefilter_all_columns(c, threads);
  return c;
}

BSplineImage::BSplineImage(const cv::Mat& image, int threads)
    : rows_(image.rows), cols_(image.cols) {
  if (image.rows < 4 || image.cols < 4)
    throw std::invalid_argument("BSplineImage: image smaller than 4x4 px");
  cv::copyMakeBorder(bspline_prefilter(image, threads), coef_, kPad, kPad, kPad, kPad,
                     cv::BORDER_REFLECT_101);
  base_ = coef_.ptr<double>(0);
  stride_ = static_cast<std::ptrdiff_t>(coef_.step1());
}

namespace {
inline void dweights(double t, double d[4]) {
  const double s = 1.0 - t;
  d[0] = -0.5 * s * s;
  d[1] = 1.5 * t * t - 2.0 * t;
  d[2] = -1.5 * t * t + t + 0.5;
  d[3] = 0.5 * t * t;
}
}  // namespace

Sample BSplineImage::sample(double x, double y) const {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  double wx[4];
  double wy[4];
  double dx[4];
  double dy[4];
  weights(x - fx, wx);
  weights(y - fy, wy);
  dweights(x - fx, dx);
  dweights(y - fy, dy);
  const int ix = static_cast<int>(fx) + kPad - 1;
  const int iy = static_cast<int>(fy) + kPad - 1;
  Sample s;
  for (int j = 0; j < 4; ++j) {
    const double* row = coef_.ptr<double>(iy + j) + ix;
    const double rv = wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2] + wx[3] * row[3];
    const double rd = dx[0] * row[0] + dx[1] * row[1] + dx[2] * row[2] + dx[3] * row[3];
    s.value += wy[j] * rv;
    s.dx += wy[j] * rd;
    s.dy += dy[j] * rv;
  }
  return s;
}

}  // namespace gs::dic
