// The matrix-free product with eq 18's matrix A = CᵀMC (analysis/curl_curl_operator.hpp)
// against the formula summed tetrahedron by tetrahedron, every kernel the same bits, symmetry
// and positivity, Dirichlet nodes, a partly filled last block, bad input.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <stdexcept>

#include "curl_curl_operator.hpp"

namespace gs::analysis {
namespace {

struct Tet {
  std::array<int, 4> node;
  double measure;
  std::array<double, 9> gradient;  // ∇φ_1..3
};

// 29 tetrahedra over 12 unknowns (three blocks, the last with 5 of its 8 lanes), random
// gradients and measures, every vertex slot sometimes a Dirichlet node (−1), and one
// tetrahedron entirely on Dirichlet nodes.
std::vector<Tet> random_tets(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> node(-3, 11);  // −3..−1: a Dirichlet node
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Tet> t(29);
  for (auto& k : t) {
    for (auto& j : k.node) j = std::max(-1, node(rng));
    k.measure = 0.1 + std::abs(u(rng));
    for (auto& g : k.gradient) g = 10.0 * u(rng);
  }
  t[7].node = {-1, -1, -1, -1};
  return t;
}

CurlCurlOperator build(const std::vector<Tet>& t) {
  CurlCurlOperator op(t.size());
  for (std::size_t e = 0; e < t.size(); ++e) op.set(e, t[e].node, t[e].measure, t[e].gradient);
  return op;
}

// Σ_k |T_k| (∇φ_i × ·)ᵀ(Σ_a ∇φ_a × v_a) for every row i, straight from the definition.
Rows3 reference(const std::vector<Tet>& t, const Rows3& v) {
  Rows3 out = Rows3::Zero(v.rows(), 3);
  for (const auto& k : t) {
    std::array<Eigen::Vector3d, 4> g;
    for (int a = 1; a < 4; ++a)
      g[static_cast<std::size_t>(a)] = Eigen::Vector3d(
          k.gradient[3 * (a - 1)], k.gradient[3 * (a - 1) + 1], k.gradient[3 * (a - 1) + 2]);
    g[0] = -(g[1] + g[2] + g[3]);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (std::size_t a = 0; a < 4; ++a)
      if (k.node[a] >= 0) c += g[a].cross(Eigen::Vector3d(v.row(k.node[a]).transpose()));
    c *= k.measure;
    for (std::size_t a = 0; a < 4; ++a)
      if (k.node[a] >= 0) out.row(k.node[a]) += c.cross(g[a]).transpose();
  }
  return out;
}

TEST(CurlCurlOperator, ProductIsTheFormulaAndEveryKernelTheSameBits) {
  const auto t = random_tets(3);
  const CurlCurlOperator op = build(t);
  EXPECT_EQ(op.size, 29u);
  EXPECT_EQ(op.blocks.size(), 4u);
  std::mt19937 rng(5);
  std::normal_distribution<double> g;
  Rows3 v(12, 3), w(12, 3);
  for (Eigen::Index i = 0; i < v.size(); ++i) v.data()[i] = g(rng), w.data()[i] = g(rng);
  std::vector<Rows3> part;
  Rows3 av, aw;
  apply_curl_curl(op, v, av, part, CurlCurlKernel::Generic);
  apply_curl_curl(op, w, aw, part, CurlCurlKernel::Generic);
  const Rows3 ref = reference(t, v);
  EXPECT_LT((av - ref).norm(), 1e-13 * ref.norm());
  // Symmetric and positive semi-definite (a sum of |T| |c|² terms).
  const double wav = (w.array() * av.array()).sum(), vaw = (v.array() * aw.array()).sum();
  EXPECT_NEAR(wav, vaw, 1e-12 * std::abs(wav) + 1e-12);
  EXPECT_GT((v.array() * av.array()).sum(), 0.0);
  Rows3 best;
  apply_curl_curl(op, v, best, part, CurlCurlKernel::Best);
  EXPECT_EQ(best, av);
  if (curl_curl_avx512_supported()) {
    Rows3 vec;
    apply_curl_curl(op, v, vec, part, CurlCurlKernel::Avx512);
    EXPECT_EQ(vec, av);  // lane for lane the generic code's operations: the same bits
  } else {
    EXPECT_THROW(apply_curl_curl(op, v, best, part, CurlCurlKernel::Avx512), std::invalid_argument);
    GTEST_SKIP() << "no AVX-512 on this CPU: the vector kernel was not compared";
  }
}

TEST(CurlCurlOperator, GradientFieldsOfOneTetrahedronHaveNoCurl) {
  // v = ∇(a·x)-like fields: on one tetrahedron with all four vertices free, v_a = s (the same
  // vector at every vertex) has Σ_a ∇φ_a × s = 0, so A·v = 0 exactly.
  Tet k{{0, 1, 2, 3}, 0.5, {1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 4.0}};
  const CurlCurlOperator op = build({k});
  Rows3 v(4, 3);
  for (int i = 0; i < 4; ++i) v.row(i) << 0.25, -1.0, 2.0;  // (exact in binary)
  std::vector<Rows3> part;
  Rows3 av;
  apply_curl_curl(op, v, av, part, CurlCurlKernel::Generic);
  EXPECT_EQ(av, Rows3::Zero(4, 3));
}

TEST(CurlCurlOperator, BadInputThrows) {
  CurlCurlOperator op(3);
  EXPECT_THROW(op.set(3, {0, 1, 2, 3}, 1.0, {}), std::out_of_range);
}

}  // namespace
}  // namespace gs::analysis
