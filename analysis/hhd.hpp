// Helmholtz–Hodge decomposition (HHD) of a piecewise-constant vector field on a Delaunay mesh
// (seed 000 §4.1–4.2, eq 9–18, after Tong et al. 2003):
//
//   ξ = ∇u + ∇×v + h                                                          (eq 9)
//
// ξ_k is constant on each simplex T_k (the mean of its vertex vectors); u and v are P1 (nodal,
// piecewise linear), so ∇u and ∇×v are constant per simplex and h = ξ − ∇u − ∇×v. The N-P
// boundary conditions u = 0, v = 0 hold at the Dirichlet nodes (the hull; with ghost nodes the
// ghost hull). In 2D v is the scalar v_z and ∇×v = (∂v/∂y, −∂v/∂x).
//
// What is solved (docs/hhd.md has the derivations):
//  * u, every solver: eq 17, Σ_k |T_k| (∇φ_i)_k·(∇u)_k = Σ_k |T_k| (∇φ_i)_k·ξ_k, i.e. K u = b with
//    K the P1 stiffness matrix (SPD once the Dirichlet rows are removed): the L2 projection of ξ
//    onto gradients (eq 10, 12, 14, 15).
//  * v, path (a) `bicgstab` (the paper's): eq 18 exactly as written, BiCGSTAB (Eigen, diagonal
//    preconditioner). In 3D its matrix is −CᵀMC (C the P1 curl, M = diag|T_k|): the normal
//    equations of eq 11; negative definite on generic meshes but conditioned like h^-4.
//  * v, path (b) `cholmod` and its variants `ldlt` (path c: Eigen SimplicialLDLT) and `cg`
//    (CG preconditioned by a smoothed-aggregation AMG V-cycle): the component-wise Laplacian K v_a
//    = (Σ_k |T_k| ξ_k × (∇φ_i)_k)_a with the same K as for u, factored once for all 1 + (1 or 3)
//    right-hand sides. Since K⊗I = CᵀMC + DᵀMD exactly for P1 fields vanishing on the hull (D the
//    P1 divergence), this minimises ‖∇×v − ξ‖² + ‖∇·v‖² (Coulomb gauge as a penalty): identical to
//    eq 18 in 2D, identical in 3D when the minimiser is divergence-free; otherwise ⟨∇×v, h⟩ =
//    ‖∇·v‖², reported.
//  * v, `projection` and `projection-amg` (`auto`, the default in 3D): eq 18's system
//    CᵀMC v = CᵀMξ itself (the paper's L2 projection, path (a)'s answer), by conjugate gradients
//    preconditioned with the vector Laplacian (path (b)'s factor, or one AMG V-cycle) and block
//    Jacobi: ∇×v ⊥ h and ∇×v ⊥ ∇u to round-off. In 2D it is path (b).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace gs::analysis {

enum class HhdSolver {
  Auto,        // 3D: ProjectionAmg; 2D: Cholmod (in 2D path (b) is eq 18 exactly)
  Projection,  // eq 18 as the paper defines it, solved as a projection (3D: PCG on CᵀMC with the
               // Laplacian factor and block Jacobi, symmetric multiplicative; 2D: path (b))
  ProjectionAmg,  // the same projection with one aggregation-AMG V-cycle in place of the
                  // Laplacian factor (added to the block Jacobi: no factor, 1.9–3.1× faster, half
                  // the memory), and u, path (b)'s v by AMG-preconditioned CG
  Cholmod,   // path (b): Laplacian, CHOLMOD Cholesky (supernodal/simplicial as CHOLMOD picks)
  Ldlt,      // path (c): Laplacian, Eigen SimplicialLDLT (AMD ordering)
  Cg,        // path (b) iterative: Laplacian, CG preconditioned by an aggregation-AMG V-cycle
  BiCgStab,  // path (a): eq 17 and eq 18 as written, BiCGSTAB (the paper's)
};
const char* hhd_solver_name(HhdSolver s);
/// Default relative residual of the iterative paths `cg` and `bicgstab`, per system.
inline constexpr double kHhdTolerance = 1e-10;
/// Default relative residual of eq 18 for `projection` in 3D: ∇×v is then within ~0.5× this of
/// the exact projection (measured, docs/hhd.md), ∇×v ⊥ h to round-off whatever the tolerance.
inline constexpr double kHhdProjectionTolerance = 1e-7;
/// "auto", "projection", "projection-amg", "cholmod", "ldlt", "cg", "bicgstab"; throws
/// std::invalid_argument
/// listing them.
HhdSolver hhd_solver_from_name(const std::string& name);

struct HhdOptions {
  HhdSolver solver = HhdSolver::Auto;
  double tolerance = 0.0;  // iterative solvers: relative residual ‖r‖/‖b‖ per system; 0: default
  int max_iterations = 10000;  // iterative solvers, per system
  /// Called between the phases and every 8 iterations of the projection's and the AMG path's
  /// conjugate gradients (`projection`, `projection-amg`; the direct and Eigen iterative paths
  /// finish their solve first); may throw to abandon the decomposition (Python's Ctrl-C).
  /// Changes no result.
  std::function<void()> poll;
};

