// Speed of the REV cell map (issue 5: the default map on a 56 000-sphere snapshot in < 1 s on
// 2 cores) against the brute-force O(cells x (particles + contacts)) baseline in the same run.
// The packing is generated in-process: a perturbed, polydisperse FCC lattice (solid fraction
// ~0.7, ~6 contacts per sphere from the overlaps) with random contact forces.
// The baseline runs on a subset of cells (every k-th) and is scaled to the whole grid; the fast
// map must agree with it on those cells (printed: largest relative difference).
//   OMP_NUM_THREADS=2 build/bin/bench_rev [n_spheres]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <unordered_map>
#include <vector>

#include "coarse_graining.hpp"
#include "grain_size.hpp"
#include "love_weber_stress.hpp"
#include "rev_cells.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

gs::Frame dense_packing(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double r = 0.5e-3, a = 2.0 * std::sqrt(2.0) * r;  // d50 ~ 1 mm
  const int side = static_cast<int>(std::ceil(std::cbrt(n / 4.0)));
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  gs::Frame f;
  for (int k = 0; k < side && f.particles.size() < n; ++k)
    for (int j = 0; j < side && f.particles.size() < n; ++j)
      for (int i = 0; i < side && f.particles.size() < n; ++i)
        for (const auto& b : basis) {
          if (f.particles.size() >= n) break;
          gs::Particle p;
          p.id = static_cast<std::int64_t>(f.particles.size());
          p.position = a * Eigen::Vector3d(i + b[0], j + b[1], k + b[2]) +
                       0.03 * r * Eigen::Vector3d(u(rng), u(rng), u(rng));
          p.radius = r * (1.0 + 0.06 * u(rng));
          p.rotation = Eigen::Vector3d(u(rng), u(rng), u(rng));
          f.particles.push_back(p);
        }
  // Contacts: overlapping pairs, found on a hash grid of cell 2 r_max.
  const double h = 2.2 * r;
  std::unordered_map<long long, std::vector<std::size_t>> grid;
  auto key = [h](const Eigen::Vector3d& x, int dx, int dy, int dz) {
    return (static_cast<long long>(std::floor(x.x() / h)) + dx) * 1000003LL * 1000003LL +
           (static_cast<long long>(std::floor(x.y() / h)) + dy) * 1000003LL +
           (static_cast<long long>(std::floor(x.z() / h)) + dz);
  };
  for (std::size_t i = 0; i < f.particles.size(); ++i)
    grid[key(f.particles[i].position, 0, 0, 0)].push_back(i);
  for (std::size_t i = 0; i < f.particles.size(); ++i)
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = grid.find(key(f.particles[i].position, dx, dy, dz));
          if (it == grid.end()) continue;
          for (const std::size_t j : it->second) {
            if (j <= i) continue;
            const auto &p = f.particles[i], &q = f.particles[j];
            const Eigen::Vector3d d = q.position - p.position;
            if (d.norm() >= p.radius + q.radius) continue;
            gs::Contact c;
            c.id1 = p.id;
            c.id2 = q.id;
            c.normal = d.normalized();
            c.point = p.position + p.radius * c.normal;
            c.normal_force = (0.5 + std::abs(u(rng))) * c.normal;
            c.shear_force = 0.2 * c.normal.cross(Eigen::Vector3d(u(rng), u(rng), u(rng)));
            f.contacts.push_back(c);
          }
        }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 56000;
  const bool baseline = argc <= 2;  // a second argument skips the brute force (profiling)
  auto t0 = Clock::now();
  const gs::Frame f = dense_packing(n, 1);
  std::printf(
      "packing: %zu spheres, %zu contacts (%.1f per sphere), generated in %.2f s, "
      "%d OpenMP threads\n",
      f.particles.size(), f.contacts.size(), 2.0 * f.contacts.size() / f.particles.size(),
      seconds_since(t0), omp_get_max_threads());
  const double d50 = gs::analysis::d50(f);

  // The default map: 3D grid, L = 5 d50, s = 1 d50, all fields (what `analyze rev` runs).
  gs::analysis::RevGridSpec spec;
  spec.cell = 5 * d50;
  spec.step = d50;
  t0 = Clock::now();
  const auto branches = gs::analysis::contact_branches(f);
  const auto grid = gs::analysis::make_rev_grid(f, spec);
  const auto fast = gs::analysis::rev_average(f, branches, grid);
  const double t_fast = seconds_since(t0);
  double e_mean = 0.0;
  for (double e : fast.void_ratio) e_mean += e;
  e_mean /= static_cast<double>(fast.void_ratio.size());
  std::printf(
      "default REV map (3D, L = 5 d50, s = d50): %zu cells (%d x %d x %d), %.3f s "
      "(mean void ratio %.4f)\n",
      grid.count(), grid.n[0], grid.n[1], grid.n[2], t_fast, e_mean);
  // Repeat for a stable number, with the time split.
  double best = t_fast, tb = 1e30, tg = 1e30, ta = 1e30;
  for (int rep = 0; rep < 3; ++rep) {
    t0 = Clock::now();
    const auto b2 = gs::analysis::contact_branches(f);
    const double t1 = seconds_since(t0);
    const auto g2 = gs::analysis::make_rev_grid(f, spec);
    const double t2 = seconds_since(t0);
    const auto r2 = gs::analysis::rev_average(f, b2, g2);
    const double t3 = seconds_since(t0);
    best = std::min(best, t3);
    tb = std::min(tb, t1);
    tg = std::min(tg, t2 - t1);
    ta = std::min(ta, t3 - t2);
  }
  std::printf("default REV map, best of 4: %.3f s (contact branches %.3f s, grid %.3f s, "
              "averaging %.3f s)\n",
              best, tb, tg, ta);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  double best1 = 1e30;
  for (int rep = 0; rep < 2; ++rep) {
    t0 = Clock::now();
    const auto r1 = gs::analysis::rev_average(f, branches, grid);
    best1 = std::min(best1, seconds_since(t0));
  }
  omp_set_num_threads(threads);
  std::printf("default REV map, averaging only, 1 thread: %.3f s\n", best1);

  // Slab map as in seed 000 §3: 2D grid in the mid-plane x-z, thickness 5 d50.
  const auto [lo, hi] = gs::particle_bounds(f);
  spec.slab = gs::analysis::Slab{0.5 * (lo + hi), Eigen::Vector3d::UnitY(),
                                 Eigen::Vector3d::UnitX(), 5 * d50};
  t0 = Clock::now();
  const auto gs_ = gs::analysis::make_rev_grid(f, spec);
  const auto slab = gs::analysis::rev_average(f, branches, gs_);
  std::printf("slab REV map (x-z, thickness 5 d50): %zu cells, %.3f s\n", gs_.count(),
              seconds_since(t0));

  // Gaussian coarse-graining on the same 3D grid of points (width d50).
  gs::analysis::RevGridSpec cg;
  cg.cell = 0.0;
  cg.step = d50;
  t0 = Clock::now();
  const auto gg = gs::analysis::make_point_grid(f, cg);
  const auto fields = gs::analysis::coarse_grain(f, branches, gg, {d50, 2650.0});
  std::printf("Gaussian coarse-graining (w = d50, 3D, %zu points): %.3f s\n", gg.count(),
              seconds_since(t0));
  // Brute force on every k-th cell, scaled.
  if (!baseline) return 0;
  const std::size_t stride = std::max<std::size_t>(1, grid.count() / 300);
  std::vector<std::size_t> cells;
  for (std::size_t c = 0; c < grid.count(); c += stride) cells.push_back(c);
  t0 = Clock::now();
  const auto brute = gs::analysis::rev_average_brute_force(f, branches, grid, {}, cells);
  const double t_brute = seconds_since(t0) * static_cast<double>(grid.count()) / cells.size();
  double dv = 0.0, ds = 0.0, smax = 0.0;
  for (const std::size_t c : cells) {
    dv = std::max(dv,
                  std::abs(fast.solid_volume[c] - brute.solid_volume[c]) / brute.solid_volume[c]);
    ds = std::max(ds, (fast.stress[c] - brute.stress[c]).norm());
    smax = std::max(smax, brute.stress[c].norm());
  }
  std::printf(
      "brute force (1 thread, %zu of %zu cells, scaled): %.1f s -> binned map is %.0fx "
      "faster; max relative difference: solid volume %.1e, stress %.1e\n",
      cells.size(), grid.count(), t_brute, t_brute / best, dv, ds / smax);

  return 0;
}
