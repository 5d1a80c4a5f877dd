// Helmholtz–Hodge decomposition on Delaunay meshes: seed 000 §4.1–4.2, eq 9–18.
#include "hhd.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/LU>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "aggregation_amg.hpp"
#include "curl_curl_operator.hpp"
#include "delaunay_mesh.hpp"
#include "thread_rows.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace gs::analysis {
namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

int vertices_of(const HhdMesh& m) {
  return m.dim + 1;
}

// z component of the cross product of two in-plane vectors (2D).
double cross_z(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

void check_mesh(const HhdMesh& m) {
  if (m.dim != 2 && m.dim != 3) {
    throw std::invalid_argument("HHD mesh dimension must be 2 or 3 (" + std::to_string(m.dim) +
                                ")");
  }
  if (m.dirichlet.size() != m.points.size()) {
    throw std::invalid_argument("one Dirichlet flag per node needed (" +
                                std::to_string(m.dirichlet.size()) + " for " +
                                std::to_string(m.points.size()) + ")");
  }
  const auto n = static_cast<std::int32_t>(m.points.size());
  for (const auto& s : m.simplices)
    for (int a = 0; a < vertices_of(m); ++a) {
      const auto i = s[static_cast<std::size_t>(a)];
      if (i < 0 || i >= n) {
        throw std::invalid_argument("simplex vertex out of range (" + std::to_string(i) + ")");
      }
    }
}

// Node -> unknown index (-1: Dirichlet or in no simplex of positive measure).
std::vector<int> unknown_index(const HhdMesh& m, const P1Geometry& g, int& count) {
  std::vector<std::uint8_t> used(m.points.size(), 0);
  for (std::size_t k = 0; k < m.simplices.size(); ++k) {
    if (!(g.measure[k] > 0.0)) continue;
    for (int a = 0; a < vertices_of(m); ++a)
      used[static_cast<std::size_t>(m.simplices[k][static_cast<std::size_t>(a)])] = 1;
  }
  // Numbered along a Hilbert curve: the rows of K (and of every vector over the unknowns) that
  // a simplex touches are then close together in memory, which the solvers' products need.
  std::vector<int> idx(m.points.size(), -1);
  count = 0;
  for (const auto i : hilbert_order(m.points, m.dim))
    if (used[static_cast<std::size_t>(i)] && !m.dirichlet[static_cast<std::size_t>(i)])
      idx[static_cast<std::size_t>(i)] = count++;
  return idx;
}

// The simplices around each unknown: those of its node point[i] (delaunay_mesh's
// vertex_simplices), in simplex order; the loops over them skip the ones of zero measure.
// Row-wise loops give each row's sums in simplex order, whatever the number of threads.
struct Incidence {
  VertexSimplices at;
  std::vector<int> point;
};

Incidence incidence(const HhdMesh& m, const std::vector<int>& idx, int n) {
  Incidence inc{vertex_simplices(m.dim, m.simplices, m.points.size()),
                std::vector<int>(static_cast<std::size_t>(n))};
  for (std::size_t p = 0; p < idx.size(); ++p)
    if (idx[p] >= 0) inc.point[static_cast<std::size_t>(idx[p])] = static_cast<int>(p);
  return inc;
}

// f(k, |T_k|, (∇φ_i)_k) for every simplex k of positive measure at unknown i, in simplex order.
template <class F>
void for_each_simplex(const Incidence& inc, const P1Geometry& g, int i, F&& f) {
  const auto p = static_cast<std::size_t>(inc.point[static_cast<std::size_t>(i)]);
  for (auto e = inc.at.offset[p]; e < inc.at.offset[p + 1]; ++e) {
    const auto k = static_cast<std::size_t>(inc.at.simplex[static_cast<std::size_t>(e)]);
    const double w = g.measure[k];
    if (w > 0.0)
      f(k, w, g.gradient[k][static_cast<std::size_t>(inc.at.vertex[static_cast<std::size_t>(e)])]);
  }
}

// Right-hand sides over the unknowns. bu: Σ_k |T_k| ∇φ_i·fu(k) (eq 17 with fu = ξ). b18:
// Σ_k |T_k| ∇φ_i × fv(k) (eq 18 as written with fv = ξ; 1 column in 2D, its z component, 3
// columns in 3D). Rows on the threads, each summed in simplex order.
// One simplex's terms at a node (sums su, sv held by the caller, nv = 3 or 1 columns of b18).
inline void add_rhs_terms(int nv, double w, const Eigen::Vector3d& gi, const Eigen::Vector3d& a,
                          const Eigen::Vector3d& b, double& su, Eigen::Vector3d& sv) {
  su += w * gi.dot(a);
  if (nv == 3) {
    sv += w * gi.cross(b);
  } else {
    sv.x() += w * cross_z(gi, b);
  }
}

template <class Fu, class Fv>
void right_hand_sides(const HhdMesh& m, const P1Geometry& g, const Incidence& inc, int n, Fu&& fu,
                      Fv&& fv, Eigen::VectorXd& bu, Eigen::MatrixXd& b18) {
  const int nv = m.dim == 3 ? 3 : 1;
  bu.resize(n);  // (every row written below)
  b18.resize(n, nv);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    double su = 0.0;  // (the sums in registers, written once)
    Eigen::Vector3d sv = Eigen::Vector3d::Zero();
    for_each_simplex(inc, g, i, [&](std::size_t k, double w, const Eigen::Vector3d& gi) {
      add_rhs_terms(nv, w, gi, fu(k), fv(k), su, sv);
    });
    bu(i) = su;
    for (int c = 0; c < nv; ++c) b18(i, c) = sv(c);
  }
}

