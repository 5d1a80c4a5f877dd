#include "bspline_interpolation.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace gs::dic {
namespace {

// In-place cubic B-spline prefilter of one line with mirror boundaries (Thévenaz et al. 2000,
// "Interpolation revisited", Appendix). Pole z = sqrt(3) - 2, overall gain 6.
void prefilter_line(std::vector<double>& c) {
  const auto n = static_cast<int>(c.size());
  if (n < 2) return;
  const double z = std::sqrt(3.0) - 2.0;
  const double gain = (1.0 - z) * (1.0 - 1.0 / z);
  for (double& v : c) v *= gain;
  // Causal initialisation: truncated geometric sum (exact to double precision).
  const int horizon = std::min(n, static_cast<int>(std::ceil(std::log(1e-16) / std::log(-z))));
  double sum = c[0];
  double zk = z;
  if (horizon < n) {
    for (int k = 1; k < horizon; ++k) {
      sum += zk * c[static_cast<std::size_t>(k)];
      zk *= z;
    }
  } else {  // full mirror sum for short lines
    const double zn = std::pow(z, n - 1);
    double z2n = zn * zn / z;
    sum = c[0] + zn * c[static_cast<std::size_t>(n - 1)];
    for (int k = 1; k <= n - 2; ++k) {
      sum += (zk + z2n) * c[static_cast<std::size_t>(k)];
      zk *= z;
      z2n /= z;
    }
    sum /= (1.0 - zn * zn);
  }
  c[0] = sum;
  for (int k = 1; k < n; ++k)
    c[static_cast<std::size_t>(k)] += z * c[static_cast<std::size_t>(k - 1)];
  // Anticausal initialisation.
  const auto last = static_cast<std::size_t>(n - 1);
  c[last] = (z / (z * z - 1.0)) * (z * c[last - 1] + c[last]);
  for (int k = n - 2; k >= 0; --k) {
    const auto i = static_cast<std::size_t>(k);
    c[i] = z * (c[i + 1] - c[i]);
  }
}

}  // namespace

cv::Mat bspline_prefilter(const cv::Mat& image) {
  if (image.empty() || image.channels() != 1)
    throw std::invalid_argument("bspline_prefilter: need a non-empty single-channel image");
  cv::Mat c;
  image.convertTo(c, CV_64F);
  std::vector<double> line;
  line.resize(static_cast<std::size_t>(c.cols));
  for (int r = 0; r < c.rows; ++r) {
    auto* row = c.ptr<double>(r);
    line.assign(row, row + c.cols);
    prefilter_line(line);
    std::copy(line.begin(), line.end(), row);
  }
  line.resize(static_cast<std::size_t>(c.rows));
  for (int col = 0; col < c.cols; ++col) {
    for (int r = 0; r < c.rows; ++r) line[static_cast<std::size_t>(r)] = c.at<double>(r, col);
    prefilter_line(line);
    for (int r = 0; r < c.rows; ++r) c.at<double>(r, col) = line[static_cast<std::size_t>(r)];
  }
  return c;
}

BSplineImage::BSplineImage(const cv::Mat& image) : rows_(image.rows), cols_(image.cols) {
  if (image.rows < 4 || image.cols < 4)
    throw std::invalid_argument("BSplineImage: image smaller than 4x4 px");
  cv::copyMakeBorder(bspline_prefilter(image), coef_, kPad, kPad, kPad, kPad,
                     cv::BORDER_REFLECT_101);
}

namespace {
inline void weights(double t, double w[4]) {
  const double s = 1.0 - t;
  const double t2 = t * t;
  const double t3 = t2 * t;
  w[0] = s * s * s / 6.0;
  w[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
  w[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
  w[3] = t3 / 6.0;
}
inline void dweights(double t, double d[4]) {
  const double s = 1.0 - t;
  d[0] = -0.5 * s * s;
  d[1] = 1.5 * t * t - 2.0 * t;
  d[2] = -1.5 * t * t + t + 0.5;
  d[3] = 0.5 * t * t;
}
}  // namespace

double BSplineImage::value(double x, double y) const {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  double wx[4];
  double wy[4];
  weights(x - fx, wx);
  weights(y - fy, wy);
  const int ix = static_cast<int>(fx) + kPad - 1;
  const int iy = static_cast<int>(fy) + kPad - 1;
  double v = 0.0;
  for (int j = 0; j < 4; ++j) {
    const double* row = coef_.ptr<double>(iy + j) + ix;
    v += wy[j] * (wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2] + wx[3] * row[3]);
  }
  return v;
}

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
