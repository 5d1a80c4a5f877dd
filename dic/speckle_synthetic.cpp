#include "speckle_synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace gs::dic {

SpecklePattern::SpecklePattern(double x0, double y0, double x1, double y1,
                               const SpeckleParams& params)
    : x0_(x0), y0_(y0), background_(params.background) {
  if (!(x1 > x0 && y1 > y0) || params.mean_radius_px <= 0.0 || params.coverage <= 0.0 ||
      params.coverage >= 1.0)
    throw std::invalid_argument("SpecklePattern: bad domain or parameters");
  const double rmax = params.mean_radius_px * (1.0 + params.radius_spread);
  // Extend the domain so discs centred outside still cover its border.
  const double ex0 = x0 - rmax, ey0 = y0 - rmax, ex1 = x1 + rmax, ey1 = y1 + rmax;
  const double a = params.mean_radius_px * (1.0 - params.radius_spread);
  const double b = rmax;
  const double mean_r2 = (b * b + a * b + a * a) / 3.0;  // E[r^2], r uniform in [a, b]
  const double lambda = -std::log(1.0 - params.coverage) / (std::numbers::pi * mean_r2);
  std::mt19937_64 rng(params.seed);
  std::poisson_distribution<long> count(lambda * (ex1 - ex0) * (ey1 - ey0));
  std::uniform_real_distribution<double> ux(ex0, ex1), uy(ey0, ey1), ur(a, b),
      ul(params.level_lo, params.level_hi);
  const long n = count(rng);
  discs_.reserve(static_cast<std::size_t>(n));
  for (long i = 0; i < n; ++i) {
    Disc d;
    d.centre = {ux(rng), uy(rng)};
    d.radius = ur(rng);
    d.level = ul(rng);
    discs_.push_back(d);
  }
  cell_ = 2.0 * rmax;
  x0_ = ex0;
  y0_ = ey0;
  nx_ = static_cast<int>(std::ceil((ex1 - ex0) / cell_)) + 1;
  ny_ = static_cast<int>(std::ceil((ey1 - ey0) / cell_)) + 1;
  cells_.resize(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_));
  for (int i = 0; i < static_cast<int>(discs_.size()); ++i) {
    const Disc& d = discs_[static_cast<std::size_t>(i)];
    const int cx0 =
        std::max(0, static_cast<int>(std::floor((d.centre.x() - d.radius - x0_) / cell_)));
    const int cx1 =
        std::min(nx_ - 1, static_cast<int>(std::floor((d.centre.x() + d.radius - x0_) / cell_)));
    const int cy0 =
        std::max(0, static_cast<int>(std::floor((d.centre.y() - d.radius - y0_) / cell_)));
    const int cy1 =
        std::min(ny_ - 1, static_cast<int>(std::floor((d.centre.y() + d.radius - y0_) / cell_)));
    for (int cy = cy0; cy <= cy1; ++cy)
      for (int cx = cx0; cx <= cx1; ++cx)
        cells_[static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) +
               static_cast<std::size_t>(cx)]
            .push_back(i);
  }
}

double SpecklePattern::intensity(const Eigen::Vector2d& X) const {
  const int cx = static_cast<int>(std::floor((X.x() - x0_) / cell_));
  const int cy = static_cast<int>(std::floor((X.y() - y0_) / cell_));
  if (cx < 0 || cy < 0 || cx >= nx_ || cy >= ny_) return background_;
  const auto& cell = cells_[static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx_) +
                            static_cast<std::size_t>(cx)];
  int top = -1;
  for (const int i : cell) {
    const Disc& d = discs_[static_cast<std::size_t>(i)];
    if ((X - d.centre).squaredNorm() <= d.radius * d.radius) top = std::max(top, i);
  }
  return top < 0 ? background_ : discs_[static_cast<std::size_t>(top)].level;
}

cv::Mat render_speckle(const SpecklePattern& pattern, int rows, int cols, const InverseMap& inverse,
                       const RenderParams& params) {
  if (rows <= 0 || cols <= 0 || params.supersample < 1)
    throw std::invalid_argument("render_speckle: bad size or supersampling");
  // Render with a margin so the blur is exact up to the image border, then crop.
  const int margin =
      params.blur_sigma > 0.0 ? static_cast<int>(std::ceil(4.0 * params.blur_sigma)) : 0;
  cv::Mat full(rows + 2 * margin, cols + 2 * margin, CV_64F);
  const int s = params.supersample;
  const double inv = 1.0 / (s * s);
#pragma omp parallel for schedule(static)
  for (int r = 0; r < full.rows; ++r) {
    for (int c = 0; c < full.cols; ++c) {
      double acc = 0.0;
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
          const Eigen::Vector2d x(c - margin - 0.5 + (i + 0.5) / s,
                                  r - margin - 0.5 + (j + 0.5) / s);
          acc += pattern.intensity(inverse(x));
        }
      full.at<double>(r, c) = acc * inv;
    }
  }
  if (params.blur_sigma > 0.0)
    cv::GaussianBlur(full, full, cv::Size(0, 0), params.blur_sigma, params.blur_sigma,
                     cv::BORDER_REFLECT);
  cv::Mat img = full(cv::Rect(margin, margin, cols, rows)).clone();
  if (params.noise_sigma > 0.0) {
    std::mt19937_64 rng(params.noise_seed);
    std::normal_distribution<double> n(0.0, params.noise_sigma);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) img.at<double>(r, c) += n(rng);
  }
  if (params.quantize_8bit)
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        img.at<double>(r, c) = std::clamp(std::round(img.at<double>(r, c)), 0.0, 255.0);
  return img;
}

}  // namespace gs::dic