// P1 stiffness K_ij = Σ_k |T_k| (∇φ_i)_k·(∇φ_j)_k over the unknowns, full symmetric storage
// (compressed, inner indices sorted), assembled row by row on the threads: each entry summed in
// simplex order (exactly symmetric). Also right_hand_sides(fu = fv = ξ) into bu and b18 in the
// same pass over each row's simplices (the same sums in the same order: the same bits).
template <class Sparse>
Sparse stiffness(const HhdMesh& m, const P1Geometry& g, const std::vector<int>& idx,
                 const Incidence& inc, int n, const std::vector<Eigen::Vector3d>& xi,
                 Eigen::VectorXd& bu, Eigen::MatrixXd& b18) {
  const int nvert = vertices_of(m);
  const int nv = m.dim == 3 ? 3 : 1;
  bu.resize(n);  // (every row written below)
  b18.resize(n, nv);
  // Symmetric: the rows are the columns.
  return assemble_rows<Sparse>(
      n, n, max_threads(),
      [&](Eigen::Index lo, Eigen::Index hi, std::vector<int>& c, std::vector<double>& v,
          std::vector<int>& outer) {
        std::vector<int> mark(static_cast<std::size_t>(n), -1), pos(static_cast<std::size_t>(n), 0);
        std::vector<std::pair<int, double>> row;
        // (room for about as many entries as the rows have simplices, ~1.7 times what a Delaunay
        // row holds: no regrowth; pages never written are never touched)
        std::size_t room = 0;
        for (auto i = lo; i < hi; ++i) {
          const auto p = static_cast<std::size_t>(inc.point[static_cast<std::size_t>(i)]);
          room += static_cast<std::size_t>(inc.at.offset[p + 1] - inc.at.offset[p]) + 1;
        }
        c.reserve(room);
        v.reserve(room);
        for (int i = static_cast<int>(lo); i < static_cast<int>(hi); ++i) {
          const auto ii = static_cast<std::size_t>(i);
          const auto p = static_cast<std::size_t>(inc.point[ii]);
          row.resize(static_cast<std::size_t>(nvert * (inc.at.offset[p + 1] - inc.at.offset[p])));
          std::size_t q = 0;  // (the row's entries so far)
          double su = 0.0;
          Eigen::Vector3d sv = Eigen::Vector3d::Zero();
          for_each_simplex(inc, g, i, [&](std::size_t k, double w, const Eigen::Vector3d& ga) {
            add_rhs_terms(nv, w, ga, xi[k], xi[k], su, sv);
            for (int b = 0; b < nvert; ++b) {
              const int j =
                  idx[static_cast<std::size_t>(m.simplices[k][static_cast<std::size_t>(b)])];
              if (j < 0) continue;
              const double value = w * ga.dot(g.gradient[k][static_cast<std::size_t>(b)]);
              // A new column takes the next place and starts from −0 (−0 + x is x, to the bit),
              // an old one adds to its place: selects, not a branch to mispredict.
              auto& mk = mark[static_cast<std::size_t>(j)];
              const bool fresh = mk != i;
              auto& pj = pos[static_cast<std::size_t>(j)];
              pj = fresh ? static_cast<int>(q) : pj;
              mk = i;
              auto& entry = row[static_cast<std::size_t>(pj)];
              entry.second = (fresh ? -0.0 : entry.second) + value;
              entry.first = j;
              q += fresh ? 1 : 0;
            }
          });
          std::sort(row.begin(), row.begin() + static_cast<std::ptrdiff_t>(q),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
          for (std::size_t e = 0; e < q; ++e) {
            c.push_back(row[e].first);
            v.push_back(row[e].second);
          }
          outer[ii + 1] = static_cast<int>(q);
          bu(i) = su;
          for (int col = 0; col < nv; ++col) b18(i, col) = sv(col);
        }
      });
}

// Eq 18 as written in 3D: block (i, j) = Σ_k |T_k| (∇φ_j ∇φ_iᵀ − (∇φ_i·∇φ_j) I), i.e. the
// coefficient of v_j[q] in row (i, p) of Σ_k |T_k| ∇φ_i × (∇×v)_k. Assembled directly in
// compressed storage on the pattern of K expanded to 3×3 blocks (no triplet list: 144 entries
// per tetrahedron would need ~1 GB at 56 000 nodes).
SpMat curl_curl_eq18(const HhdMesh& m, const P1Geometry& g, const std::vector<int>& idx,
                     const SpMat& k) {
  const int n = static_cast<int>(k.cols());
  SpMat a(3 * n, 3 * n);
  const auto nnz = static_cast<Eigen::Index>(9 * k.nonZeros());
  a.resizeNonZeros(nnz);
  int* outer = a.outerIndexPtr();
  int* inner = a.innerIndexPtr();
  double* val = a.valuePtr();
  std::fill(val, val + nnz, 0.0);
  const int* kouter = k.outerIndexPtr();
  const int* kinner = k.innerIndexPtr();
  for (int j = 0; j < n; ++j) {
    const int c = kouter[j + 1] - kouter[j];
    for (int q = 0; q < 3; ++q) {
      const int col = 3 * j + q;
      outer[col] = 9 * kouter[j] + 3 * q * c;
      for (int e = 0; e < c; ++e)
        for (int p = 0; p < 3; ++p) inner[outer[col] + 3 * e + p] = 3 * kinner[kouter[j] + e] + p;
    }
  }
  outer[3 * n] = static_cast<int>(nnz);
  for (std::size_t s = 0; s < m.simplices.size(); ++s) {
    const double w = g.measure[s];
    if (!(w > 0.0)) continue;
    for (std::size_t b = 0; b < 4; ++b) {
      const int j = idx[static_cast<std::size_t>(m.simplices[s][b])];
      if (j < 0) continue;
      const int c = kouter[j + 1] - kouter[j];
      const Eigen::Vector3d& gj = g.gradient[s][b];
      for (std::size_t a4 = 0; a4 < 4; ++a4) {
        const int i = idx[static_cast<std::size_t>(m.simplices[s][a4])];
        if (i < 0) continue;
        const int e = static_cast<int>(
            std::lower_bound(kinner + kouter[j], kinner + kouter[j + 1], i) - (kinner + kouter[j]));
        const Eigen::Vector3d& gi = g.gradient[s][a4];
        const double dot = gi.dot(gj);
        for (int q = 0; q < 3; ++q) {
          double* column = val + 9 * kouter[j] + 3 * q * c + 3 * e;
          for (int p = 0; p < 3; ++p) column[p] += w * (gj[p] * gi[q] - (p == q ? dot : 0.0));
        }
      }
    }
  }
  return a;
}

// A = CᵀMC (the matrix of eq 18 up to its sign), laid out for its products: the tetrahedra of
// positive measure in the order of their smallest unknown (the unknowns follow a Hilbert curve,
// so consecutive tetrahedra read and write nearby rows), each with its four unknowns (−1: a
// Dirichlet node), |T_k| and ∇φ_1..3 (∇φ_0 = −∇φ_1 − ∇φ_2 − ∇φ_3, summed as p1_geometry sums
// it: the same bits).
CurlCurlOperator curl_curl_operator(const HhdMesh& m, const P1Geometry& g,
                                    const std::vector<int>& idx, Eigen::Index n) {
  // Stable counting sort by the smallest unknown (simplices of one key in simplex order).
  const auto ns = static_cast<std::ptrdiff_t>(m.simplices.size());
  std::vector<int> first(m.simplices.size(), -1);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < ns; ++kk) {
    const auto k = static_cast<std::size_t>(kk);
    if (!(g.measure[k] > 0.0)) continue;
    int f = std::numeric_limits<int>::max();
    for (std::size_t a = 0; a < 4; ++a) {
      const int j = idx[static_cast<std::size_t>(m.simplices[k][a])];
      if (j >= 0) f = std::min(f, j);
    }
    if (f != std::numeric_limits<int>::max()) first[k] = f;
  }
  std::vector<std::size_t> start(static_cast<std::size_t>(n) + 1, 0);
  for (const int f : first)
    if (f >= 0) ++start[static_cast<std::size_t>(f) + 1];
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) start[i + 1] += start[i];
  std::vector<std::int32_t> order(start.back());
  for (std::size_t k = 0; k < first.size(); ++k)
    if (first[k] >= 0)
      order[start[static_cast<std::size_t>(first[k])]++] = static_cast<std::int32_t>(k);
  CurlCurlOperator op(order.size());
  const auto nb = static_cast<std::ptrdiff_t>(op.blocks.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t bb = 0; bb < nb; ++bb) {
    const auto lo = static_cast<std::size_t>(bb) * CurlCurlOperator::kLanes;
    const std::size_t hi = std::min(order.size(), lo + CurlCurlOperator::kLanes);
    for (std::size_t e = lo; e < hi; ++e) {
      const auto k = static_cast<std::size_t>(order[e]);
      std::array<int, 4> node{};
      for (std::size_t a = 0; a < 4; ++a)
        node[a] = idx[static_cast<std::size_t>(m.simplices[k][a])];
      std::array<double, 9> gradient{};
      for (std::size_t a = 1; a < 4; ++a)
        for (std::size_t q = 0; q < 3; ++q)
          gradient[3 * (a - 1) + q] = g.gradient[k][a][static_cast<Eigen::Index>(q)];
      op.set(e, node, g.measure[k], gradient);
    }
  }
  return op;
}

