// A = CᵀMC of eq 18 (seed 000) applied matrix-free; see curl_curl_operator.hpp.
#include "curl_curl_operator.hpp"

#include "simd_choice.hpp"
#include "thread_rows.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define GS_CURL_X86 1
#else
#define GS_CURL_X86 0
#endif

#ifdef _OPENMP
#include <omp.h>
#endif

namespace gs::analysis {

using Block = CurlCurlOperator::Block;
constexpr int kLanes = CurlCurlOperator::kLanes;

CurlCurlOperator::CurlCurlOperator(std::size_t tetrahedra)
    : blocks((tetrahedra + kLanes - 1) / kLanes), size(tetrahedra) {}

void CurlCurlOperator::set(std::size_t e, const std::array<int, 4>& node, double measure,
                           const std::array<double, 9>& gradient) {
  if (e >= size)
    throw std::out_of_range("curl-curl operator: tetrahedron " + std::to_string(e) + " of " +
                            std::to_string(size));
  Block& b = blocks[e / kLanes];
  const auto lane = static_cast<int>(e % kLanes);
  for (std::size_t q = 0; q < 9; ++q) b.gradient[q][lane] = gradient[q];
  b.measure[lane] = measure;
  for (std::size_t a = 0; a < 4; ++a) {
    const auto bit = static_cast<std::uint8_t>(1u << lane);
    b.offset[a][lane] = node[a] < 0 ? 0 : 3 * node[a];
    b.live[a] = static_cast<std::uint8_t>(node[a] < 0 ? (b.live[a] & ~bit) : (b.live[a] | bit));
  }
}

namespace {

// The lanes [l0, l1) of block bi that lie in the tetrahedra [lo, hi).
void lane_bounds(std::size_t bi, std::size_t lo, std::size_t hi, int& l0, int& l1) {
  const std::size_t first = bi * kLanes;
  l0 = static_cast<int>(std::max(lo, first) - first);
  l1 = static_cast<int>(std::min(hi, first + kLanes) - first);
}

bool live(const Block& b, std::size_t a, int lane) {
  return ((b.live[a] >> lane) & 1u) != 0;
}

// Lanes [l0, l1) of block b: c = |T| Σ_{a≥1} ∇φ_a × (v_a − v_0) (= |T| Σ_a ∇φ_a × v_a, since
// ∇φ_0 = −Σ_{a≥1} ∇φ_a); row a gets c × ∇φ_a, row 0 minus their sum. The reference for the
// vector variant: each of its lanes performs exactly these operations in this order.
void block_generic(const Block& b, int l0, int l1, const double* vd, double* od) {
  static constexpr double zero[3] = {0.0, 0.0, 0.0};
  for (int l = l0; l < l1; ++l) {
    const double* v0 = live(b, 0, l) ? vd + b.offset[0][l] : zero;
    double c[3] = {0.0, 0.0, 0.0};
    for (std::size_t a = 1; a < 4; ++a) {
      const double* va = live(b, a, l) ? vd + b.offset[a][l] : zero;
      const double g0 = b.gradient[3 * (a - 1)][l], g1 = b.gradient[3 * (a - 1) + 1][l],
                   g2 = b.gradient[3 * (a - 1) + 2][l];
      const double d0 = va[0] - v0[0], d1 = va[1] - v0[1], d2 = va[2] - v0[2];
      c[0] += g1 * d2 - g2 * d1;
      c[1] += g2 * d0 - g0 * d2;
      c[2] += g0 * d1 - g1 * d0;
    }
    const double w = b.measure[l];
    c[0] *= w;
    c[1] *= w;
    c[2] *= w;
    double s[3] = {0.0, 0.0, 0.0};
    for (std::size_t a = 1; a < 4; ++a) {
      const double g0 = b.gradient[3 * (a - 1)][l], g1 = b.gradient[3 * (a - 1) + 1][l],
                   g2 = b.gradient[3 * (a - 1) + 2][l];
      const double e0 = c[1] * g2 - c[2] * g1;
      const double e1 = c[2] * g0 - c[0] * g2;
      const double e2 = c[0] * g1 - c[1] * g0;
      s[0] += e0;
      s[1] += e1;
      s[2] += e2;
      if (live(b, a, l)) {
        double* o = od + b.offset[a][l];
        o[0] += e0;
        o[1] += e1;
        o[2] += e2;
      }
    }
    if (live(b, 0, l)) {
      double* o = od + b.offset[0][l];
      o[0] -= s[0];
      o[1] -= s[1];
      o[2] -= s[2];
    }
  }
}

void range_generic(const CurlCurlOperator& op, std::size_t lo, std::size_t hi, const double* vd,
                   double* od) {
  if (lo >= hi) return;
  for (std::size_t bi = lo / kLanes; bi * kLanes < hi; ++bi) {
    int l0 = 0, l1 = 0;
    lane_bounds(bi, lo, hi, l0, l1);
    block_generic(op.blocks[bi], l0, l1, vd, od);
  }
}

#if GS_CURL_X86
// Eight tetrahedra at once: the vertex values gathered (zero for a Dirichlet node), c and the
// four row contributions computed lane-wise as block_generic does (no fused multiply-adds: this
// file is compiled with -ffp-contract=off), then added to the rows lane by lane in the scalar
// order.
__attribute__((target("avx512f"))) void range_avx512(const CurlCurlOperator& op, std::size_t lo,
                                                     std::size_t hi, const double* vd, double* od) {
  if (lo >= hi) return;
  alignas(64) double e[12][kLanes];  // rows 1..3 (x, y, z each), then s = their sum
  const __m512d zero = _mm512_setzero_pd();
  for (std::size_t bi = lo / kLanes; bi * kLanes < hi; ++bi) {
    const Block& b = op.blocks[bi];
    int l0 = 0, l1 = 0;
    lane_bounds(bi, lo, hi, l0, l1);
    __m512d v0[3], c[3] = {zero, zero, zero};
    {
      const __m256i idx = _mm256_load_si256(reinterpret_cast<const __m256i*>(b.offset[0]));
      for (int q = 0; q < 3; ++q) v0[q] = _mm512_mask_i32gather_pd(zero, b.live[0], idx, vd + q, 8);
    }
    __m512d g[9];
    for (int q = 0; q < 9; ++q) g[q] = _mm512_load_pd(b.gradient[q]);
    for (int a = 1; a < 4; ++a) {
      const __m256i idx = _mm256_load_si256(reinterpret_cast<const __m256i*>(b.offset[a]));
      const __m512d* ga = g + 3 * (a - 1);
      const __m512d d0 =
          _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, b.live[a], idx, vd, 8), v0[0]);
      const __m512d d1 =
          _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, b.live[a], idx, vd + 1, 8), v0[1]);
      const __m512d d2 =
          _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, b.live[a], idx, vd + 2, 8), v0[2]);
      c[0] = _mm512_add_pd(c[0], _mm512_sub_pd(_mm512_mul_pd(ga[1], d2), _mm512_mul_pd(ga[2], d1)));
      c[1] = _mm512_add_pd(c[1], _mm512_sub_pd(_mm512_mul_pd(ga[2], d0), _mm512_mul_pd(ga[0], d2)));
      c[2] = _mm512_add_pd(c[2], _mm512_sub_pd(_mm512_mul_pd(ga[0], d1), _mm512_mul_pd(ga[1], d0)));
    }
    const __m512d w = _mm512_load_pd(b.measure);
    for (int q = 0; q < 3; ++q) c[q] = _mm512_mul_pd(c[q], w);
    __m512d s[3] = {zero, zero, zero};
    for (int a = 1; a < 4; ++a) {
      const __m512d* ga = g + 3 * (a - 1);
      const __m512d e0 = _mm512_sub_pd(_mm512_mul_pd(c[1], ga[2]), _mm512_mul_pd(c[2], ga[1]));
      const __m512d e1 = _mm512_sub_pd(_mm512_mul_pd(c[2], ga[0]), _mm512_mul_pd(c[0], ga[2]));
      const __m512d e2 = _mm512_sub_pd(_mm512_mul_pd(c[0], ga[1]), _mm512_mul_pd(c[1], ga[0]));
      s[0] = _mm512_add_pd(s[0], e0);
      s[1] = _mm512_add_pd(s[1], e1);
      s[2] = _mm512_add_pd(s[2], e2);
      _mm512_store_pd(e[3 * (a - 1)], e0);
      _mm512_store_pd(e[3 * (a - 1) + 1], e1);
      _mm512_store_pd(e[3 * (a - 1) + 2], e2);
    }
    for (int q = 0; q < 3; ++q) _mm512_store_pd(e[9 + q], s[q]);
    for (int l = l0; l < l1; ++l) {
      for (std::size_t a = 1; a < 4; ++a) {
        if (!live(b, a, l)) continue;
        double* o = od + b.offset[a][l];
        o[0] += e[3 * (a - 1)][l];
        o[1] += e[3 * (a - 1) + 1][l];
        o[2] += e[3 * (a - 1) + 2][l];
      }
      if (live(b, 0, l)) {
        double* o = od + b.offset[0][l];
        o[0] -= e[9][l];
        o[1] -= e[10][l];
        o[2] -= e[11][l];
      }
    }
  }
}
#endif

}  // namespace

