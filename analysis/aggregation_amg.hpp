// Smoothed-aggregation algebraic multigrid (Vaněk, Mandel & Brezina, Computing 56 (1996)
// 179–196) for a symmetric positive definite sparse matrix such as the P1 Laplacian K of the
// Helmholtz–Hodge decomposition (seed 000 eq 17): one symmetric V-cycle is a fixed SPD
// preconditioner for conjugate gradients, and stands in for the exact K⁻¹ in the preconditioner
// of eq 18's projection (docs/hhd.md). Written here because no Debian C++ library offers one
// without MPI (hypre's BoomerAMG needs MPI initialised in the calling process).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Sparse>
#include <functional>
#include <vector>

namespace gs::analysis {

struct AmgOptions {
  double strength = 0.02;  // i, j strongly connected when |a_ij| >= strength·sqrt(a_ii a_jj)
  int coarsest = 400;      // a level this small (unknowns) is solved directly (dense Cholesky)
  int sweeps = 1;          // damped Jacobi sweeps before and after the coarse correction
  int max_levels = 12;
};

/// One level: its matrix, the prolongation from the next (coarser) level and its transpose,
/// the inverse diagonal and the Jacobi damping 4/(3 λ_max(D⁻¹A)).
struct AmgLevel {
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> a, p, r;
  Eigen::VectorXd inv_diag;
  double omega = 0.0;
};

struct AmgHierarchy {
  std::vector<AmgLevel> levels;          // finest first; the last one's a is the coarsest
  Eigen::LLT<Eigen::MatrixXd> coarsest;  // dense Cholesky of the coarsest matrix
  int sweeps = 1;
};

/// Builds the hierarchy of a symmetric positive definite matrix (full symmetric storage).
/// Deterministic: the same matrix gives the same hierarchy. Throws std::invalid_argument for a
/// matrix that is not square or has a non-positive diagonal entry.
AmgHierarchy build_amg(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a,
                       const AmgOptions& options = {});
/// The same from a row-major matrix given up to the hierarchy (its finest level takes its
/// storage: no copy; `a` is left empty).
AmgHierarchy build_amg(Eigen::SparseMatrix<double, Eigen::RowMajor, int>&& a,
                       const AmgOptions& options = {});

/// One symmetric V-cycle from a zero initial guess applied to each column of b: an SPD
/// approximation of A⁻¹b (the columns share each pass over the matrices).
Eigen::MatrixXd amg_vcycle(const AmgHierarchy& h, const Eigen::MatrixXd& b);

/// A block of right-hand sides with each unknown's columns side by side (row-major).
using AmgBlock = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// The V-cycle's blocks on every level (solution, right-hand side, scratch): kept by a caller
/// that cycles many times, so that they are allocated once.
struct AmgWorkspace {
  std::vector<AmgBlock> x, b, t;
};
/// amg_vcycle for a row-major block (no change of layout, no copy: x may be any row-major
/// matrix of b's size, such as an N×3 one): x ≈ A⁻¹b, the same bits; `w` holds the blocks
/// between calls; x must not share storage with b. The row sums of three or four columns use
/// AVX2 where the CPU has it (GS_SIMD=generic: the plain loop; the same bits either way). Throws
/// std::invalid_argument when x is not b's size.
void amg_vcycle(const AmgHierarchy& h, const Eigen::Ref<const AmgBlock>& b, Eigen::Ref<AmgBlock> x,
                AmgWorkspace& w);

/// Conjugate gradients on A x = b (A: the matrix the hierarchy was built from) for every column
/// of b at once (each column its own step lengths, frozen once it converged), preconditioned by
/// amg_vcycle, from x = 0, until every column's relative residual ‖b − A x‖ ≤ tolerance ‖b‖ or
/// max_iterations. Returns x (each column the same bits as if solved alone); `iterations` is
/// the number of iterations run, `converged` whether every column reached the tolerance,
/// `column_iterations` (if given) the iterations each column took. `poll` (if set) is called
/// every 8 iterations, outside any parallel region, and may throw to stop the solve (Ctrl-C in
/// the Python package); it does not change the iterates.
Eigen::MatrixXd amg_pcg(const AmgHierarchy& h, const Eigen::MatrixXd& b, double tolerance,
                        int max_iterations, int& iterations, bool& converged,
                        std::vector<int>* column_iterations = nullptr,
                        const std::function<void()>& poll = {});

}  // namespace gs::analysis
