// Speed of the Delaunay tetrahedron strain (issue 6: 56 000 particles in < 1 s on 2 cores,
// Delaunay included) and of the 2D void cells. Prints the time split of one full run
// (Delaunay, gradients, averaging), then Google Benchmark timings.
//   cmake -DGRANOSCOPE_BENCH=ON ... && OMP_NUM_THREADS=2 build/bin/bench_strain
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <vector>

#include "kuhn_void_cells.hpp"
#include "tet_strain.hpp"

namespace {

// Jittered cubic lattice (a dense-packing-like point set: no large voids), 1 mm spacing.
std::vector<Eigen::Vector3d> packing(std::size_t n, unsigned seed) {
  const auto side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(n))));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.3e-3, 0.3e-3);
  std::vector<Eigen::Vector3d> x;
  for (int k = 0; k < side && x.size() < n; ++k)
    for (int j = 0; j < side && x.size() < n; ++j)
      for (int i = 0; i < side && x.size() < n; ++i)
        x.emplace_back(1e-3 * i + u(rng), 1e-3 * j + u(rng), 1e-3 * k + u(rng));
  return x;
}

std::vector<Eigen::Vector3d> motion(const std::vector<Eigen::Vector3d>& x, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1e-6);
  Eigen::Matrix3d h;
  h << 0.001, 0.002, 0, 0, -0.002, 0, 0, 0, 0.0005;
  std::vector<Eigen::Vector3d> u(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    u[i] = h * x[i] + Eigen::Vector3d(g(rng), g(rng), g(rng));
  return u;
}

void BM_TetStrain56k(benchmark::State& state) {
  const auto x = packing(56000, 1);
  const auto u = motion(x, 2);
  double d = 0, gr = 0, av = 0;
  for (auto _ : state) {
    const auto r = gs::analysis::tet_strain(x, u);
    benchmark::DoNotOptimize(r.mean_gradient);
    d += r.seconds_delaunay;
    gr += r.seconds_gradients;
    av += r.seconds_averaging;
  }
  const auto it = static_cast<double>(state.iterations());
  state.counters["delaunay_s"] = d / it;
  state.counters["gradients_s"] = gr / it;
  state.counters["averaging_s"] = av / it;
}
BENCHMARK(BM_TetStrain56k)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_VoidCells8k(benchmark::State& state) {
  // 8000 particles in a periodic square (the size of seed 000's 2D slice), contacts = short
  // Delaunay edges of the 3 x 3 replicated points.
  const std::size_t n = 8000;
  const double side = 0.09;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ud(0.0, side);
  std::vector<Eigen::Vector2d> x(n), all;
  std::vector<std::int32_t> owner;
  for (auto& p : x) p = Eigen::Vector2d(ud(rng), ud(rng));
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i)
      for (std::size_t k = 0; k < n; ++k) {
        all.push_back(x[k] + side * Eigen::Vector2d(i, j));
        owner.push_back(static_cast<std::int32_t>(k));
      }
  std::set<std::pair<std::int32_t, std::int32_t>> pairs;
  const double cut = 1.4 * side / std::sqrt(static_cast<double>(n));
  for (const auto& t : gs::analysis::delaunay_triangles(all))
    for (std::size_t a = 0; a < 3; ++a) {
      const auto p = static_cast<std::size_t>(t[a]), q = static_cast<std::size_t>(t[(a + 1) % 3]);
      if ((all[p] - all[q]).norm() < cut)
        pairs.emplace(std::min(owner[p], owner[q]), std::max(owner[p], owner[q]));
    }
  const auto g = gs::analysis::make_particle_graph(x, {pairs.begin(), pairs.end()}, true,
                                                   side * Eigen::Matrix2d::Identity());
  std::vector<Eigen::Vector2d> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = Eigen::Vector2d(0.01 * x[i].y(), 0.0);
  const Eigen::Matrix2d rate = Eigen::Matrix2d{{0, 0.01 * side}, {0, 0}};
  for (auto _ : state) {
    const auto c = gs::analysis::find_void_cells(g);
    const auto d = gs::analysis::void_cell_deformation(g, c, v, 1e-3, rate);
    benchmark::DoNotOptimize(d.mean);
  }
}
BENCHMARK(BM_VoidCells8k)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  {
    const auto x = packing(56000, 1);
    const auto u = motion(x, 2);
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = gs::analysis::tet_strain(x, u);
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::size_t slivers = 0;
    for (auto s : r.sliver) slivers += s;
    std::printf(
        "tet strain, %zu particles, %zu tets (%zu slivers): total %.3f s = Delaunay %.3f s + "
        "gradients %.3f s + averaging %.3f s\n",
        x.size(), r.simplices.size(), slivers, total, r.seconds_delaunay, r.seconds_gradients,
        r.seconds_averaging);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