// The 3×3 diagonal blocks of A, Σ_k |T_k| (|∇φ_i|² I − ∇φ_i ∇φ_iᵀ), inverted (pseudo-inverse
// for a block of rank < 3: a node whose tetrahedra all share one gradient direction).
std::vector<Eigen::Matrix3d> curl_curl_block_inverses(const HhdMesh& m, const P1Geometry& g,
                                                      const std::vector<int>& idx, int n) {
  std::vector<Eigen::Matrix3d> d(static_cast<std::size_t>(n), Eigen::Matrix3d::Zero());
  for (std::size_t k = 0; k < m.simplices.size(); ++k) {
    const double w = g.measure[k];
    if (!(w > 0.0)) continue;
    for (std::size_t a = 0; a < 4; ++a) {
      const int i = idx[static_cast<std::size_t>(m.simplices[k][a])];
      if (i < 0) continue;
      const Eigen::Vector3d& gi = g.gradient[k][a];
      d[static_cast<std::size_t>(i)] +=
          w * (gi.squaredNorm() * Eigen::Matrix3d::Identity() - gi * gi.transpose());
    }
  }
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix3d& b = d[static_cast<std::size_t>(i)];
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(b);
    const Eigen::Vector3d ev = es.eigenvalues();
    Eigen::Vector3d inv = Eigen::Vector3d::Zero();
    for (int q = 0; q < 3; ++q)
      if (ev(q) > 1e-12 * ev(2)) inv(q) = 1.0 / ev(q);
    b = es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
  }
  return d;
}

// Row i of x times its node's 3×3 block.
Eigen::RowVector3d block_row(const std::vector<Eigen::Matrix3d>& d, const Rows3& x,
                             Eigen::Index i) {
  return (d[static_cast<std::size_t>(i)] * x.row(i).transpose()).transpose();
}

