#include "reliability_guided.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "bspline_interpolation.hpp"
#include "zncc_seed.hpp"

namespace gs::dic {

PoiGrid make_grid(int rows, int cols, int radius, int step, const cv::Mat& roi) {
  if (step < 1) throw std::invalid_argument("POI step must be >= 1 px");
  if (radius < 1) throw std::invalid_argument("subset must be at least 3 px");
  PoiGrid g;
  g.step = step;
  g.x0 = radius;
  g.y0 = radius;
  if (cols < 2 * radius + 1 || rows < 2 * radius + 1)
    throw std::invalid_argument("image smaller than one subset");
  g.nx = (cols - 1 - 2 * radius) / step + 1;
  g.ny = (rows - 1 - 2 * radius) / step + 1;
  g.in_roi.assign(static_cast<std::size_t>(g.size()), 1);
  if (!roi.empty()) {
    if (roi.rows != rows || roi.cols != cols)
      throw std::invalid_argument("ROI mask size differs from the image size");
    cv::Mat m;
    if (roi.channels() != 1) throw std::invalid_argument("ROI mask must be single-channel");
    roi.convertTo(m, CV_8U);
    for (int i = 0; i < g.size(); ++i)
      g.in_roi[static_cast<std::size_t>(i)] = m.at<std::uint8_t>(g.y(i), g.x(i)) != 0 ? 1 : 0;
  }
  if (std::none_of(g.in_roi.begin(), g.in_roi.end(), [](std::uint8_t v) { return v != 0; }))
    throw std::invalid_argument("ROI contains no point of interest");
  return g;
}

DicField correlate(const cv::Mat& reference, const cv::Mat& deformed, const PoiGrid& grid,
                   const DicOptions& options) {
  if (reference.size() != deformed.size())
    throw std::invalid_argument("reference and deformed images differ in size");
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto t0 = Clock::now();
  cv::Mat ref64;
  cv::Mat def64;
  reference.convertTo(ref64, CV_64F);
  deformed.convertTo(def64, CV_64F);
  const int threads = std::max(1, options.threads);
  const BSplineImage def_spline(def64, threads);
  IcgnOptions icgn = options.icgn;
  icgn.threads = threads;
  const IcgnSolver solver(ref64, def_spline, options.radius, icgn);

  DicField out;
  out.seconds_prefilter = since(t0);
  t0 = Clock::now();
  out.grid = grid;
  const auto n = static_cast<std::size_t>(grid.size());
  out.p.assign(n, Shape::Zero());
  out.zncc.assign(n, -1.0);
  out.valid.assign(n, 0);
  out.solved.assign(n, 0);

  auto store = [&](int idx, const IcgnResult& r) {
    const auto i = static_cast<std::size_t>(idx);
    out.p[i] = r.p;
    out.zncc[i] = r.zncc;
    out.solved[i] = 1;
    out.icgn_iterations += r.iterations;
    out.valid[i] = (r.ok && r.zncc >= options.zncc_min) ? 1 : 0;
  };

  // Seeds: candidates on a lattice over the grid (nearest in-ROI POI along the row).
  std::vector<int> candidates;
  const int S = std::max(1, options.seeds_per_axis);
  for (int sj = 0; sj < S; ++sj)
    for (int si = 0; si < S; ++si) {
      const int j = std::min(grid.ny - 1, static_cast<int>((sj + 0.5) * grid.ny / S));
      const int i0 = std::min(grid.nx - 1, static_cast<int>((si + 0.5) * grid.nx / S));
      for (int d = 0; d < grid.nx; ++d) {
        const int i = i0 + ((d % 2) ? (d + 1) / 2 : -(d / 2));
        if (i < 0 || i >= grid.nx) continue;
        if (grid.in_roi[static_cast<std::size_t>(j * grid.nx + i)]) {
          candidates.push_back(j * grid.nx + i);
          break;
        }
      }
    }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  cv::Mat ref32;
  cv::Mat def32;
  ref64.convertTo(ref32, CV_32F);
  def64.convertTo(def32, CV_32F);
  std::vector<IcgnResult> seed_res(candidates.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int s = 0; s < static_cast<int>(candidates.size()); ++s) {
    const int idx = candidates[static_cast<std::size_t>(s)];
    const IntegerMatch m =
        zncc_match(ref32, def32, grid.x(idx), grid.y(idx), options.radius, options.search);
    if (!m.ok) continue;
    Shape guess = Shape::Zero();
    guess[0] = m.u;
    guess[3] = m.v;
    seed_res[static_cast<std::size_t>(s)] = solver.solve(grid.x(idx), grid.y(idx), guess);
  }
  std::vector<int> front;
  double best_seed = -1.0;
  for (std::size_t s = 0; s < candidates.size(); ++s) {
    store(candidates[s], seed_res[s]);
    best_seed = std::max(best_seed, seed_res[s].zncc);
    if (out.valid[static_cast<std::size_t>(candidates[s])]) front.push_back(candidates[s]);
  }
  out.seeds = static_cast<int>(front.size());
  out.seconds_seeds = since(t0);
  t0 = Clock::now();
  if (front.empty())
    throw std::runtime_error("no seed reached the ZNCC threshold (best " +
                             std::to_string(best_seed) + ")");

  const int dxs[4] = {1, -1, 0, 0};
  const int dys[4] = {0, 0, 1, -1};
  std::vector<std::uint8_t> queued(n, 0);
  while (!front.empty()) {
    if (options.poll) options.poll();
    // Next front: unsolved in-ROI neighbours of the valid POIs of this front, sorted.
    std::vector<int> next;
    for (const int idx : front) {
      const int i = idx % grid.nx;
      const int j = idx / grid.nx;
      for (int d = 0; d < 4; ++d) {
        const int ii = i + dxs[d];
        const int jj = j + dys[d];
        if (ii < 0 || jj < 0 || ii >= grid.nx || jj >= grid.ny) continue;
        const int nidx = jj * grid.nx + ii;
        const auto u = static_cast<std::size_t>(nidx);
        if (!grid.in_roi[u] || out.solved[u] || queued[u]) continue;
        queued[u] = 1;
        next.push_back(nidx);
      }
    }
    std::sort(next.begin(), next.end());
    std::vector<IcgnResult> res(next.size());
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads)
    for (int q = 0; q < static_cast<int>(next.size()); ++q) {
      const int idx = next[static_cast<std::size_t>(q)];
      const int i = idx % grid.nx;
      const int j = idx / grid.nx;
      int from = -1;
      double best = -2.0;
      for (int d = 0; d < 4; ++d) {  // best-correlated solved valid neighbour
        const int ii = i + dxs[d];
        const int jj = j + dys[d];
        if (ii < 0 || jj < 0 || ii >= grid.nx || jj >= grid.ny) continue;
        const auto u = static_cast<std::size_t>(jj * grid.nx + ii);
        if (out.valid[u] && out.zncc[u] > best) {
          best = out.zncc[u];
          from = jj * grid.nx + ii;
        }
      }
      const Shape guess = shift_shape(out.p[static_cast<std::size_t>(from)],
                                      grid.x(idx) - grid.x(from), grid.y(idx) - grid.y(from));
      res[static_cast<std::size_t>(q)] = solver.solve(grid.x(idx), grid.y(idx), guess);
    }
    front.clear();
    for (std::size_t q = 0; q < next.size(); ++q) {
      store(next[q], res[q]);
      if (out.valid[static_cast<std::size_t>(next[q])]) front.push_back(next[q]);
    }
  }
  out.seconds_propagation = since(t0);
  return out;
}

}  // namespace gs::dic
