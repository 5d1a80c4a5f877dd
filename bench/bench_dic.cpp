// DIC accuracy and speed against exact synthetic motion (issue 8 acceptance tables).
// Usage: bench_dic [--quick]. Prints Markdown tables; timings are wall clock.
#include <omp.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "dic_strain.hpp"
#include "reliability_guided.hpp"
#include "render_frames.hpp"
#include "speckle_synthetic.hpp"
#include "zncc_seed.hpp"

using namespace gs::dic;

namespace {

constexpr double kNoise = 2.55;  // 1% of the 255 grey-level range

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

cv::Mat render(const SpecklePattern& pat, int rows, int cols, const InverseMap& inv,
               std::uint64_t seed) {
  RenderParams rp;
  rp.noise_sigma = kNoise;
  rp.noise_seed = seed;
  return render_speckle(pat, rows, cols, inv, rp);
}

InverseMap identity() {
  return [](const Eigen::Vector2d& x) { return x; };
}

struct Stats {
  double mean = 0.0, sd = 0.0, rms = 0.0;
  int n = 0;
};

Stats stats(const std::vector<double>& e) {
  Stats s;
  for (const double v : e) s.mean += v;
  s.n = static_cast<int>(e.size());
  if (s.n == 0) return s;
  s.mean /= s.n;
  for (const double v : e) {
    s.sd += (v - s.mean) * (v - s.mean);
    s.rms += v * v;
  }
  s.sd = std::sqrt(s.sd / s.n);
  s.rms = std::sqrt(s.rms / s.n);
  return s;
}

void translations(int n) {
  std::printf("\n## Rigid translations (subset 31 px, step 4 px, noise 1%%, %dx%d px)\n\n", n, n);
  std::printf(
      "| shift px | bias u px | std u px | bias v px | std v px | valid POIs "
      "|\n|---|---|---|---|---|---|\n");
  const SpecklePattern pat(-40, -40, n + 40, n + 40, SpeckleParams{});
  const cv::Mat ref = render(pat, n, n, identity(), 1);
  DicOptions opt;
  opt.radius = 15;
  opt.threads = 2;
  const PoiGrid grid = make_grid(n, n, opt.radius, 4);
  double worst_bias = 0.0, worst_sd = 0.0;
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    const cv::Mat def = render(
        pat, n, n, [t](const Eigen::Vector2d& x) { return Eigen::Vector2d(x.x() - t, x.y()); },
        100 + static_cast<std::uint64_t>(k));
    const DicField f = correlate(ref, def, grid, opt);
    std::vector<double> eu, ev;
    for (std::size_t i = 0; i < f.p.size(); ++i)
      if (f.valid[i]) {
        eu.push_back(f.p[i][0] - t);
        ev.push_back(f.p[i][3]);
      }
    const Stats su = stats(eu), sv = stats(ev);
    worst_bias = std::max({worst_bias, std::abs(su.mean), std::abs(sv.mean)});
    worst_sd = std::max({worst_sd, su.sd, sv.sd});
    std::printf("| %.1f | %+.4f | %.4f | %+.4f | %.4f | %d/%d |\n", t, su.mean, su.sd, sv.mean,
                sv.sd, su.n, grid.size());
  }
  std::printf("\nworst |bias| = %.4f px (target < 0.005), worst std = %.4f px (target < 0.01)\n",
              worst_bias, worst_sd);
}

void uniform_strain(int n) {
  std::printf(
      "\n## Uniform strain (exx = 0.5%%, eyy = -0.2%%, subset 31, step 2, window 15 POIs, noise "
      "1%%)\n\n");
  const double exx = 0.005, eyy = -0.002, c0 = n / 2.0;
  const SpecklePattern pat(-40, -40, n + 40, n + 40, SpeckleParams{});
  const cv::Mat ref = render(pat, n, n, identity(), 1);
  const cv::Mat def = render(
      pat, n, n,
      [&](const Eigen::Vector2d& x) {
        return Eigen::Vector2d(c0 + (x.x() - c0) / (1 + exx), c0 + (x.y() - c0) / (1 + eyy));
      },
      2);
  DicOptions opt;
  opt.radius = 15;
  opt.threads = 2;
  const PoiGrid grid = make_grid(n, n, opt.radius, 2);
  const DicField f = correlate(ref, def, grid, opt);
  std::vector<double> u(f.p.size()), v(f.p.size());
  for (std::size_t i = 0; i < u.size(); ++i) {
    u[i] = f.p[i][0];
    v[i] = f.p[i][3];
  }
  const StrainField s = plane_fit_strain(grid, u, v, f.valid, 7, 31);
  std::vector<double> e1, e2, e3;
  for (std::size_t i = 0; i < u.size(); ++i)
    if (s.valid[i]) {
      e1.push_back(s.exx[i] - (exx + 0.5 * exx * exx));
      e2.push_back(s.eyy[i] - (eyy + 0.5 * eyy * eyy));
      e3.push_back(s.exy[i]);
    }
  const Stats a = stats(e1), b = stats(e2), c = stats(e3);
  std::printf("| component | mean error | RMS error | max |error| |\n|---|---|---|---|\n");
  auto mx = [](const std::vector<double>& e) {
    double m = 0;
    for (double v : e) m = std::max(m, std::abs(v));
    return m;
  };
  std::printf(
      "| Exx | %+.2e | %.2e | %.2e |\n| Eyy | %+.2e | %.2e | %.2e |\n| Exy | %+.2e | %.2e | %.2e "
      "|\n",
      a.mean, a.rms, mx(e1), b.mean, b.rms, mx(e2), c.mean, c.rms, mx(e3));
  std::printf("\nVSG = %.0f px; %d POIs with strain (target: error < 5e-4)\n", s.vsg_px, a.n);
}

