// Smoothed-aggregation algebraic multigrid: aggregation by strong connections, a tentative
// prolongation by the constant on each aggregate, smoothed by one damped Jacobi step, Galerkin
// coarse matrices, a symmetric V-cycle with damped Jacobi sweeps (Vaněk, Mandel & Brezina 1996).
#include "aggregation_amg.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

using RowMat = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

// A·X for a few columns, rows on the threads (each row's sum in the matrix's order: the same
// result for any number of threads).
Eigen::MatrixXd times(const RowMat& a, const Eigen::MatrixXd& x) {
  const Eigen::Index rows = a.rows(), cols = x.cols();
  Eigen::MatrixXd y(rows, cols);
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
#pragma omp parallel for schedule(static)
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      double s = 0.0;
      for (int e = outer[i]; e < outer[i + 1]; ++e) s += val[e] * x(inner[e], c);
      y(i, c) = s;
    }
  }
  return y;
}

// λ_max(D⁻¹A) by power iteration from a fixed start (a lower bound, close after a few steps).
double largest_eigenvalue(const RowMat& a, const Eigen::VectorXd& inv_diag) {
  const Eigen::Index n = a.rows();
  Eigen::MatrixXd q(n, 1);
  for (Eigen::Index i = 0; i < n; ++i) q(i, 0) = 1.0 + 0.37 * static_cast<double>(i % 11);
  q /= q.norm();
  double lambda = 1.0;
  for (int it = 0; it < 15; ++it) {
    Eigen::MatrixXd z = inv_diag.asDiagonal() * times(a, q);
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
std::vector<int> aggregates(const RowMat& a, const Eigen::VectorXd& diag, double strength,
                            int& count) {
  const Eigen::Index n = a.rows();
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* val = a.valuePtr();
  auto strong = [&](Eigen::Index i, int e) {
    const int j = inner[e];
    return j != i && std::abs(val[e]) >= strength * std::sqrt(diag(i) * diag(j));
  };
  std::vector<int> agg(static_cast<std::size_t>(n), -1);
  count = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    bool free = true;
    for (int e = outer[i]; e < outer[i + 1] && free; ++e)
      if (strong(i, e) && agg[static_cast<std::size_t>(inner[e])] >= 0) free = false;
    if (!free) continue;
    agg[static_cast<std::size_t>(i)] = count;
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      if (strong(i, e)) agg[static_cast<std::size_t>(inner[e])] = count;
    ++count;
  }
  const std::vector<int> first = agg;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    double best = 0.0;
    for (int e = outer[i]; e < outer[i + 1]; ++e) {
      const int g = first[static_cast<std::size_t>(inner[e])];
      if (strong(i, e) && g >= 0 && std::abs(val[e]) > best) {
        best = std::abs(val[e]);
        agg[static_cast<std::size_t>(i)] = g;
      }
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (agg[static_cast<std::size_t>(i)] >= 0) continue;
    agg[static_cast<std::size_t>(i)] = count;
    for (int e = outer[i]; e < outer[i + 1]; ++e)
      if (strong(i, e) && agg[static_cast<std::size_t>(inner[e])] < 0)
        agg[static_cast<std::size_t>(inner[e])] = count;
    ++count;
  }
  return agg;
}

Eigen::MatrixXd cycle(const AmgHierarchy& h, std::size_t l, const Eigen::MatrixXd& b) {
  if (l + 1 == h.levels.size()) return h.coarsest.solve(b);
  const AmgLevel& L = h.levels[l];
  const auto d = L.inv_diag.asDiagonal();
  Eigen::MatrixXd x = L.omega * (d * b);
  for (int s = 1; s < h.sweeps; ++s) x += L.omega * (d * (b - times(L.a, x)));
  x += times(L.p, cycle(h, l + 1, times(L.r, b - times(L.a, x))));
  for (int s = 0; s < h.sweeps; ++s) x += L.omega * (d * (b - times(L.a, x)));
  return x;
}

}  // namespace

