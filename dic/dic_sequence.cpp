#include "dic_sequence.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace gs::dic {

bool is_textureless(const cv::Mat& image) {
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(image, mean, stddev);
  return stddev[0] < 0.5;  // grey levels: below half a quantisation step of 8-bit images
}

namespace {

FrameResult from_field(const DicField& f) {
  FrameResult r;
  const std::size_t n = f.p.size();
  r.u.resize(n);
  r.v.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    r.u[i] = f.valid[i] ? f.p[i][0] : std::numeric_limits<double>::quiet_NaN();
    r.v[i] = f.valid[i] ? f.p[i][3] : std::numeric_limits<double>::quiet_NaN();
  }
  r.zncc = f.zncc;
  r.valid = f.valid;
  return r;
}

// Bilinear interpolation of an incremental field (defined on the grid placed in the previous
// image) at point (x, y); false when a corner is invalid or outside the grid.
bool interpolate(const PoiGrid& g, const FrameResult& inc, double x, double y, double& du,
                 double& dv, double& zncc) {
  const double gx = (x - g.x0) / g.step;
  const double gy = (y - g.y0) / g.step;
  const int i = static_cast<int>(std::floor(gx));
  const int j = static_cast<int>(std::floor(gy));
  if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) return false;
  const int i1 = std::min(i + 1, g.nx - 1);
  const int j1 = std::min(j + 1, g.ny - 1);
  const double tx = gx - i;
  const double ty = gy - j;
  const int idx[4] = {j * g.nx + i, j * g.nx + i1, j1 * g.nx + i, j1 * g.nx + i1};
  const double w[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
  du = dv = 0.0;
  zncc = 1.0;
  for (int k = 0; k < 4; ++k) {
    const auto q = static_cast<std::size_t>(idx[k]);
    if (w[k] == 0.0) continue;
    if (!inc.valid[q]) return false;
    du += w[k] * inc.u[q];
    dv += w[k] * inc.v[q];
    zncc = std::min(zncc, inc.zncc[q]);
  }
  return true;
}

}  // namespace

SequenceResult correlate_sequence(const std::vector<cv::Mat>& images, const cv::Mat& roi,
                                  const SequenceOptions& options) {
  if (images.size() < 2) throw std::invalid_argument("need a reference and at least one image");
  for (std::size_t k = 1; k < images.size(); ++k)
    if (images[k].size() != images[0].size())
      throw std::invalid_argument("image " + std::to_string(k + 1) +
                                  " differs in size from the reference");
  SequenceResult out;
  out.grid = make_grid(images[0].rows, images[0].cols, options.dic.radius, options.step, roi);
  const int subset = 2 * options.dic.radius + 1;
  for (std::size_t k = 1; k < images.size(); ++k) {
    const cv::Mat& ref = options.incremental ? images[k - 1] : images[0];
    FrameResult fr;
    DicField f;
    try {
      f = correlate(ref, images[k], out.grid, options.dic);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("image " + std::to_string(k + 1) + ": " + e.what());
    }
    out.seconds_prefilter += f.seconds_prefilter;
    out.seconds_seeds += f.seconds_seeds;
    out.seconds_propagation += f.seconds_propagation;
    out.icgn_iterations += f.icgn_iterations;
    const FrameResult inc = from_field(f);
    if (!options.incremental || k == 1) {
      fr = inc;
    } else {
      const FrameResult& prev = out.frames.back();
      fr = prev;
      for (int i = 0; i < out.grid.size(); ++i) {
        const auto c = static_cast<std::size_t>(i);
        double du = 0.0, dv = 0.0, z = -1.0;
        if (prev.valid[c] && interpolate(out.grid, inc, out.grid.x(i) + prev.u[c],
                                         out.grid.y(i) + prev.v[c], du, dv, z)) {
          fr.u[c] = prev.u[c] + du;
          fr.v[c] = prev.v[c] + dv;
          fr.zncc[c] = z;
        } else {
          fr.u[c] = fr.v[c] = std::numeric_limits<double>::quiet_NaN();
          fr.zncc[c] = -1.0;
          fr.valid[c] = 0;
        }
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    fr.strain =
        plane_fit_strain(out.grid, fr.u, fr.v, fr.valid, options.strain_window_radius, subset);
    out.seconds_strain +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out.frames.push_back(std::move(fr));
  }
  return out;
}

}  // namespace gs::dic