void sinusoidal(int rows, int cols) {
  const double A = 0.5, lambda = 128.0, k = 2 * std::numbers::pi / lambda;
  std::printf(
      "\n## Sinusoidal displacement u = %.1f sin(2 pi X / %.0f) (noise 1%%, step 2, %dx%d px, 2 "
      "threads)\n\n",
      A, lambda, cols, rows);
  const SpecklePattern pat(-40, -40, cols + 40, rows + 40, SpeckleParams{});
  const cv::Mat ref = render(pat, rows, cols, identity(), 1);
  const cv::Mat def = render(
      pat, rows, cols,
      [&](const Eigen::Vector2d& x) {
        double X = x.x();
        for (int it = 0; it < 30; ++it)
          X -= (X + A * std::sin(k * X) - x.x()) / (1 + A * k * std::cos(k * X));
        return Eigen::Vector2d(X, x.y());
      },
      3);
  std::printf(
      "| subset px | RMS u error px | time per POI us | window POIs | VSG px | RMS exx error "
      "|\n|---|---|---|---|---|---|\n");
  for (const int subset : {21, 31, 41, 61}) {
    DicOptions opt;
    opt.radius = subset / 2;
    opt.threads = 2;
    const PoiGrid grid = make_grid(rows, cols, opt.radius, 2);
    const double t0 = now();
    const DicField f = correlate(ref, def, grid, opt);
    const double dt = now() - t0;
    std::vector<double> eu, u(f.p.size()), v(f.p.size());
    for (std::size_t i = 0; i < f.p.size(); ++i) {
      u[i] = f.p[i][0];
      v[i] = f.p[i][3];
      if (f.valid[i]) eu.push_back(u[i] - A * std::sin(k * grid.x(static_cast<int>(i))));
    }
    bool first = true;
    for (const int w : {5, 9, 15}) {
      const StrainField s = plane_fit_strain(grid, u, v, f.valid, w / 2, subset);
      std::vector<double> es;
      for (std::size_t i = 0; i < u.size(); ++i)
        if (s.valid[i]) es.push_back(s.sxx[i] - A * k * std::cos(k * grid.x(static_cast<int>(i))));
      if (first)
        std::printf("| %d | %.4f | %.2f | %d | %.0f | %.2e |\n", subset, stats(eu).rms,
                    1e6 * dt / grid.size(), w, s.vsg_px, stats(es).rms);
      else
        std::printf("| | | | %d | %.0f | %.2e |\n", w, s.vsg_px, stats(es).rms);
      first = false;
    }
  }
  std::printf("\n(peak strain amplitude %.2e; exx error is small strain vs du/dX)\n", A * k);
}

void speed(int n) {
  std::printf(
      "\n## Speed (subset 31, step 2, %dx%d px image, translation 0.37 px + 0.2%% strain)\n\n", n,
      n);
  const SpecklePattern pat(-40, -40, n + 40, n + 40, SpeckleParams{});
  const cv::Mat ref = render(pat, n, n, identity(), 1);
  const cv::Mat def = render(
      pat, n, n,
      [](const Eigen::Vector2d& x) {
        return Eigen::Vector2d((x.x() - 0.37) / 1.002, x.y() + 0.21);
      },
      2);
  DicOptions opt;
  opt.radius = 15;
  const PoiGrid grid = make_grid(n, n, opt.radius, 2);
  std::printf("| method | threads | POIs | time s | POI/s | valid |\n|---|---|---|---|---|---|\n");
  for (const int th : {1, 2}) {
    opt.threads = th;
    const double t0 = now();
    const DicField f = correlate(ref, def, grid, opt);
    const double dt = now() - t0;
    int nv = 0;
    for (const auto v : f.valid) nv += v;
    std::printf("| IC-GN + B-spline + RG | %d | %d | %.3f | %.0f | %d |\n", th, grid.size(), dt,
                grid.size() / dt, nv);
  }
  // Baseline: integer ZNCC template matching at every POI (+-3 px search), no sub-pixel.
  cv::Mat r32, d32;
  ref.convertTo(r32, CV_32F);
  def.convertTo(d32, CV_32F);
  for (const int th : {1, 2}) {
    std::vector<int> ok(static_cast<std::size_t>(grid.size()));
    const double t0 = now();
#pragma omp parallel for schedule(dynamic, 64) num_threads(th)
    for (int i = 0; i < grid.size(); ++i)
      ok[static_cast<std::size_t>(i)] = zncc_match(r32, d32, grid.x(i), grid.y(i), 15, 3).ok;
    const double dt = now() - t0;
    int nv = 0;
    for (const int v : ok) nv += v;
    std::printf("| ZNCC matchTemplate (integer, +-3 px) | %d | %d | %.3f | %.0f | %d |\n", th,
                grid.size(), dt, grid.size() / dt, nv);
  }
}