AmgHierarchy build_amg(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a0,
                       const AmgOptions& o) {
  if (a0.rows() != a0.cols())
    throw std::invalid_argument("AMG: matrix not square (" + std::to_string(a0.rows()) + "x" +
                                std::to_string(a0.cols()) + ")");
  AmgHierarchy h;
  h.sweeps = std::max(1, o.sweeps);
  RowMat a = a0;
  a.makeCompressed();
  while (true) {
    AmgLevel L;
    L.a = std::move(a);
    const Eigen::VectorXd diag = L.a.diagonal();
    if (diag.size() > 0 && !(diag.minCoeff() > 0.0))
      throw std::invalid_argument("AMG: non-positive diagonal entry (" +
                                  std::to_string(diag.minCoeff()) + ")");
    L.inv_diag = diag.cwiseInverse();
    int nc = 0;
    std::vector<int> agg;
    if (L.a.rows() > o.coarsest && static_cast<int>(h.levels.size()) + 1 < o.max_levels)
      agg = aggregates(L.a, diag, o.strength, nc);
    if (agg.empty() || nc >= L.a.rows()) {  // (the coarsest level: small, or no coarsening)
      h.levels.push_back(std::move(L));
      break;
    }
    // P = (I − ω D⁻¹A) P_t, P_t the constant on each aggregate; the next level RᵀAP, R = Pᵀ.
    L.omega = 4.0 / (3.0 * largest_eigenvalue(L.a, L.inv_diag));
    RowMat pt(L.a.rows(), nc);
    std::vector<Eigen::Triplet<double, int>> t;
    t.reserve(agg.size());
    for (std::size_t i = 0; i < agg.size(); ++i) t.emplace_back(static_cast<int>(i), agg[i], 1.0);
    pt.setFromTriplets(t.begin(), t.end());
    RowMat smooth = L.inv_diag.asDiagonal() * (L.a * pt);
    smooth *= L.omega;
    L.p = pt - smooth;
    L.p.prune(0.0);
    L.r = L.p.transpose();
    a = L.r * (L.a * L.p);
    a.makeCompressed();
    h.levels.push_back(std::move(L));
  }
  h.coarsest.compute(Eigen::MatrixXd(h.levels.back().a));
  if (h.coarsest.info() != Eigen::Success)
    throw std::invalid_argument("AMG: coarsest matrix not positive definite");
  return h;
}

Eigen::MatrixXd amg_vcycle(const AmgHierarchy& h, const Eigen::MatrixXd& b) {
  return cycle(h, 0, b);
}

Eigen::MatrixXd amg_pcg(const AmgHierarchy& h, const Eigen::MatrixXd& b, double tolerance,
                        int max_iterations, int& iterations, bool& converged) {
  if (h.levels.empty()) throw std::invalid_argument("AMG: empty hierarchy");
  const RowMat& a = h.levels.front().a;
  const Eigen::Index cols = b.cols();
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(b.rows(), cols);
  Eigen::MatrixXd r = b;
  std::vector<char> done(static_cast<std::size_t>(cols), 0);
  Eigen::VectorXd bnorm = b.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < cols; ++c) done[static_cast<std::size_t>(c)] = bnorm(c) == 0.0;
  iterations = 0;
  converged = true;
  auto all_done = [&] {
    return std::all_of(done.begin(), done.end(), [](char d) { return d != 0; });
  };
  if (all_done()) return x;
  Eigen::MatrixXd z = amg_vcycle(h, r);
  Eigen::MatrixXd p = z;
  Eigen::VectorXd rz = (r.array() * z.array()).colwise().sum().transpose();
  for (int it = 1; it <= max_iterations; ++it) {
    const Eigen::MatrixXd ap = times(a, p);
    iterations = it;
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (done[static_cast<std::size_t>(c)]) continue;
      const double pap = p.col(c).dot(ap.col(c));
      if (!(pap > 0.0) || !(rz(c) > 0.0)) {  // (breakdown: no further progress possible)
        done[static_cast<std::size_t>(c)] = 1;
        converged = false;
        continue;
      }
      const double alpha = rz(c) / pap;
      x.col(c) += alpha * p.col(c);
      r.col(c) -= alpha * ap.col(c);
      if (r.col(c).norm() <= tolerance * bnorm(c)) done[static_cast<std::size_t>(c)] = 1;
    }
    if (all_done()) return x;
    z = amg_vcycle(h, r);
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (done[static_cast<std::size_t>(c)]) continue;
      const double rz_new = r.col(c).dot(z.col(c));
      p.col(c) = z.col(c) + (rz_new / rz(c)) * p.col(c);
      rz(c) = rz_new;
    }
  }
  converged = false;
  return x;
}

}  // namespace gs::analysis