Rows3 apply_blocks(const std::vector<Eigen::Matrix3d>& d, const Rows3& r) {
  Rows3 z(r.rows(), 3);
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < r.rows(); ++i) z.row(i) = block_row(d, r, i);
  return z;
}

// Σ over [0, n) of f(begin, end) (N sums) taken per chunk of rows on the threads, then over the
// chunks in order (thread_rows.hpp): the same bits for any number of threads.
template <std::size_t N, class F>
std::array<double, N> chunked_sums(Eigen::Index n, F&& f) {
  std::vector<std::array<double, N>> part(static_cast<std::size_t>(row_chunks(n)));
  for_row_chunks(n, [&](Eigen::Index lo, Eigen::Index hi, Eigen::Index k) {
    part[static_cast<std::size_t>(k)] = f(lo, hi);
  });
  std::array<double, N> sum{};
  for (const auto& x : part)
    for (std::size_t q = 0; q < N; ++q) sum[q] += x[q];
  return sum;
}

template <class F>
double chunked_sum(Eigen::Index n, F&& f) {
  return chunked_sums<1>(
      n, [&](Eigen::Index lo, Eigen::Index hi) { return std::array<double, 1>{f(lo, hi)}; })[0];
}

// Eq 18 in 3D as the projection it is: v minimises ‖∇×v − ξ‖ over P1 fields vanishing on the
// hull, i.e. A v = CᵀMξ with A = CᵀMC (SPD on Delaunay meshes, but conditioned like h⁻⁴ and much
// worse with slivers). Conjugate gradients, from v = 0, on A with a symmetric two-part
// preconditioner:
//  * the vector Laplacian K⊗I (`solve_k`, the factor path (b) computes): K⊗I = CᵀMC + DᵀMD, so
//    (K⊗I)⁻¹A = I − (K⊗I)⁻¹DᵀMD is the identity on divergence-free fields; and
//  * damped block Jacobi on A's 3×3 node blocks before and after it (symmetric multiplicative),
//    for the modes K⊗I gets wrong: a sliver tetrahedron stiffens K in every direction, A only
//    tangentially to the sliver. Damping ω = 1.5/λ_max(D⁻¹A) (power iteration, a lower bound of
//    λ_max): ω λ_max < 2 keeps the preconditioner SPD. On 10 000 random points it cuts the
//    iterations from 1 527 (Laplacian alone) to 118; a per-sliver 12×12 block or a deflation of
//    low-order polynomial divergence modes did not reduce them further (docs/hhd.md).
// `additive` (for an approximate solve_k such as one AMG V-cycle): z = solve_k(r) + ω D⁻¹r with
// ω = 0.4/λ_max instead, SPD for any ω > 0 and with no product with A inside: ~1.7× the
// iterations, each a third of the products (faster once solve_k is cheap; docs/hhd.md).
// CG minimises ‖C(v − v*)‖_M, the error of ∇×v, over its Krylov space, and its residual is
// orthogonal to that space, which holds v: ⟨∇×v, h⟩ = vᵀ(CᵀMξ − Av) = 0 at every iterate (to
// round-off). Stops at ‖CᵀMξ − Av‖ ≤ tolerance ‖CᵀMξ‖ (eq 18's residual) or max_iterations.
template <class SolveK>
Eigen::MatrixXd projection_pcg(const HhdMesh& m, const P1Geometry& g, const std::vector<int>& idx,
                               const Eigen::MatrixXd& b, SolveK&& solve_k, bool additive,
                               double tolerance, int max_iterations, int& iterations,
                               bool& converged, const std::function<void()>& poll) {
  const Eigen::Index n = b.rows();
  iterations = 0;
  converged = true;
  Rows3 v = Rows3::Zero(n, 3);
  const double bnorm = b.norm();
  if (bnorm == 0.0) return Eigen::MatrixXd(v);
  const auto d = curl_curl_block_inverses(m, g, idx, static_cast<int>(n));
  const CurlCurlOperator op = curl_curl_operator(m, g, idx, n);
  auto dot = [n](const Rows3& x, const Rows3& y) {
    return chunked_sum(n, [&](Eigen::Index lo, Eigen::Index hi) {
      double s = 0.0;
      for (Eigen::Index i = lo; i < hi; ++i) s += x.row(i).dot(y.row(i));
      return s;
    });
  };
  // The vectors of the iterations, allocated once.
  Rows3 r = b, z(n, 3), p(n, 3), ap(n, 3), k(n, 3), t(n, 3);
  std::vector<Rows3> part;
  // λ_max(D⁻¹A) by power iteration from a fixed start (deterministic).
  Rows3 q = Rows3::Ones(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    q.row(i) *= (i % 7 == 0 ? -1.0 : 1.0) * (1.0 + 0.01 * static_cast<double>(i % 13));
  double lambda = 1.0;
  for (int it = 0; it < 12; ++it) {
    apply_curl_curl(op, q, ap, part);
    const Rows3 dq = apply_blocks(d, ap);
    const double qaq = dot(q, ap);
    const double qdq = dot(dq, ap);
    if (qaq > 0.0) lambda = qdq / qaq;  // Rayleigh quotient of D⁻¹A in the A inner product
    q = dq / std::sqrt(dot(dq, dq));
  }
  const double omega = (additive ? 0.4 : 1.5) / lambda;
  // z = ω D⁻¹x (+ z if `add`), the blocks on the threads.
  auto jacobi = [&](const Rows3& x, bool add) {
#pragma omp parallel for schedule(static)
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::RowVector3d y = omega * block_row(d, x, i);
      z.row(i) = add ? Eigen::RowVector3d(z.row(i) + y) : y;
    }
  };
  // z = P r; returns rᵀz.
  auto precondition = [&]() {
    if (additive) {
      solve_k(r, k);
      return chunked_sum(n, [&](Eigen::Index lo, Eigen::Index hi) {
        double s = 0.0;
        for (Eigen::Index i = lo; i < hi; ++i) {
          z.row(i) = k.row(i) + omega * block_row(d, r, i);
          s += r.row(i).dot(z.row(i));
        }
        return s;
      });
    }
    jacobi(r, false);
    apply_curl_curl(op, z, ap, part);
    t = r - ap;
    solve_k(t, k);
    z += k;
    apply_curl_curl(op, z, ap, part);
    t = r - ap;
    jacobi(t, true);
    return dot(r, z);
  };
  double rz = precondition();
  p = z;
  for (int it = 1; it <= max_iterations; ++it) {
    apply_curl_curl(op, p, ap, part);
    const double pap = dot(p, ap);
    if (!(pap > 0.0) || !(rz > 0.0)) break;
    const double alpha = rz / pap;
    const double rr = chunked_sum(n, [&](Eigen::Index lo, Eigen::Index hi) {
      double s = 0.0;
      for (Eigen::Index i = lo; i < hi; ++i) {
        v.row(i) += alpha * p.row(i);
        r.row(i) -= alpha * ap.row(i);
        s += r.row(i).squaredNorm();
      }
      return s;
    });
    iterations = it;
    if (std::sqrt(rr) <= tolerance * bnorm) return Eigen::MatrixXd(v);
    if (poll && it % 8 == 0) poll();
    const double rz_new = precondition();
    const double beta = rz_new / rz;
#pragma omp parallel for schedule(static)
    for (Eigen::Index i = 0; i < n; ++i) p.row(i) = z.row(i) + beta * p.row(i);
    rz = rz_new;
  }
  converged = false;
  return Eigen::MatrixXd(v);
}