// Rendered "DEM" frames: a random sequential packing of spheres in a slab (3 d50 thick), simple
// shear with the continuum spin plus random grain rotations, seen through the front face.
void rendered_dem(int size_d50) {
  const double d50 = 0.002;
  std::mt19937_64 rng(5);
  const double L = size_d50 * d50, T = 3 * d50;
  std::uniform_real_distribution<double> ux(0, L), uy(0, T), ur(0.4 * d50, 0.6 * d50),
      rot(-0.02, 0.02);
  gs::Frame f0;
  for (int tries = 0; tries < 400000; ++tries) {
    gs::Particle p;
    p.position = {ux(rng), uy(rng), ux(rng)};
    p.radius = ur(rng);
    bool ok = true;
    for (const auto& q : f0.particles)
      if ((q.position - p.position).squaredNorm() < (q.radius + p.radius) * (q.radius + p.radius)) {
        ok = false;
        break;
      }
    if (!ok) continue;
    p.id = static_cast<std::int64_t>(f0.particles.size()) + 1;
    f0.particles.push_back(p);
  }
  const double gamma = 0.01;
  gs::Frame f1 = f0;
  for (auto& p : f1.particles) {
    p.position.x() += gamma * (p.position.z() - L / 2);
    const double spin = 0.5 * gamma + rot(rng);  // about +y: x towards -z for positive angle
    p.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitY()));
  }
  const Camera cam = make_camera(f0, View::Front, 25.0, 0.0, "bench");
  gs::dic::RenderOptions ro;
  ro.noise_sigma = kNoise;
  const cv::Mat ref = render_frame(f0, cam, ro);
  ro.seed = 1;
  ro.noise_sigma = kNoise;
  gs::Frame f1n = f1;
  f1n.step = 1;  // different noise realisation
  const cv::Mat def = render_frame(f1n, cam, ro);
  const GroundTruth gt = ground_truth(f0, f1, cam);
  std::printf(
      "\n## Rendered DEM frames (%zu spheres, %dx%d px, 25 px per d50, simple shear %.0f%%, 1%% "
      "noise)\n\n",
      f0.particles.size(), cam.cols, cam.rows, 100 * gamma);
  std::printf(
      "DIC u, v against the ground truth averaged over each subset (visible grain pixels).\n\n");
  std::printf(
      "| subset px | subset / d50 | RMS u-u_gt px | RMS v-v_gt px | valid POIs | time per POI us "
      "|\n|---|---|---|---|---|---|\n");
  for (const int subset : {21, 31, 41, 61}) {
    DicOptions opt;
    opt.radius = subset / 2;
    opt.threads = 2;
    opt.zncc_min = 0.8;
    const PoiGrid grid = make_grid(cam.rows, cam.cols, opt.radius, 2);
    const double t0 = now();
    const DicField f = correlate(ref, def, grid, opt);
    const double dt = now() - t0;
    std::vector<double> eu, ev;
    for (int i = 0; i < grid.size(); ++i) {
      if (!f.valid[static_cast<std::size_t>(i)]) continue;
      double su = 0, sv = 0;
      int n = 0;
      for (int r = grid.y(i) - opt.radius; r <= grid.y(i) + opt.radius; ++r)
        for (int c = grid.x(i) - opt.radius; c <= grid.x(i) + opt.radius; ++c) {
          const double u = gt.u.at<double>(r, c);
          if (!std::isfinite(u) || !gt.visible.at<std::uint8_t>(r, c)) continue;
          su += u;
          sv += gt.v.at<double>(r, c);
          ++n;
        }
      if (n < subset * subset / 4) continue;
      eu.push_back(f.p[static_cast<std::size_t>(i)][0] - su / n);
      ev.push_back(f.p[static_cast<std::size_t>(i)][3] - sv / n);
    }
    std::printf("| %d | %.2f | %.4f | %.4f | %zu/%d | %.2f |\n", subset, subset / 25.0,
                stats(eu).rms, stats(ev).rms, eu.size(), grid.size(), 1e6 * dt / grid.size());
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("# granoscope DIC bench%s (OpenMP max threads %d)\n", quick ? " (quick)" : "",
              omp_get_max_threads());
  translations(quick ? 128 : 256);
  uniform_strain(quick ? 160 : 256);
  sinusoidal(quick ? 128 : 192, quick ? 256 : 512);
  rendered_dem(quick ? 8 : 14);
  speed(quick ? 192 : 512);
  return 0;
}
