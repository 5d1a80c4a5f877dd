// Speed against error of the Helmholtz–Hodge decomposition (seed 000 eq 9–18) in 3D, every solver
// path in the same process (path (a) the paper's BiCGSTAB on eq 18 as written; path (b) the
// Laplacian with the gauge as a penalty, CHOLMOD or AMG-preconditioned CG; path (c) Eigen LDLT;
// `projection-amg` eq 18 by PCG with an AMG V-cycle, the default in 3D, and `projection` the same
// with the Laplacian's Cholesky factor), on two kinds of input:
//  * lattice: jittered lattices of the unit cube and the analytic field of
//    tests/analysis/hhd_test_fields.hpp (ξ = ∇U + ∇×V + c, V divergence-free): the L2 error of
//    each part against the exact decomposition;
//  * random: N uniformly random points (slivers included) and issue 20's field (a Lamb–Oseen
//    vortex crossing the hull, a Gaussian source, a translation): |∇×v|, |h|, cos(∇×v, h),
//    cos(∇u, h), ‖∇·v‖ and the relative difference of ∇×v from path (a)'s where it converged.
// Then the whole pipeline (mesh, ξ, HHD, extrema, tubes) on the 5.5e4-node lattice and on 5.6e4
// random points (issue 23 item 7), with each 3D path but bicgstab and ldlt (GS_BENCH_PATHS
// applies).
//   build/bin/bench_hhd [N ...]      (default 10000 56000 200000)
// Environment: GS_BENCH_MESH (lattice, random or both: default both; the tables and the pipeline),
// GS_BENCH_PATHS (comma list of bicgstab, projection, projection-amg, cholmod, cg, ldlt; default
// all), GS_BENCH_LDLT_MAX (largest N for LDLT, default 60000: its AMD ordering fills in far more
// than CHOLMOD's METIS), GS_BENCH_BICGSTAB_ITERATIONS (cap of path (a), default 3000; a capped run
// is reported as not converged with its residual), GS_BENCH_PIPELINE=0 skips the pipeline (N > 1
// runs each path N times in turn: the first run in a process pays for first touches, the later ones
// are warm).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "delaunay_mesh.hpp"
#include "hhd.hpp"
#include "hhd_test_fields.hpp"
#include "vortex_analysis.hpp"