template <class Solver>
Eigen::VectorXd iterate(Solver& s, const Eigen::VectorXd& b, int& iterations, bool& converged) {
  if (b.norm() == 0.0) return Eigen::VectorXd::Zero(b.size());
  const Eigen::VectorXd x = s.solve(b);
  iterations = std::max(iterations, static_cast<int>(s.iterations()));
  if (s.info() != Eigen::Success) converged = false;
  return x;
}

}  // namespace

const char* hhd_solver_name(HhdSolver s) {
  switch (s) {
    case HhdSolver::Auto:
      return "auto";
    case HhdSolver::Cholmod:
      return "cholmod";
    case HhdSolver::Ldlt:
      return "ldlt";
    case HhdSolver::Cg:
      return "cg";
    case HhdSolver::BiCgStab:
      return "bicgstab";
    case HhdSolver::Projection:
      return "projection";
    case HhdSolver::ProjectionAmg:
      return "projection-amg";
  }
  return "?";
}

HhdSolver hhd_solver_from_name(const std::string& name) {
  for (auto s : {HhdSolver::Auto, HhdSolver::Projection, HhdSolver::ProjectionAmg,
                 HhdSolver::Cholmod, HhdSolver::Ldlt, HhdSolver::Cg, HhdSolver::BiCgStab})
    if (name == hhd_solver_name(s)) return s;
  throw std::invalid_argument(
      "unknown HHD solver, expected auto, projection, projection-amg, cholmod, ldlt, cg or "
      "bicgstab (" +
      name + ")");
}

P1Geometry p1_geometry(const HhdMesh& m) {
  check_mesh(m);
  P1Geometry g;
  const std::size_t ns = m.simplices.size();
  g.measure.assign(ns, 0.0);
  g.gradient.assign(ns, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                         Eigen::Vector3d::Zero()});
  const auto n = static_cast<std::ptrdiff_t>(ns);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < n; ++kk) {
    const auto k = static_cast<std::size_t>(kk);
    const auto& s = m.simplices[k];
    auto& gr = g.gradient[k];
    if (m.dim == 3) {
      std::array<Eigen::Vector3d, 4> x;
      for (std::size_t a = 0; a < 4; ++a) x[a] = m.points[static_cast<std::size_t>(s[a])];
      Eigen::Matrix3d j;
      for (int a = 0; a < 3; ++a) j.col(a) = x[static_cast<std::size_t>(a) + 1] - x[0];
      const double volume = std::abs(j.determinant()) / 6.0;
      if (!(tetrahedron_quality(x, volume) > 1e-12)) continue;
      // Barycentric λ = J⁻¹ (x − x0): the rows of J⁻¹ are ∇φ_1..3; ∇φ_0 = −Σ. Equal to the
      // paper's face normal of length area(f) / (3 |T|) (tested).
      const Eigen::Matrix3d inv = j.inverse();
      gr[0] = Eigen::Vector3d::Zero();
      for (int a = 0; a < 3; ++a) {
        gr[static_cast<std::size_t>(a) + 1] = inv.row(a).transpose();
        gr[0] -= gr[static_cast<std::size_t>(a) + 1];
      }
      g.measure[k] = volume;
    } else {
      std::array<Eigen::Vector2d, 3> x;
      for (std::size_t a = 0; a < 3; ++a) x[a] = m.points[static_cast<std::size_t>(s[a])].head<2>();
      Eigen::Matrix2d j;
      j.col(0) = x[1] - x[0];
      j.col(1) = x[2] - x[0];
      const double area = std::abs(j.determinant()) / 2.0;
      if (!(triangle_quality(x, area) > 1e-12)) continue;
      const Eigen::Matrix2d inv = j.inverse();
      gr[0] = Eigen::Vector3d::Zero();
      for (int a = 0; a < 2; ++a) {
        gr[static_cast<std::size_t>(a) + 1] = Eigen::Vector3d(inv(a, 0), inv(a, 1), 0.0);
        gr[0] -= gr[static_cast<std::size_t>(a) + 1];
      }
      g.measure[k] = area;
    }
  }
  return g;
}

