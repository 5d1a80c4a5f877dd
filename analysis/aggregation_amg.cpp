// Smoothed-aggregation algebraic multigrid: aggregation by strong connections, a tentative
// prolongation by the constant on each aggregate, smoothed by one damped Jacobi step, Galerkin
// coarse matrices, a symmetric V-cycle with damped Jacobi sweeps (Vaněk, Mandel & Brezina 1996).
//
// The right-hand sides travel as one row-major block (a node's columns side by side), so every
// pass over a matrix serves all of them; rows go to the threads, and each row's sums are taken in
// the matrix's order whatever the number of threads or columns (the same bits).
#include "aggregation_amg.hpp"
#include "simd_choice.hpp"
#include "thread_rows.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace gs::analysis {
namespace {

using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
using Block = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Index = Eigen::Index;

// Matrix entries below this are not worth waking the threads for (the sparse products).
constexpr Index kParallelWork = 8192;

#if defined(__x86_64__) || defined(__i386__)
#define GS_AMG_X86 1
// Row sums of three or four columns with 256-bit vectors (a row of x: one load, its fourth lane
// masked off for three), four rows at a time so that their chains of additions overlap; each
// column's sum in the row's storage order, multiply then add (no fused multiply-adds: this file
// is compiled with -ffp-contract=off): the same bits as the scalar loop. out: 4 per row.
template <int C>
__attribute__((target("avx2"))) void row_sums_avx2(const int* outer, const int* inner,
                                                   const double* val, const double* xd, Index begin,
                                                   Index end, double* out) {
  static_assert(C == 3 || C == 4);
  const __m256i mask = _mm256_set_epi64x(C == 4 ? -1 : 0, -1, -1, -1);
#define GS_LOAD(j)                                          \
  (C == 4 ? _mm256_loadu_pd(xd + static_cast<Index>(j) * C) \
          : _mm256_maskload_pd(xd + static_cast<Index>(j) * C, mask))
  Index i = begin;
  for (; i + 4 <= end; i += 4) {
    const int o0 = outer[i], o1 = outer[i + 1], o2 = outer[i + 2], o3 = outer[i + 3],
              o4 = outer[i + 4];
    const int m = std::min(std::min(o1 - o0, o2 - o1), std::min(o3 - o2, o4 - o3));
    __m256d s0 = _mm256_setzero_pd(), s1 = s0, s2 = s0, s3 = s0;
    for (int e = 0; e < m; ++e) {
      s0 = _mm256_add_pd(s0, _mm256_mul_pd(_mm256_set1_pd(val[o0 + e]), GS_LOAD(inner[o0 + e])));
      s1 = _mm256_add_pd(s1, _mm256_mul_pd(_mm256_set1_pd(val[o1 + e]), GS_LOAD(inner[o1 + e])));
      s2 = _mm256_add_pd(s2, _mm256_mul_pd(_mm256_set1_pd(val[o2 + e]), GS_LOAD(inner[o2 + e])));
      s3 = _mm256_add_pd(s3, _mm256_mul_pd(_mm256_set1_pd(val[o3 + e]), GS_LOAD(inner[o3 + e])));
    }
    for (int e = o0 + m; e < o1; ++e)
      s0 = _mm256_add_pd(s0, _mm256_mul_pd(_mm256_set1_pd(val[e]), GS_LOAD(inner[e])));
    for (int e = o1 + m; e < o2; ++e)
      s1 = _mm256_add_pd(s1, _mm256_mul_pd(_mm256_set1_pd(val[e]), GS_LOAD(inner[e])));
    for (int e = o2 + m; e < o3; ++e)
      s2 = _mm256_add_pd(s2, _mm256_mul_pd(_mm256_set1_pd(val[e]), GS_LOAD(inner[e])));
    for (int e = o3 + m; e < o4; ++e)
      s3 = _mm256_add_pd(s3, _mm256_mul_pd(_mm256_set1_pd(val[e]), GS_LOAD(inner[e])));
    double* q = out + 4 * (i - begin);
    _mm256_storeu_pd(q, s0);
    _mm256_storeu_pd(q + 4, s1);
    _mm256_storeu_pd(q + 8, s2);
    _mm256_storeu_pd(q + 12, s3);
  }
  for (; i < end; ++i) {
    __m256d s0 = _mm256_setzero_pd();
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      s0 = _mm256_add_pd(s0, _mm256_mul_pd(_mm256_set1_pd(val[e]), GS_LOAD(inner[e])));
    _mm256_storeu_pd(out + 4 * (i - begin), s0);
  }
}

#undef GS_LOAD

#else
#define GS_AMG_X86 0
#endif

// f(begin, end, −1) over ranges of A's rows holding about equal numbers of entries, the ranges on
// the threads (for passes without sums over rows: any partition gives the same bits). A coarse
// level's few long rows (a restriction: 2 785 rows of ~140 entries at 5.6e4 nodes) are then
// shared out too.
template <class F>
void for_row_ranges(const RowMat& a, F&& f) {
  const Index n = a.rows(), nnz = a.nonZeros();
  const int threads = max_threads();
  if (nnz < kParallelWork || threads == 1) {
    f(Index{0}, n, Index{-1});
    return;
  }
  const int pieces = 4 * threads;
  std::vector<Index> bound(static_cast<std::size_t>(pieces) + 1, n);
  const int* outer = a.outerIndexPtr();
  bound[0] = 0;
  for (int k = 1; k < pieces; ++k) {
    const auto target = static_cast<int>(nnz * k / pieces);
    bound[static_cast<std::size_t>(k)] = std::lower_bound(outer, outer + n, target) - outer;
  }
#pragma omp parallel for schedule(static)
  for (int k = 0; k < pieces; ++k)
    f(bound[static_cast<std::size_t>(k)], bound[static_cast<std::size_t>(k) + 1], Index{-1});
}

// For every row i of A: sums s_c = Σ_e a_ie x_(j_e, c) over the row in storage order, then
// row(i, s, chunk), the rows split by `ranges` (for_row_chunks: chunk the chunk of 2 048 rows,
// for per-chunk sums; for_row_ranges: −1). C columns known at compile time (C = 0: x.cols() at
// run time).
template <int C, class Ranges, class Row>
void for_rows_fixed(const RowMat& a, const Block& x, Ranges&& ranges, Row&& row) {
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
  const double* xd = x.data();
  const Index cols = C > 0 ? C : x.cols();
#if GS_AMG_X86
  if constexpr (C == 3 || C == 4) {
    static const bool avx2 = simd_allowed(SimdCap::Avx2);
    if (avx2) {
      ranges([&](Index begin, Index end, Index chunk) {
        constexpr Index kPiece = 256;  // rows a piece: its sums stay in L1
        alignas(32) double s[4 * kPiece];
        for (Index lo = begin; lo < end; lo += kPiece) {
          const Index hi = std::min(end, lo + kPiece);
          row_sums_avx2<C>(outer, inner, val, xd, lo, hi, s);
          for (Index i = lo; i < hi; ++i) row(i, s + 4 * (i - lo), chunk);
        }
      });
      return;
    }
  }
#endif
  ranges([&](Index begin, Index end, Index chunk) {
    if constexpr (C > 0) {
      for (Index i = begin; i < end; ++i) {
        std::array<double, C> s{};  // (a fresh local per row: the sums stay in registers)
        for (int e = outer[i]; e < outer[i + 1]; ++e) {
          const double v = val[e];
          const double* xr = xd + static_cast<Index>(inner[e]) * C;
          for (int c = 0; c < C; ++c) s[static_cast<std::size_t>(c)] += v * xr[c];
        }
        row(i, s.data(), chunk);
      }
    } else {
      std::vector<double> s(static_cast<std::size_t>(cols));
      for (Index i = begin; i < end; ++i) {
        std::fill(s.begin(), s.end(), 0.0);
        for (int e = outer[i]; e < outer[i + 1]; ++e) {
          const double v = val[e];
          const double* xr = xd + static_cast<Index>(inner[e]) * cols;
          for (Index c = 0; c < cols; ++c) s[static_cast<std::size_t>(c)] += v * xr[c];
        }
        row(i, s.data(), chunk);
      }
    }
  });
}

template <class Ranges, class Row>
void for_rows_in(const RowMat& a, const Block& x, Ranges&& ranges, Row&& row) {
  switch (x.cols()) {
    case 1:
      return for_rows_fixed<1>(a, x, ranges, row);
    case 2:
      return for_rows_fixed<2>(a, x, ranges, row);
    case 3:
      return for_rows_fixed<3>(a, x, ranges, row);
    case 4:
      return for_rows_fixed<4>(a, x, ranges, row);
    default:
      return for_rows_fixed<0>(a, x, ranges, row);
  }
}

// row(i, s, −1) for every row, the rows in ranges of equal work (no per-chunk sums).
template <class Row>
void for_rows(const RowMat& a, const Block& x, Row&& row) {
  for_rows_in(
      a, x, [&](auto&& f) { for_row_ranges(a, f); }, row);
}

// row(i, s, chunk) for every row, the rows in for_row_chunks's chunks (for per-chunk sums).
template <class Row>
void for_rows_chunked(const RowMat& a, const Block& x, Row&& row) {
  for_rows_in(
      a, x, [&](auto&& f) { for_row_chunks(a.rows(), f); }, row);
}

// Per-chunk partial sums of `cols` columns, added over the chunks in order.
struct ChunkSums {
  Index cols;
  Eigen::MatrixXd part;  // cols × chunks
  ChunkSums(Index n, Index c) : cols(c), part(Eigen::MatrixXd::Zero(c, row_chunks(n))) {}
  double* at(Index chunk) { return part.col(chunk).data(); }
  Eigen::VectorXd total() const {
    Eigen::VectorXd t = Eigen::VectorXd::Zero(cols);
    for (Index k = 0; k < part.cols(); ++k) t += part.col(k);
    return t;
  }
};

// Σ_i a_ic b_ic per column.
Eigen::VectorXd column_dots(const Block& a, const Block& b) {
  const Index cols = a.cols();
  ChunkSums sums(a.rows(), cols);
  for_row_chunks(a.rows(), [&](Index begin, Index end, Index chunk) {
    double* s = sums.at(chunk);
    for (Index i = begin; i < end; ++i)
      for (Index c = 0; c < cols; ++c) s[c] += a(i, c) * b(i, c);
  });
  return sums.total();
}

// Y = A·X.
void times(const RowMat& a, const Block& x, Block& y) {
  const Index cols = x.cols();
  y.resize(a.rows(), cols);
  for_rows(a, x, [&](Index i, const double* s, Index) {
    for (Index c = 0; c < cols; ++c) y(i, c) = s[c];
  });
}

// One damped Jacobi sweep: Y = X + ω D⁻¹ (B − A·X) (Y: a block or a view of B's size).
template <class B, class Y>
void jacobi(const AmgLevel& L, const Block& x, const B& b, Y& y) {
  const Index cols = x.cols();
  y.resize(L.a.rows(), cols);
  for_rows(L.a, x, [&](Index i, const double* s, Index) {
    const double w = L.omega * L.inv_diag(i);
    for (Index c = 0; c < cols; ++c) y(i, c) = x(i, c) + w * (b(i, c) - s[c]);
  });
}

// A·B of two sparse matrices (Gustavson: row by row with a dense accumulator), rows on the
// threads in contiguous ranges; each entry summed in A's row order, then B's, for any number of
// threads. sorted = false leaves each row's columns in the order they first appear: for a
// factor that only this product reads again (its sums do not depend on that order).
RowMat multiply(const RowMat& a, const RowMat& b, bool sorted = true) {
  const Index n = a.rows(), m = b.cols();
  const int* ao = a.outerIndexPtr();
  const int* ai = a.innerIndexPtr();
  const double* av = a.valuePtr();
  const int* bo = b.outerIndexPtr();
  const int* bi = b.innerIndexPtr();
  const double* bv = b.valuePtr();
  const int threads = a.nonZeros() >= kParallelWork ? max_threads() : 1;
  return assemble_rows<RowMat>(
      n, m, threads,
      [&](Index lo, Index hi, std::vector<int>& c, std::vector<double>& v,
          std::vector<int>& outer) {
        std::vector<Index> mark(static_cast<std::size_t>(m), -1);
        std::vector<double> acc(static_cast<std::size_t>(m), 0.0);
        const auto guess = static_cast<std::size_t>(
            (ao[hi] - ao[lo]) * (b.rows() > 0 ? b.nonZeros() / b.rows() + 1 : 1));
        c.reserve(guess);
        v.reserve(guess);
        for (Index i = lo; i < hi; ++i) {
          const std::size_t start = c.size();
          std::size_t room = 0;
          for (int e = ao[i]; e < ao[i + 1]; ++e)
            room += static_cast<std::size_t>(bo[ai[e] + 1] - bo[ai[e]]);
          c.resize(start + room);
          std::size_t q = start;
          // A new column starts from −0 (−0 + x is x, to the bit) and takes the next place, an
          // old one adds: selects, not a branch to mispredict.
          for (int e = ao[i]; e < ao[i + 1]; ++e)
            for (int f = bo[ai[e]]; f < bo[ai[e] + 1]; ++f) {
              const auto j = static_cast<std::size_t>(bi[f]);
              const bool fresh = mark[j] != i;
              mark[j] = i;
              acc[j] = (fresh ? -0.0 : acc[j]) + av[e] * bv[f];
              c[q] = bi[f];
              q += fresh ? 1 : 0;
            }
          c.resize(q);
          if (sorted) std::sort(c.begin() + static_cast<std::ptrdiff_t>(start), c.end());
          for (std::size_t e = start; e < c.size(); ++e)
            v.push_back(acc[static_cast<std::size_t>(c[e])]);
          outer[static_cast<std::size_t>(i) + 1] = static_cast<int>(c.size() - start);
        }
      });
}

// Per stored entry of A: 1 when it is a strong connection, |a_ij| ≥ θ √(a_ii a_jj), i ≠ j.
std::vector<char> strong_entries(const RowMat& a, const Eigen::VectorXd& diag, double theta) {
  const Eigen::VectorXd scale = diag.cwiseSqrt().cwiseInverse();
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
  std::vector<char> strong(static_cast<std::size_t>(a.nonZeros()), 0);
#pragma omp parallel for schedule(static) if (a.nonZeros() >= kParallelWork)
  for (Index i = 0; i < a.rows(); ++i)
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      strong[static_cast<std::size_t>(e)] =
          inner[e] != i && std::abs(val[e]) * scale(i) * scale(inner[e]) >= theta;
  return strong;
}

// The filtered matrix A_F: A's strong connections and its diagonal, the weak connections of a
// row lumped into its diagonal (VMB's Ã).
RowMat filtered(const RowMat& a, const std::vector<char>& strong) {
  const Index n = a.rows();
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
  RowMat f(n, a.cols());  // (filled in place: compressed, outer index first)
  int* fo = f.outerIndexPtr();
  fo[0] = 0;
#pragma omp parallel for schedule(static) if (a.nonZeros() >= kParallelWork)
  for (Index i = 0; i < n; ++i) {
    int c = 0;
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      c += (strong[static_cast<std::size_t>(e)] || inner[e] == i) ? 1 : 0;
    fo[i + 1] = c;
  }
  for (Index i = 0; i < n; ++i) fo[i + 1] += fo[i];
  f.resizeNonZeros(fo[n]);
  int* fi = f.innerIndexPtr();
  double* fv = f.valuePtr();
#pragma omp parallel for schedule(static) if (a.nonZeros() >= kParallelWork)
  for (Index i = 0; i < n; ++i) {
    double lumped = 0.0;
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      if (inner[e] != i && !strong[static_cast<std::size_t>(e)]) lumped += val[e];
    int q = fo[i];
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      if (inner[e] == i) {
        fi[q] = inner[e];
        fv[q++] = val[e] + lumped;
      } else if (strong[static_cast<std::size_t>(e)]) {
        fi[q] = inner[e];
        fv[q++] = val[e];
      }
    }
  }
  return f;
}