namespace {

using namespace gs::analysis;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

long env_long(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v ? std::atol(v) : fallback;
}

std::string env_string(const char* name, const char* fallback) {
  const char* v = std::getenv(name);
  return v ? v : fallback;
}

bool wanted(const std::string& path) {
  const std::string list = env_string("GS_BENCH_PATHS", "");
  if (list.empty()) return true;
  std::stringstream s(list);
  std::string item;
  while (std::getline(s, item, ','))
    if (item == path) return true;
  return false;
}

double cosine(double dot, double a, double b) {
  return a > 0.0 && b > 0.0 ? dot / (a * b) : 0.0;
}

struct Run {
  double seconds = 0.0;
  HhdResult r;
};

Run run(const HhdMesh& m, const std::vector<Eigen::Vector3d>& xi, HhdSolver solver,
        int max_iterations) {
  HhdOptions o;
  o.solver = solver;
  o.max_iterations = max_iterations;
  const auto t0 = Clock::now();
  Run out;
  out.r = helmholtz_hodge(m, xi, o);
  out.seconds = since(t0);
  return out;
}

void print_head(const char* name, const Run& p) {
  const auto& r = p.r.report;
  std::printf("  %-26s %8.3f s (assembly %.3f, factor %.3f, solve %.3f)", name, p.seconds,
              r.seconds_assembly, r.seconds_factor, r.seconds_solve);
  if (r.iterations_u + r.iterations_v > 0) std::printf(" it %d/%d", r.iterations_u, r.iterations_v);
  if (!r.converged) std::printf(" NOT CONVERGED");
}

// Measure-weighted relative L2 difference of two per-simplex fields.
double relative_difference(const HhdResult& a, const HhdResult& b) {
  double d = 0.0, n = 0.0;
  for (std::size_t k = 0; k < a.measure.size(); ++k) {
    d += a.measure[k] * (a.curl_v[k] - b.curl_v[k]).squaredNorm();
    n += a.measure[k] * b.curl_v[k].squaredNorm();
  }
  return n > 0.0 ? std::sqrt(d / n) : 0.0;
}

void print_parts(const HhdResult& r, const HhdResult* reference) {
  std::printf(
      "\n      |curl v| %.4f |h| %.4f cos(curl,h) %+.1e cos(grad,h) %+.1e cos(grad,curl) %+.1e "
      "|div v| %.3g eq18 res %.1e",
      r.norm_curl_v, r.norm_harmonic, cosine(r.dot_curl_harmonic, r.norm_curl_v, r.norm_harmonic),
      cosine(r.dot_grad_harmonic, r.norm_grad_u, r.norm_harmonic),
      cosine(r.dot_grad_curl, r.norm_grad_u, r.norm_curl_v), r.norm_div_v, r.report.residual_eq18);
  if (reference) std::printf(" curl vs path a %.1e", relative_difference(r, *reference));
  std::printf("\n");
}

struct Path {
  const char* key;
  const char* label;
  HhdSolver solver;
};

const std::vector<Path>& paths() {
  static const std::vector<Path> p = {
      {"bicgstab", "path a  bicgstab (paper)", HhdSolver::BiCgStab},
      {"projection", "projection (factor)", HhdSolver::Projection},
      {"projection-amg", "projection-amg (default)", HhdSolver::ProjectionAmg},
      {"cholmod", "path b  cholmod", HhdSolver::Cholmod},
      {"cg", "path b' cg (AMG)", HhdSolver::Cg},
      {"ldlt", "path c  ldlt (Eigen)", HhdSolver::Ldlt}};
  return p;
}

// Every wanted path on one mesh; path (a) first, as the reference of the others' ∇×v.
void all_paths(const HhdMesh& m, const std::vector<Eigen::Vector3d>& xi,
               const gs::test::AnalyticField* exact) {
  const long ldlt_max = env_long("GS_BENCH_LDLT_MAX", 60000);
  const int bicg_max = static_cast<int>(env_long("GS_BENCH_BICGSTAB_ITERATIONS", 3000));
  std::optional<Run> a;
  double seconds_b = 0.0, seconds_proj = 0.0;
  for (const auto& p : paths()) {
    if (!wanted(p.key)) continue;
    if (p.solver == HhdSolver::Ldlt && static_cast<long>(m.points.size()) > ldlt_max) {
      std::printf("  %-26s skipped (N > GS_BENCH_LDLT_MAX = %ld)\n", p.label, ldlt_max);
      continue;
    }
    const Run r = run(m, xi, p.solver, p.solver == HhdSolver::BiCgStab ? bicg_max : 100000);
    print_head(p.label, r);
    if (exact) {
      double eg = 0, ec = 0, eh = 0, ng = 0, nc = 0, nh = 0;
      for (std::size_t k = 0; k < m.simplices.size(); ++k) {
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (std::size_t q = 0; q < 4; ++q)
          x += m.points[static_cast<std::size_t>(m.simplices[k][q])];
        x /= 4.0;
        const double w = r.r.measure[k];
        eg += w * (r.r.grad_u[k] - exact->grad_U(x)).squaredNorm();
        ec += w * (r.r.curl_v[k] - exact->curl_V(x)).squaredNorm();
        eh += w * (r.r.harmonic[k] - exact->c).squaredNorm();
        ng += w * exact->grad_U(x).squaredNorm();
        nc += w * exact->curl_V(x).squaredNorm();
        nh += w * exact->c.squaredNorm();
      }
      std::printf("  err grad %.3e curl %.3e h %.3e", std::sqrt(eg / ng), std::sqrt(ec / nc),
                  std::sqrt(eh / nh));
    }
    print_parts(r.r, a && a->r.report.converged ? &a->r : nullptr);
    if (p.solver == HhdSolver::BiCgStab) a = r;
    if (p.solver == HhdSolver::Cg) seconds_b = r.seconds;
    if (p.solver == HhdSolver::ProjectionAmg) seconds_proj = r.seconds;
  }
  if (seconds_b > 0.0 && seconds_proj > 0.0) {
    std::printf("  ratio projection-amg (default) / path b' cg (AMG): %.1f",
                seconds_proj / seconds_b);
    if (a) std::printf("   path a / projection-amg: %.1f", a->seconds / seconds_proj);
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<long> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::atol(argv[i]));
  if (sizes.empty()) sizes = {10000, 56000, 200000};
  const std::string mesh_kind = env_string("GS_BENCH_MESH", "both");
  gs::test::AnalyticField f;
  f.dim = 3;
  for (const long target : sizes) {
    if (mesh_kind != "random") {
      const int n = static_cast<int>(std::lround(std::cbrt(static_cast<double>(target)))) - 1;
      auto t0 = Clock::now();
      const auto m = gs::test::box_mesh(3, n, 7);
      const double mesh_s = since(t0);
      std::vector<Eigen::Vector3d> nodal;
      for (const auto& p : m.points) nodal.push_back(f.xi(p));
      std::printf(
          "lattice N = %zu nodes, %zu tetrahedra (mesh %.2f s); xi = grad U + curl V + c, errors "
          "relative L2 against the exact parts\n",
          m.points.size(), m.simplices.size(), mesh_s);
      all_paths(m, simplex_mean(m, nodal), &f);
    }
    if (mesh_kind != "lattice") {
      auto t0 = Clock::now();
      const auto m = gs::test::random_cube_mesh(static_cast<std::size_t>(target), 1);
      const double mesh_s = since(t0);
      std::vector<Eigen::Vector3d> nodal;
      for (const auto& p : m.points) nodal.push_back(gs::test::vortex_source_translation(p));
      std::printf(
          "random N = %zu nodes, %zu tetrahedra (Delaunay %.2f s); issue 20's field (vortex "
          "across the hull + source + translation)\n",
          m.points.size(), m.simplices.size(), mesh_s);
      all_paths(m, simplex_mean(m, nodal), nullptr);
    }
    std::fflush(stdout);
  }
  const long pipeline_runs = env_long("GS_BENCH_PIPELINE", 1);
  if (pipeline_runs <= 0) return 0;
  // Whole pipeline on ~5.6e4 nodes: mesh + ξ + HHD + extrema + tubes, timed from the points.
  const gs::test::AnalyticField& field = f;
  for (const bool lattice : {true, false}) {
    if ((lattice && mesh_kind == "random") || (!lattice && mesh_kind == "lattice")) continue;
    const auto m = lattice ? gs::test::box_mesh(3, 37, 8) : gs::test::random_cube_mesh(56000, 1);
    std::vector<Eigen::Vector3d> nodal;
    for (const auto& p : m.points)
      nodal.push_back(lattice ? field.xi(p) : gs::test::vortex_source_translation(p));
    for (const auto& path : paths())
      for (long run = 0; run < pipeline_runs; ++run) {
        const HhdSolver solver = path.solver;
        if (solver == HhdSolver::BiCgStab || solver == HhdSolver::Ldlt || !wanted(path.key))
          continue;
        VortexAnalysisOptions o;
        o.hhd.solver = solver;
        const auto t0 = Clock::now();
        const auto a = analyze_vortices(m.points, nodal, 3, o);
        const double total = since(t0);
        const auto& r = a.hhd.report;
        const auto c = count_extrema(a.extrema, true);
        std::printf(
            "pipeline %s %zu nodes, %s: total %.3f s = Delaunay %.3f + assembly %.3f + factor "
            "%.3f + solve %.3f + detection %.3f (+ rest %.3f); %zu extrema (%zu significant), %zu "
            "tubes\n",
            lattice ? "lattice" : "random", m.points.size(), r.solver.c_str(), total,
            a.seconds_delaunay, r.seconds_assembly, r.seconds_factor, r.seconds_solve,
            a.seconds_detection,
            total - a.seconds_delaunay - r.seconds_assembly - r.seconds_factor - r.seconds_solve -
                a.seconds_detection,
            a.extrema.size(), c[0] + c[1] + c[2] + c[3], a.tubes.size());
        std::fflush(stdout);
      }
  }
  return 0;
}