std::vector<Eigen::Vector3d> simplex_mean(const HhdMesh& m,
                                          const std::vector<Eigen::Vector3d>& nodal) {
  check_mesh(m);
  if (nodal.size() != m.points.size()) {
    throw std::invalid_argument("one vector per node needed (" + std::to_string(nodal.size()) +
                                " for " + std::to_string(m.points.size()) + ")");
  }
  const int nv = vertices_of(m);
  std::vector<Eigen::Vector3d> xi(m.simplices.size());  // (first written on the threads)
  const auto ns = static_cast<std::ptrdiff_t>(m.simplices.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < ns; ++kk) {
    const auto k = static_cast<std::size_t>(kk);
    xi[k] = Eigen::Vector3d::Zero();
    for (int a = 0; a < nv; ++a)
      xi[k] += nodal[static_cast<std::size_t>(m.simplices[k][static_cast<std::size_t>(a)])];
    xi[k] /= nv;
    if (m.dim == 2) xi[k].z() = 0.0;
  }
  return xi;
}

namespace {

// ∇u, ∇×v and ∇·v on simplex k (one expression each for the p1_* functions and the fused pass
// of helmholtz_hodge: the same bits).
Eigen::Vector3d gradient_on(const HhdMesh& m, const P1Geometry& g, const Eigen::VectorXd& u,
                            std::size_t k) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int a = 0; a < vertices_of(m); ++a)
    out +=
        u(m.simplices[k][static_cast<std::size_t>(a)]) * g.gradient[k][static_cast<std::size_t>(a)];
  return out;
}

Eigen::Vector3d curl_on(const HhdMesh& m, const P1Geometry& g, const Eigen::MatrixXd& v,
                        std::size_t k) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int a = 0; a < vertices_of(m); ++a) {
    const auto i = m.simplices[k][static_cast<std::size_t>(a)];
    const Eigen::Vector3d& gr = g.gradient[k][static_cast<std::size_t>(a)];
    if (m.dim == 3) {
      out += gr.cross(Eigen::Vector3d(v(i, 0), v(i, 1), v(i, 2)));
    } else {
      out += v(i, 0) * Eigen::Vector3d(gr.y(), -gr.x(), 0.0);
    }
  }
  return out;
}