// λ_max(D⁻¹A) by power iteration from a fixed start (a lower bound, close after a few steps).
double largest_eigenvalue(const RowMat& a, const Eigen::VectorXd& inv_diag) {
  const Index n = a.rows();
  Block q(n, 1), z(n, 1);
  for (Index i = 0; i < n; ++i) q(i, 0) = 1.0 + 0.37 * static_cast<double>(i % 11);
  q /= q.norm();
  double lambda = 1.0;
  for (int it = 0; it < 10; ++it) {
    for_rows(a, q, [&](Index i, const double* s, Index) { z(i, 0) = inv_diag(i) * s[0]; });
    const double norm = z.norm();
    if (!(norm > 0.0)) break;
    lambda = norm;
    q = z / norm;
  }
  return lambda;
}
// Aggregates of the strongly connected unknowns: (1) an unknown whose strong neighbours are all
// free becomes the root of an aggregate with them; (2) a free unknown joins the aggregate of
// its strongest neighbour from (1); (3) what is left forms aggregates with its free neighbours.
std::vector<int> aggregates(const RowMat& a, const std::vector<char>& is_strong, int& count) {
  const Eigen::Index n = a.rows();
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
  auto strong = [&](int e) { return is_strong[static_cast<std::size_t>(e)] != 0; };
  std::vector<int> agg(static_cast<std::size_t>(n), -1);
  count = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    bool free = true;
    for (int e = outer[i]; e < outer[i + 1] && free; ++e)
      if (strong(e) && agg[static_cast<std::size_t>(inner[e])] >= 0) free = false;
    if (!free) continue;
    agg[static_cast<std::size_t>(i)] = count;
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      if (strong(e)) agg[static_cast<std::size_t>(inner[e])] = count;
    ++count;
  }
  const std::vector<int> first = agg;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    double best = 0.0;
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      const int g = first[static_cast<std::size_t>(inner[e])];
      if (strong(e) && g >= 0 && std::abs(val[e]) > best) {
        best = std::abs(val[e]);
        agg[static_cast<std::size_t>(i)] = g;
      }
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    agg[static_cast<std::size_t>(i)] = count;
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      if (strong(e) && agg[static_cast<std::size_t>(inner[e])] < 0)
        agg[static_cast<std::size_t>(inner[e])] = count;
    ++count;
  }
  return agg;
}

