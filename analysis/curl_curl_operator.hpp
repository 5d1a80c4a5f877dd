// The matrix of eq 18 in 3D (seed 000), A = CᵀMC, applied matrix-free: A·v = Σ_k over the
// tetrahedra of c_k × ∇φ_i with c_k = |T_k| Σ_a ∇φ_a × v_a (row i of the product; C the P1
// curl, M = diag |T_k|). Laid out for its products: tetrahedra in blocks of eight, each block's
// gradients, measures and node offsets lane by lane (structure of arrays), so that the
// AVX-512 variant computes eight tetrahedra at once; every variant gives the same bits (the
// operations of each lane in the order of the scalar code, no fused multiply-adds).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace gs::analysis {

/// Vectors over the unknowns with a node's three components side by side.
using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

struct CurlCurlOperator {
  static constexpr int kLanes = 8;
  struct alignas(64) Block {
    double gradient[9][kLanes];      // ∇φ_1, ∇φ_2, ∇φ_3 (x, y, z each); ∇φ_0 = −Σ
    double measure[kLanes];          // |T_k| (0 in the padding lanes)
    std::int32_t offset[4][kLanes];  // 3 × unknown of vertex a (0 for a Dirichlet node)
    std::uint8_t live[4];            // bit l: vertex a of lane l is an unknown
  };
  std::vector<Block> blocks;
  std::size_t size = 0;  // tetrahedra (the last block padded with zeros)

  CurlCurlOperator() = default;
  /// Room for `tetrahedra`, all zero (contributing nothing) until set.
  explicit CurlCurlOperator(std::size_t tetrahedra);
  /// Sets tetrahedron e: its four unknowns (−1: a Dirichlet node, v = 0 there), |T_k| and
  /// ∇φ_1..3 (9 values). The products sum the tetrahedra in the order of e. Tetrahedra of
  /// different blocks (e / kLanes) may be set from different threads.
  void set(std::size_t e, const std::array<int, 4>& node, double measure,
           const std::array<double, 9>& gradient);
};

enum class CurlCurlKernel { Best, Generic, Avx512 };

/// Whether this CPU runs the AVX-512 variant.
bool curl_curl_avx512_supported();

/// result = A·v (v: the unknowns' rows). Each thread sums a fixed range of tetrahedra into its
/// own buffer (`part`, kept by the caller between products: fresh buffers cost more in page
/// faults than the product at 10⁶ nodes), added in thread order: the result depends on the
/// number of threads, not on the scheduling or the kernel. `Best`: AVX-512 where the CPU has it
/// (the environment variable GS_SIMD=generic or avx2 forces the plain code, as for the solver's
/// kernels); asking for Avx512 on a CPU without it throws std::invalid_argument.
void apply_curl_curl(const CurlCurlOperator& op, const Rows3& v, Rows3& result,
                     std::vector<Rows3>& part, CurlCurlKernel kernel = CurlCurlKernel::Best);

}  // namespace gs::analysis