double divergence_on(const HhdMesh& m, const P1Geometry& g, const Eigen::MatrixXd& v,
                     std::size_t k) {
  double out = 0.0;
  if (m.dim != 3) return out;
  for (std::size_t a = 0; a < 4; ++a) {
    const auto i = m.simplices[k][a];
    out += g.gradient[k][a].dot(Eigen::Vector3d(v(i, 0), v(i, 1), v(i, 2)));
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector3d> p1_gradient(const HhdMesh& m, const P1Geometry& g,
                                         const Eigen::VectorXd& u) {
  std::vector<Eigen::Vector3d> out(m.simplices.size());  // (first written on the threads)
  const auto ns = static_cast<std::ptrdiff_t>(m.simplices.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < ns; ++kk)
    out[static_cast<std::size_t>(kk)] = gradient_on(m, g, u, static_cast<std::size_t>(kk));
  return out;
}

std::vector<Eigen::Vector3d> p1_curl(const HhdMesh& m, const P1Geometry& g,
                                     const Eigen::MatrixXd& v) {
  std::vector<Eigen::Vector3d> out(m.simplices.size());  // (first written on the threads)
  const auto ns = static_cast<std::ptrdiff_t>(m.simplices.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < ns; ++kk)
    out[static_cast<std::size_t>(kk)] = curl_on(m, g, v, static_cast<std::size_t>(kk));
  return out;
}

std::vector<double> p1_divergence(const HhdMesh& m, const P1Geometry& g, const Eigen::MatrixXd& v) {
  std::vector<double> out(m.simplices.size(), 0.0);
  if (m.dim != 3) return out;
  const auto ns = static_cast<std::ptrdiff_t>(m.simplices.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < ns; ++kk)
    out[static_cast<std::size_t>(kk)] = divergence_on(m, g, v, static_cast<std::size_t>(kk));
  return out;
}

HhdResult helmholtz_hodge(const HhdMesh& m, const std::vector<Eigen::Vector3d>& xi,
                          const HhdOptions& o) {
  check_mesh(m);
  if (xi.size() != m.simplices.size()) {
    throw std::invalid_argument("one vector per simplex needed (" + std::to_string(xi.size()) +
                                " for " + std::to_string(m.simplices.size()) + ")");
  }
  for (std::size_t k = 0; k < xi.size(); ++k) {
    if (!xi[k].allFinite()) {
      throw std::invalid_argument("non-finite vector (simplex " + std::to_string(k) + ")");
    }
  }
  if (!(o.tolerance >= 0.0 && o.tolerance < 1.0) || o.max_iterations < 1) {
    throw std::invalid_argument(
        "iterative solver needs tolerance in [0, 1) (0: its default) and max_iterations >= 1");
  }
  HhdResult r;
  r.dim = m.dim;
  const int nv = m.dim == 3 ? 3 : 1;
  auto t0 = Clock::now();
  const P1Geometry g = p1_geometry(m);
  int n = 0;
  const std::vector<int> idx = unknown_index(m, g, n);
  if (n == 0) throw std::invalid_argument("HHD mesh has no interior node to solve for");
  r.report.unknowns = static_cast<std::size_t>(n);
  HhdSolver solver = o.solver;
  if (solver == HhdSolver::Auto)
    solver = m.dim == 3 ? HhdSolver::ProjectionAmg : HhdSolver::Cholmod;
  const bool projection = solver == HhdSolver::Projection || solver == HhdSolver::ProjectionAmg;
  const double tolerance = o.tolerance > 0.0 ? o.tolerance
                           : projection      ? kHhdProjectionTolerance
                                             : kHhdTolerance;
  const bool iterative = solver == HhdSolver::Cg || solver == HhdSolver::BiCgStab ||
                         solver == HhdSolver::ProjectionAmg ||
                         (solver == HhdSolver::Projection && m.dim == 3);
  r.report.tolerance = iterative ? tolerance : 0.0;
  r.report.solver = hhd_solver_name(solver);
  r.xi.resize(xi.size());  // (copied on the threads: the pages first touched there)
  const auto n_simplices = static_cast<std::ptrdiff_t>(xi.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t kk = 0; kk < n_simplices; ++kk) {
    const auto k = static_cast<std::size_t>(kk);
    r.xi[k] = xi[k];
    if (m.dim == 2) r.xi[k].z() = 0.0;
  }
  Eigen::VectorXd bu;
  Eigen::MatrixXd b18;
  const Incidence inc = incidence(m, idx, n);
  // K and the right-hand sides (eq 17 and eq 18 with ξ) in one pass. K: column-major for the
  // factorisations; row-major (the same arrays: K is symmetric) for the AMG paths, which take
  // it over.
  const bool amg = solver == HhdSolver::Cg || solver == HhdSolver::ProjectionAmg;
  const SpMat k = amg ? SpMat() : stiffness<SpMat>(m, g, idx, inc, n, r.xi, bu, b18);
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> k_rows =
      amg ? stiffness<Eigen::SparseMatrix<double, Eigen::RowMajor, int>>(m, g, idx, inc, n, r.xi,
                                                                         bu, b18)
          : Eigen::SparseMatrix<double, Eigen::RowMajor, int>();
  r.report.seconds_assembly = seconds_since(t0);

  // Solutions over the unknowns: column 0 = u, columns 1.. = v.
  Eigen::MatrixXd x(n, 1 + nv);
  Eigen::MatrixXd v_coulomb;  // projection in 3D: path (b)'s v (see HhdResult::v_coulomb)
  Eigen::MatrixXd rhs(n, 1 + nv);
  rhs.col(0) = bu;
  rhs.rightCols(nv) = -b18;  // path (b): K v = Σ |T| ξ × ∇φ_i (docs/hhd.md)
  auto direct = [&](auto& factor) {
    t0 = Clock::now();
    factor.compute(k);
    r.report.seconds_factor = seconds_since(t0);
    if (factor.info() != Eigen::Success) {
      throw std::invalid_argument(
          "HHD stiffness matrix factorization failed (not positive "
          "definite: degenerate mesh?)");
    }
    t0 = Clock::now();
    x = factor.solve(rhs);
    r.report.seconds_solve = seconds_since(t0);
  };
  // 3D: eq 18's projection from path (b)'s solution in x (kept as v_coulomb), with solve_k
  // (K⁻¹ or an approximation of it, per column) in its preconditioner.
  auto project = [&](auto&& solve_k, bool additive) {
    t0 = Clock::now();
    v_coulomb = x.rightCols(3);
    bool converged = true;
    x.rightCols(3) = projection_pcg(m, g, idx, Eigen::MatrixXd(-b18), solve_k, additive, tolerance,
                                    o.max_iterations, r.report.iterations_v, converged, o.poll);
    r.report.converged = r.report.converged && converged;
    r.report.seconds_solve += seconds_since(t0);
  };
  // Path (b) by AMG-preconditioned CG, u and every component of v at once (each column stops at
  // its own relative residual `tol`).
  auto amg_path_b = [&](const AmgHierarchy& h, double tol) {
    t0 = Clock::now();
    std::vector<int> its;
    int iterations = 0;
    bool converged = true;
    x = amg_pcg(h, rhs, tol, o.max_iterations, iterations, converged, &its, o.poll);
    r.report.iterations_u = its[0];
    r.report.iterations_v = *std::max_element(its.begin() + 1, its.end());
    r.report.converged = converged;
    r.report.seconds_solve = seconds_since(t0);
  };
  switch (solver) {
    case HhdSolver::Projection: {
      Eigen::CholmodDecomposition<SpMat, Eigen::Lower> s;
      direct(s);  // u, and path (b)'s v (eq 18 itself in 2D)
      if (o.poll) o.poll();
      if (m.dim == 3)
        project([&](const Rows3& q, Rows3& out) { out = s.solve(Eigen::MatrixXd(q)); }, false);
      break;
    }
    case HhdSolver::ProjectionAmg: {
      // u and path (b)'s v (eq 18 itself in 2D) by AMG-preconditioned CG to kHhdTolerance (or
      // the tolerance asked for, if smaller); in 3D eq 18's projection with the V-cycle as the
      // Laplacian part of its preconditioner.
      t0 = Clock::now();
      const AmgHierarchy h = build_amg(std::move(k_rows));
      r.report.seconds_factor = seconds_since(t0);
      amg_path_b(h, std::min(tolerance, kHhdTolerance));
      if (o.poll) o.poll();
      if (m.dim == 3) {
        r.report.iterations_v = 0;
        AmgWorkspace w;
        project([&](const Rows3& q, Rows3& out) { amg_vcycle(h, q, out, w); }, true);
      } else {
        r.report.tolerance = std::min(tolerance, kHhdTolerance);  // (no projection iterations)
      }
      break;
    }
    case HhdSolver::Auto:  // resolved above
    case HhdSolver::Cholmod: {
      Eigen::CholmodDecomposition<SpMat, Eigen::Lower> s;
      direct(s);
      break;
    }
    case HhdSolver::Ldlt: {
      Eigen::SimplicialLDLT<SpMat, Eigen::Lower> s;
      direct(s);
      break;
    }
    case HhdSolver::Cg: {
      // Path (b) by conjugate gradients, every column at once, preconditioned with one V-cycle
      // of smoothed-aggregation AMG (its setup reported as the factor).
      t0 = Clock::now();
      const AmgHierarchy h = build_amg(std::move(k_rows));
      r.report.seconds_factor = seconds_since(t0);
      amg_path_b(h, tolerance);
      break;
    }
    case HhdSolver::BiCgStab: {
      // Eq 17 as written (matrix K) and eq 18 as written (2D: −K; 3D: the block matrix).
      t0 = Clock::now();
      Eigen::BiCGSTAB<SpMat> su;
      su.setTolerance(tolerance);
      su.setMaxIterations(o.max_iterations);
      su.compute(k);
      SpMat a18 = m.dim == 3 ? curl_curl_eq18(m, g, idx, k) : SpMat(-k);
      Eigen::BiCGSTAB<SpMat> sv;
      sv.setTolerance(tolerance);
      sv.setMaxIterations(o.max_iterations);
      sv.compute(a18);
      r.report.seconds_factor = seconds_since(t0);
      t0 = Clock::now();
      x.col(0) = iterate(su, bu, r.report.iterations_u, r.report.converged);
      if (m.dim == 3) {
        Eigen::VectorXd b(3 * n);
        for (int i = 0; i < n; ++i) b.segment<3>(3 * i) = b18.row(i).transpose();
        const Eigen::VectorXd v = iterate(sv, b, r.report.iterations_v, r.report.converged);
        for (int i = 0; i < n; ++i) x.row(i).tail<3>() = v.segment<3>(3 * i).transpose();
      } else {
        x.col(1) = iterate(sv, b18.col(0), r.report.iterations_v, r.report.converged);
      }
      r.report.seconds_solve = seconds_since(t0);
      break;
    }
  }

  // Nodal potentials (zero at the Dirichlet nodes) and the per-simplex parts.
  r.u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.points.size()));
  r.v = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(m.points.size()), nv);
  r.v_coulomb = r.v;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    if (idx[i] < 0) continue;
    const auto ii = static_cast<Eigen::Index>(i);
    r.u(ii) = x(idx[i], 0);
    r.v.row(ii) = x.row(idx[i]).tail(nv);
    r.v_coulomb.row(ii) = v_coulomb.rows() > 0 ? v_coulomb.row(idx[i]) : r.v.row(ii);
  }
  r.measure = g.measure;
  // ∇u, ∇×v (p1_gradient, p1_curl), h, and the norms and inner products (with ∇·v's) in one
  // pass over the simplices (chunked: the same bits on any threads).
  r.grad_u.resize(r.xi.size());
  r.curl_v.resize(r.xi.size());
  r.harmonic.resize(r.xi.size());
  const auto sums = chunked_sums<8>(
      static_cast<Eigen::Index>(r.xi.size()), [&](Eigen::Index lo, Eigen::Index hi) {
        std::array<double, 8> q{};
        for (auto kk = lo; kk < hi; ++kk) {
          const auto k = static_cast<std::size_t>(kk);
          const double w = r.measure[k];
          r.grad_u[k] = gradient_on(m, g, r.u, k);
          r.curl_v[k] = curl_on(m, g, r.v, k);
          const double div_k = divergence_on(m, g, r.v, k);
          const Eigen::Vector3d &xi_k = r.xi[k], &gu = r.grad_u[k], &cv = r.curl_v[k];
          const Eigen::Vector3d h = xi_k - gu - cv;
          r.harmonic[k] = h;
          q[0] += w * xi_k.dot(xi_k);
          q[1] += w * gu.dot(gu);
          q[2] += w * cv.dot(cv);
          q[3] += w * h.dot(h);
          q[4] += w * gu.dot(cv);
          q[5] += w * gu.dot(h);
          q[6] += w * cv.dot(h);
          q[7] += w * div_k * div_k;
        }
        return q;
      });
  r.norm_xi = std::sqrt(sums[0]);
  r.norm_grad_u = std::sqrt(sums[1]);
  r.norm_curl_v = std::sqrt(sums[2]);
  r.norm_harmonic = std::sqrt(sums[3]);
  r.dot_grad_curl = sums[4];
  r.dot_grad_harmonic = sums[5];
  r.dot_curl_harmonic = sums[6];
  r.norm_div_v = std::sqrt(sums[7]);

  // Residuals of eq 17 and eq 18 as written, matrix-free: Σ_k |T_k| ∇φ_i·(∇u − ξ)_k and
  // Σ_k |T_k| ∇φ_i × (∇×v − ξ)_k.
  Eigen::VectorXd res17;
  Eigen::MatrixXd res18;
  right_hand_sides(
      m, g, inc, n, [&](std::size_t k) { return Eigen::Vector3d(r.grad_u[k] - r.xi[k]); },
      [&](std::size_t k) { return Eigen::Vector3d(r.curl_v[k] - r.xi[k]); }, res17, res18);
  const auto relative = [](double num, double den) { return den > 0.0 ? num / den : num; };
  r.report.residual_eq17 = relative(res17.norm(), bu.norm());
  r.report.residual_eq18 = relative(res18.norm(), b18.norm());
  return r;
}

}  // namespace gs::analysis
