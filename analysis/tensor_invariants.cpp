// Stress and strain invariants (seed 003 §2.1.3, §2.2.3, eq 10–12, 17, 23–26, App. 1–2).
#include "tensor_invariants.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = 180.0 / std::numbers::pi;

/// Eigen-decomposition of a symmetric matrix, values in decreasing order.
void sorted_eigen(const Eigen::Matrix3d& a, Eigen::Vector3d& values, Eigen::Matrix3d& vectors) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(a);
  for (int k = 0; k < 3; ++k) {  // Eigen sorts increasingly
    values[k] = es.eigenvalues()[2 - k];
    vectors.col(k) = es.eigenvectors().col(2 - k);
  }
}

double ratio(double num, double den) {
  return den != 0.0 ? num / den : kNaN;
}

/// Lode angle (deg) from b, tan(theta) = sqrt(3) b / (2 - b) (seed 003 §2.2.3, eq 23).
double lode_from_b(double b) {
  return std::isfinite(b) ? std::atan2(std::sqrt(3.0) * b, 2.0 - b) * kDeg : kNaN;
}

}  // namespace

StressInvariants stress_invariants(const Eigen::Matrix3d& sigma, int dim) {
  StressInvariants s;
  const Eigen::Matrix3d sym = 0.5 * (sigma + sigma.transpose());
  const double norm = sigma.norm();
  s.asymmetry = norm > 0.0 ? 0.5 * (sigma - sigma.transpose()).norm() / norm : 0.0;
  if (dim == 2) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(sym.topLeftCorner<2, 2>());
    const double s1 = es.eigenvalues()[1], s2 = es.eigenvalues()[0];
    s.principal = Eigen::Vector3d(s1, s2, kNaN);
    s.directions.topLeftCorner<2, 1>() = es.eigenvectors().col(1);
    s.directions.block<2, 1>(0, 1) = es.eigenvectors().col(0);
    s.directions(2, 2) = 1.0;
    s.p = 0.5 * (s1 + s2);
    s.q = 0.5 * (s1 - s2);
    s.eta = ratio(s.q, s.p);
    s.b = s.lode_deg = kNaN;
    s.j2d = s.q * s.q;
    s.j3d = kNaN;
    s.phi_mob_deg = s.p > 0.0 ? std::asin(std::min(1.0, s.q / s.p)) * kDeg : kNaN;
    return s;
  }
  sorted_eigen(sym, s.principal, s.directions);
  s.p = sym.trace() / 3.0;
  const Eigen::Matrix3d dev = sym - s.p * Eigen::Matrix3d::Identity();
  s.j2d = 0.5 * (dev * dev).trace();
  s.j3d = (dev * dev * dev).trace() / 3.0;
  s.q = std::sqrt(3.0 * s.j2d);
  s.eta = ratio(s.q, s.p);
  const double s1 = s.principal[0], s2 = s.principal[1], s3 = s.principal[2];
  s.b = s1 > s3 ? (s2 - s3) / (s1 - s3) : kNaN;
  s.lode_deg = lode_from_b(s.b);
  s.phi_mob_deg =
      s1 + s3 > 0.0 ? std::asin(std::clamp((s1 - s3) / (s1 + s3), -1.0, 1.0)) * kDeg : kNaN;
  return s;
}

StrainInvariants strain_invariants(const Eigen::Matrix3d& F) {
  if (!F.allFinite()) throw std::invalid_argument("deformation gradient is not finite");
  StrainInvariants e;
  e.J = F.determinant();
  if (!(e.J > 0.0)) {
    throw std::invalid_argument("deformation gradient has det F <= 0 (" + std::to_string(e.J) +
                                ")");
  }
  e.eps_v = 1.0 - e.J;  // eq 11
  const double cbrt_j = std::cbrt(e.J);
  e.Fv = cbrt_j * Eigen::Matrix3d::Identity();  // eq 12
  e.Fd = F / cbrt_j;
  // Polar decomposition: U = sqrt(F^T F), R = F U^-1.
  Eigen::Vector3d c;
  Eigen::Matrix3d q;
  sorted_eigen(F.transpose() * F, c, q);
  const Eigen::Vector3d stretch = c.cwiseSqrt();  // decreasing
  e.U = q * stretch.asDiagonal() * q.transpose();
  e.R = F * q * stretch.cwiseInverse().asDiagonal() * q.transpose();
  e.biot = Eigen::Matrix3d::Identity() - e.U;
  // Principal Biot strains e1 >= e2 >= e3 belong to the stretches in increasing order.
  for (int k = 0; k < 3; ++k) {
    e.principal[k] = 1.0 - stretch[2 - k];
    e.directions.col(k) = q.col(2 - k);
  }
  const Eigen::Vector3d ud = stretch / cbrt_j;  // principal values of Ud
  const double mean = ud.sum() / 3.0;
  const double j2d = 0.5 * (ud.array() - mean).square().sum();
  e.eps_q = 2.0 * std::sqrt(j2d / 3.0);  // §2.1.3
  const double e1 = e.principal[0], e2 = e.principal[1], e3 = e.principal[2];
  e.b_eps = e1 > e3 ? (e2 - e3) / (e1 - e3) : kNaN;
  e.b_stretch =
      stretch[0] > stretch[2] ? (stretch[1] - stretch[2]) / (stretch[0] - stretch[2]) : kNaN;
  e.lode_deg = lode_from_b(e.b_eps);
  return e;
}

Eigen::Vector3d deviatoric_stretch(double eps_q, double b_stretch) {
  // eq 23: Lode angle; sqrt(J2D(Fd)) = sqrt(3) eps_q / 2.
  const double theta = std::atan2(std::sqrt(3.0) * b_stretch, 2.0 - b_stretch);
  const double sj = std::sqrt(3.0) * eps_q / 2.0;
  const double k = 2.0 / std::sqrt(3.0) * sj;
  const double a = k * std::cos(theta), b = k * std::cos(2.0 * std::numbers::pi / 3.0 - theta),
               c = k * std::cos(2.0 * std::numbers::pi / 3.0 + theta);
  // eq 25: x^3 - J2D x + J3D = 1 with x = J1(Fd)/3, J2D = -(ab + bc + ca), J3D = abc; eq 26 is
  // Cardano's root, taken here in the numerically safe form of Newton from x = 1.
  const double j2d = -(a * b + b * c + c * a), j3d = a * b * c;
  double x = 1.0;
  for (int it = 0; it < 100; ++it) {
    const double f = x * x * x - j2d * x + j3d - 1.0, df = 3.0 * x * x - j2d;
    const double dx = f / df;
    x -= dx;
    if (std::abs(dx) < 1e-17) break;
  }
  return Eigen::Vector3d(x + a, x + b, x + c);  // eq 24
}

}  // namespace gs::analysis