// Per level: the solution, the right-hand side and a scratch block of the V-cycle.
AmgWorkspace workspace(const AmgHierarchy& h) {
  AmgWorkspace w;
  w.x.resize(h.levels.size());
  w.b.resize(h.levels.size());
  w.t.resize(h.levels.size());
  return w;
}

// One V-cycle from zero on level l: x ≈ A_l⁻¹ b, with x = *out when given (level 0 of
// amg_vcycle: the caller's right-hand side and result, no copies), else w.x[l] and b = w.b[l];
// w.t[l] is scratch.
template <class B, class Out>
void cycle(const AmgHierarchy& h, std::size_t l, AmgWorkspace& w, const B& b, Out* out) {
  Block& x = w.x[l];
  const Index cols = b.cols();
  x.resize(b.rows(), cols);
  if (l + 1 == h.levels.size()) {  // column by column: each column's bits whatever the block
    for (Index c = 0; c < cols; ++c) {
      const Eigen::VectorXd xc = h.coarsest.solve(Eigen::VectorXd(b.col(c)));
      if (out)
        out->col(c) = xc;
      else
        x.col(c) = xc;
    }
    return;
  }
  const AmgLevel& L = h.levels[l];
  Block& t = w.t[l];
  for_row_chunks(b.rows(), [&](Index begin, Index end, Index) {
    for (Index i = begin; i < end; ++i) {
      const double d = L.omega * L.inv_diag(i);
      for (Index c = 0; c < cols; ++c) x(i, c) = d * b(i, c);
    }
  });
  for (int s = 1; s < h.sweeps; ++s) {
    jacobi(L, x, b, t);
    x.swap(t);
  }
  t.resize(b.rows(), cols);  // the residual, restricted
  for_rows(L.a, x, [&](Index i, const double* s, Index) {
    for (Index c = 0; c < cols; ++c) t(i, c) = b(i, c) - s[c];
  });
  times(L.r, t, w.b[l + 1]);
  cycle(h, l + 1, w, w.b[l + 1], static_cast<Block*>(nullptr));
  for_rows(L.p, w.x[l + 1], [&](Index i, const double* s, Index) {
    for (Index c = 0; c < cols; ++c) x(i, c) += s[c];
  });
  for (int s = 0; s < h.sweeps; ++s) {
    if (out && s + 1 == h.sweeps) {
      jacobi(L, x, b, *out);
    } else {
      jacobi(L, x, b, t);
      x.swap(t);
    }
  }
}

}  // namespace