bool curl_curl_avx512_supported() {
#if GS_CURL_X86
  static const bool ok = __builtin_cpu_supports("avx512f");
  return ok;
#else
  return false;
#endif
}

void apply_curl_curl(const CurlCurlOperator& op, const Rows3& v, Rows3& result,
                     std::vector<Rows3>& part, CurlCurlKernel kernel) {
  if (kernel == CurlCurlKernel::Avx512 && !curl_curl_avx512_supported())
    throw std::invalid_argument("the AVX-512 curl-curl kernel needs a CPU with AVX-512F");
  const bool vector = kernel == CurlCurlKernel::Avx512 ||
                      (kernel == CurlCurlKernel::Best && simd_allowed(SimdCap::Avx512));
  const Eigen::Index n = v.rows();
  const std::size_t ns = op.size;
  const int threads = max_threads();
  part.resize(static_cast<std::size_t>(threads));
#pragma omp parallel num_threads(threads)
  {
    const int t = thread_number();
    Rows3& out = t == 0 ? result : part[static_cast<std::size_t>(t)];
    out.setZero(n, 3);
    const auto [first, last] = thread_share(static_cast<std::ptrdiff_t>(ns), t, threads);
    const auto lo = static_cast<std::size_t>(first), hi = static_cast<std::size_t>(last);
#if GS_CURL_X86
    if (vector)
      range_avx512(op, lo, hi, v.data(), out.data());
    else
#endif
      range_generic(op, lo, hi, v.data(), out.data());
  }
  (void)vector;
  for (std::size_t t = 1; t < part.size(); ++t) result += part[t];
}

}  // namespace gs::analysis