/// The mesh of the decomposition: nodes (2D: x, y used, z ignored), simplices in the
/// DelaunayMesh layout, and the Dirichlet nodes (u = 0, v = 0).
struct HhdMesh {
  int dim = 3;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<std::int32_t, 4>> simplices;
  std::vector<std::uint8_t> dirichlet;
};

/// Per simplex: |T_k| and (∇φ_a)_k of its vertices (seed 000, text of eq 17–18: the normal of
/// the face opposite vertex a pointing towards a, of length area(f)/(3|T_k|) in 3D and
/// length(f)/(2|T_k|) in 2D; z = 0 in 2D). A simplex flat in floating point (shape quality
/// <= 1e-12) gets measure 0 and zero gradients: it has no weight in any integral.
struct P1Geometry {
  std::vector<double> measure;
  std::vector<std::array<Eigen::Vector3d, 4>> gradient;
};
P1Geometry p1_geometry(const HhdMesh& mesh);

/// ξ_k = mean of the vertex vectors (seed 000 §4.1; 2D: the z components are dropped).
std::vector<Eigen::Vector3d> simplex_mean(const HhdMesh& mesh,
                                          const std::vector<Eigen::Vector3d>& nodal);
/// ∇u per simplex of the P1 interpolant of nodal values u.
std::vector<Eigen::Vector3d> p1_gradient(const HhdMesh& mesh, const P1Geometry& g,
                                         const Eigen::VectorXd& u);
/// ∇×v per simplex: 3D v is N×3 and ∇×v = Σ_a (∇φ_a) × v_a; 2D v is N×1 (v_z) and
/// ∇×v = Σ_a v_a (∂_y φ_a, −∂_x φ_a, 0).
std::vector<Eigen::Vector3d> p1_curl(const HhdMesh& mesh, const P1Geometry& g,
                                     const Eigen::MatrixXd& v);
/// ∇·v per simplex of a 3D P1 vector field (N×3). 2D (N×1, v_z): zeros.
std::vector<double> p1_divergence(const HhdMesh& mesh, const P1Geometry& g,
                                  const Eigen::MatrixXd& v);

struct HhdReport {
  std::string solver;        // the one used (auto resolved)
  double tolerance = 0.0;    // the relative residual the iterative solver aimed at (0: direct)
  std::size_t unknowns = 0;  // nodes solved for (not Dirichlet, in a simplex of positive measure)
  int iterations_u = 0, iterations_v = 0;  // iterative solvers (v: the most over components)
  bool converged = true;                   // iterative solvers reached `tolerance`
  // ‖lhs − rhs‖ / ‖rhs‖ of eq 17 and of eq 18 as written, over the solved nodes, evaluated
  // matrix-free from the final fields whatever the solver (path (b) in 3D solves a different
  // system for v, so its eq 18 residual measures the gauge difference).
  double residual_eq17 = 0.0, residual_eq18 = 0.0;
  double seconds_assembly = 0.0, seconds_factor = 0.0, seconds_solve = 0.0;
};

struct HhdResult {
  int dim = 3;
  Eigen::VectorXd u;  // scalar potential per node (units of ξ × length)
  Eigen::MatrixXd v;  // vector potential per node: N×3, or N×1 (v_z) in 2D
  // The potential the vortex centres and tubes use (seed 000 §5–6): `projection` in 3D gives
  // path (b)'s v, the solution of (K⊗I) w = CᵀMξ = CᵀM(∇×v), i.e. the potential of eq 18's curl
  // part with ∇·w penalised (Coulomb gauge). Eq 18 fixes only ∇×v: its own P1 v carries a
  // discretisation gauge (‖∇·v‖ ≫ ‖∇×v‖ on irregular meshes) that would make |v| maxima noise.
  // Every other path: equal to v.
  Eigen::MatrixXd v_coulomb;
  std::vector<double> measure;
  std::vector<Eigen::Vector3d> xi, grad_u, curl_v, harmonic;  // per simplex (z = 0 in 2D)
  // Measure-weighted L2 norms ‖a‖ = sqrt(Σ_k |T_k| a_k·a_k) and inner products of the parts.
  double norm_xi = 0.0, norm_grad_u = 0.0, norm_curl_v = 0.0, norm_harmonic = 0.0;
  double norm_div_v = 0.0;  // ‖∇·v‖ (3D; 0 in 2D)
  double dot_grad_curl = 0.0, dot_grad_harmonic = 0.0, dot_curl_harmonic = 0.0;
  HhdReport report;
};

/// Decomposes the per-simplex field `xi` (one vector per mesh simplex). Throws
/// std::invalid_argument for sizes that do not match, non-finite input, a mesh with no node to
/// solve for, or a failed factorization.
HhdResult helmholtz_hodge(const HhdMesh& mesh, const std::vector<Eigen::Vector3d>& xi,
                          const HhdOptions& options = {});

}  // namespace gs::analysis