AmgHierarchy build_amg(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a0,
                       const AmgOptions& o) {
  RowMat a = a0;
  return build_amg(std::move(a), o);
}

AmgHierarchy build_amg(RowMat&& a, const AmgOptions& o) {
  if (a.rows() != a.cols())
    throw std::invalid_argument("AMG: matrix not square (" + std::to_string(a.rows()) + "x" +
                                std::to_string(a.cols()) + ")");
  AmgHierarchy h;
  h.sweeps = std::max(1, o.sweeps);
  // (Eigen 3.4's sparse matrices have no move operations: std::move copies them, swap does not;
  // the levels are filled in place.)
  h.levels.reserve(static_cast<std::size_t>(std::max(1, o.max_levels)));
  a.makeCompressed();
  while (true) {
    AmgLevel& L = h.levels.emplace_back();
    L.a.swap(a);
    const Eigen::VectorXd diag = L.a.diagonal();
    if (diag.size() > 0 && !(diag.minCoeff() > 0.0))
      throw std::invalid_argument("AMG: non-positive diagonal entry (" +
                                  std::to_string(diag.minCoeff()) + ")");
    L.inv_diag = diag.cwiseInverse();
    int nc = 0;
    std::vector<int> agg;
    std::vector<char> strong;
    // (L is already in h.levels: at most max_levels levels)
    if (L.a.rows() > o.coarsest && static_cast<int>(h.levels.size()) < o.max_levels) {
      strong = strong_entries(L.a, diag, o.strength);
      agg = aggregates(L.a, strong, nc);
    }
    if (agg.empty() || nc >= L.a.rows()) break;  // (the coarsest level: small, or no coarsening)
    // P = (I − ω_F D_F⁻¹A_F) P_t, P_t the constant on each aggregate, A_F the filtered matrix
    // (which keeps P as local as the aggregates); the next level RᵀAP, R = Pᵀ.
    L.omega = 4.0 / (3.0 * largest_eigenvalue(L.a, L.inv_diag));
    RowMat smoother = filtered(L.a, strong);
    {
      const Eigen::VectorXd inv_f = smoother.diagonal().cwiseInverse();
      const double omega_f = 4.0 / (3.0 * largest_eigenvalue(smoother, inv_f));
#pragma omp parallel for schedule(static) if (smoother.nonZeros() >= kParallelWork)
      for (Index i = 0; i < smoother.outerSize(); ++i)  // I − ω_F D_F⁻¹A_F
        for (RowMat::InnerIterator it(smoother, i); it; ++it)
          it.valueRef() = (it.col() == i ? 1.0 : 0.0) - omega_f * inv_f(i) * it.value();
    }
    RowMat pt(L.a.rows(), nc);  // (one 1 per row, in its aggregate's column)
    pt.resizeNonZeros(L.a.rows());
    for (Index i = 0; i < L.a.rows(); ++i) {
      pt.outerIndexPtr()[i] = static_cast<int>(i);
      pt.innerIndexPtr()[i] = agg[static_cast<std::size_t>(i)];
      pt.valuePtr()[i] = 1.0;
    }
    pt.outerIndexPtr()[L.a.rows()] = static_cast<int>(L.a.rows());
    {
      RowMat p = multiply(smoother, pt);
      L.p.swap(p);
    }
    L.p.prune(0.0);
    L.r = L.p.transpose();
    {
      RowMat rap = multiply(L.r, multiply(L.a, L.p, false));
      a = 0.5 * (rap + RowMat(rap.transpose()));  // (symmetric to the last bit: an SPD V-cycle)
    }
  }
  h.coarsest.compute(Eigen::MatrixXd(h.levels.back().a));
  if (h.coarsest.info() != Eigen::Success)
    throw std::invalid_argument("AMG: coarsest matrix not positive definite");
  return h;
}

