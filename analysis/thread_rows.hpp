// Rows on the threads. Sparse matrices assembled row by row: each thread builds a contiguous range
// of rows into its own column and value lists, joined into one compressed matrix. Sums over rows
// in fixed chunks: taken per chunk, then over the chunks in order, they have the same bits for
// any number of threads.
#pragma once

#include <Eigen/Sparse>
#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace gs::analysis {

/// The threads a parallel region gets (OMP_NUM_THREADS, a scene's `threads`; 1 without OpenMP).
inline int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

/// This thread's number in a parallel region (0 outside one, or without OpenMP).
inline int thread_number() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

/// Thread t's contiguous share [first, second) of n items split among `threads`.
inline std::pair<std::ptrdiff_t, std::ptrdiff_t> thread_share(std::ptrdiff_t n, int t,
                                                              int threads) {
  return {n * t / threads, n * (t + 1) / threads};
}

/// Rows go to the threads in chunks of this many.
inline constexpr Eigen::Index kRowChunk = 2048;
/// Below this many rows the threads are not woken.
inline constexpr Eigen::Index kParallelRows = 8192;

inline Eigen::Index row_chunks(Eigen::Index n) {
  return (n + kRowChunk - 1) / kRowChunk;
}

/// f(begin, end, chunk) for every chunk of the rows [0, n), the chunks on the threads.
template <class F>
void for_row_chunks(Eigen::Index n, F&& f) {
  const Eigen::Index nc = row_chunks(n);
#pragma omp parallel for schedule(static) if (n >= kParallelRows)
  for (Eigen::Index k = 0; k < nc; ++k) f(k * kRowChunk, std::min(n, (k + 1) * kRowChunk), k);
}

/// `outer[i + 1]` holds the number of entries of row i (outer[0] = 0); `inner[t]` and `value[t]`
/// the entries of thread t's rows, in row order, threads in row order. Returns the compressed
/// matrix with these rows (for a column-major `Sparse`, of a symmetric matrix: rows = columns).
template <class Sparse>
Sparse join_thread_rows(Eigen::Index rows, Eigen::Index cols, std::vector<int>& outer,
                        const std::vector<std::vector<int>>& inner,
                        const std::vector<std::vector<double>>& value) {
  for (std::size_t i = 0; i + 1 < outer.size(); ++i) outer[i + 1] += outer[i];
  // Written straight into the matrix's arrays (a join and a copy of a map would touch the
  // entries twice more: at 5.6e4 nodes, 10 MB of fresh pages each).
  Sparse m(rows, cols);
  m.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), m.outerIndexPtr());
  std::vector<std::size_t> offset(inner.size() + 1, 0);
  for (std::size_t t = 0; t < inner.size(); ++t) offset[t + 1] = offset[t] + inner[t].size();
  const auto threads = static_cast<std::ptrdiff_t>(inner.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t tt = 0; tt < threads; ++tt) {
    const auto t = static_cast<std::size_t>(tt);
    std::copy(inner[t].begin(), inner[t].end(), m.innerIndexPtr() + offset[t]);
    std::copy(value[t].begin(), value[t].end(), m.valuePtr() + offset[t]);
  }
  return m;
}

/// Rows [0, rows) built on `threads` threads in contiguous ranges: build(lo, hi, inner, value,
/// outer) appends the entries of rows lo..hi−1 (columns ascending) to that thread's lists and
/// sets outer[i + 1] to row i's count. Returns the joined compressed matrix.
template <class Sparse, class Build>
Sparse assemble_rows(Eigen::Index rows, Eigen::Index cols, int threads, Build&& build) {
  std::vector<std::vector<int>> inner(static_cast<std::size_t>(threads));
  std::vector<std::vector<double>> value(static_cast<std::size_t>(threads));
  std::vector<int> outer(static_cast<std::size_t>(rows) + 1, 0);
#pragma omp parallel num_threads(threads)
  {
    const int t = thread_number();
    const auto [lo, hi] = thread_share(rows, t, threads);
    build(lo, hi, inner[static_cast<std::size_t>(t)], value[static_cast<std::size_t>(t)], outer);
  }
  return join_thread_rows<Sparse>(rows, cols, outer, inner, value);
}

}  // namespace gs::analysis