Eigen::MatrixXd amg_vcycle(const AmgHierarchy& h, const Eigen::MatrixXd& b) {
  AmgWorkspace w;
  AmgBlock x(b.rows(), b.cols());
  amg_vcycle(h, AmgBlock(b), x, w);
  return Eigen::MatrixXd(x);
}

void amg_vcycle(const AmgHierarchy& h, const Eigen::Ref<const AmgBlock>& b, Eigen::Ref<AmgBlock> x,
                AmgWorkspace& w) {
  if (h.levels.empty()) throw std::invalid_argument("AMG: empty hierarchy");
  if (x.rows() != b.rows() || x.cols() != b.cols())
    throw std::invalid_argument("AMG: the V-cycle's result is not the right-hand side's size (" +
                                std::to_string(x.rows()) + "x" + std::to_string(x.cols()) + ")");
  if (w.x.size() != h.levels.size()) w = workspace(h);
  cycle(h, 0, w, b, &x);
}

Eigen::MatrixXd amg_pcg(const AmgHierarchy& h, const Eigen::MatrixXd& b0, double tolerance,
                        int max_iterations, int& iterations, bool& converged,
                        std::vector<int>* column_iterations, const std::function<void()>& poll) {
  if (h.levels.empty()) throw std::invalid_argument("AMG: empty hierarchy");
  const RowMat& a = h.levels.front().a;
  const Index n = b0.rows(), cols = b0.cols();
  AmgWorkspace w = workspace(h);
  Block& r = w.b[0];        // the residual is the V-cycle's right-hand side,
  const Block& z = w.x[0];  // and its output the preconditioned residual
  r = b0;
  Block x = Block::Zero(n, cols), p, ap(n, cols);
  std::vector<char> done(static_cast<std::size_t>(cols), 0);
  const Eigen::VectorXd bnorm = column_dots(r, r).cwiseSqrt();
  for (Index c = 0; c < cols; ++c) done[static_cast<std::size_t>(c)] = bnorm(c) == 0.0;
  iterations = 0;
  converged = true;
  std::vector<int> its(static_cast<std::size_t>(cols), 0);
  auto finish = [&] {
    if (column_iterations) *column_iterations = its;
    return Eigen::MatrixXd(x);
  };
  auto all_done = [&] {
    return std::all_of(done.begin(), done.end(), [](char d) { return d != 0; });
  };
  if (all_done()) return finish();
  cycle(h, 0, w, r, static_cast<Block*>(nullptr));
  p = z;
  Eigen::VectorXd rz = column_dots(r, z);
  Eigen::VectorXd alpha(cols), beta(cols);
  for (int it = 1; it <= max_iterations; ++it) {
    iterations = it;
    ChunkSums pap(n, cols);  // A·p and pᵀA·p in one pass
    for_rows_chunked(a, p, [&](Index i, const double* s, Index chunk) {
      double* q = pap.at(chunk);
      for (Index c = 0; c < cols; ++c) {
        ap(i, c) = s[c];
        q[c] += p(i, c) * s[c];
      }
    });
    const Eigen::VectorXd pap_total = pap.total();
    for (Index c = 0; c < cols; ++c) {
      alpha(c) = 0.0;
      if (done[static_cast<std::size_t>(c)]) continue;
      its[static_cast<std::size_t>(c)] = it;
      if (!(pap_total(c) > 0.0) || !(rz(c) > 0.0)) {  // (breakdown: no further progress)
        done[static_cast<std::size_t>(c)] = 1;
        converged = false;
        continue;
      }
      alpha(c) = rz(c) / pap_total(c);
    }
    ChunkSums rr(n, cols);  // the updates and ‖r‖² in one pass
    for_row_chunks(n, [&](Index begin, Index end, Index chunk) {
      double* q = rr.at(chunk);
      for (Index i = begin; i < end; ++i)
        for (Index c = 0; c < cols; ++c) {
          x(i, c) += alpha(c) * p(i, c);
          r(i, c) -= alpha(c) * ap(i, c);
          q[c] += r(i, c) * r(i, c);
        }
    });
    const Eigen::VectorXd rnorm = rr.total().cwiseSqrt();
    for (Index c = 0; c < cols; ++c)
      if (!done[static_cast<std::size_t>(c)] && rnorm(c) <= tolerance * bnorm(c))
        done[static_cast<std::size_t>(c)] = 1;
    if (all_done()) return finish();
    if (poll && it % 8 == 0) poll();
    cycle(h, 0, w, r, static_cast<Block*>(nullptr));
    const Eigen::VectorXd rz_new = column_dots(r, z);
    for (Index c = 0; c < cols; ++c) {
      beta(c) = 0.0;
      if (done[static_cast<std::size_t>(c)]) continue;
      beta(c) = rz_new(c) / rz(c);
      rz(c) = rz_new(c);
    }
    for_row_chunks(n, [&](Index begin, Index end, Index) {
      for (Index i = begin; i < end; ++i)
        for (Index c = 0; c < cols; ++c) p(i, c) = z(i, c) + beta(c) * p(i, c);
    });
  }
  converged = false;
  return finish();
}

}  // namespace gs::analysis
