// Invariants of stress and deformation (seed 003, Li et al.: §2.1.3 and §2.2.3, eq 10–12, 17,
// 23–26, App. 1–2), compression positive as in the seed.
//
// Stress (symmetric part of sigma): p = J1/3, q = sqrt(3 J2D) (J2D = tr(s^2)/2, s the
// deviator), eta = q/p, b = (s2 - s3)/(s1 - s3) with s1 >= s2 >= s3 the principal stresses,
// Lode angle tan(theta) = sqrt(3) b / (2 - b) (0 deg: triaxial compression, 60 deg: extension),
// so that eq 17 rebuilds the principal stresses from p, eta, theta; mobilised friction angle
// sin(phi) = (s1 - s3)/(s1 + s3) (Mohr, seed 000 §3 and 004 use it for the specimen).
// In 2D (a 2D frame; in-plane 2x2 part): p = (s1 + s2)/2, q = (s1 - s2)/2 (radius of Mohr's
// circle), eta = q/p, sin(phi) = q/p; b and the Lode angle are undefined (NaN).
//
// Deformation gradient F (det F > 0): J = det F, volumetric strain eps_v = 1 - J (eq 11), the
// split F = Fv Fd with Fv = J^(1/3) I and Fd = J^(-1/3) F (eq 12); F = R U (polar); Biot strain
// eps = I - U (eq 2 with the rigid rotation R removed; compression positive); deviatoric strain
// eps_q = 2 sqrt(J2D(Ud)/3) with Ud = J^(-1/3) U (the rotation-free Fd); b_eps = (e2 - e3) /
// (e1 - e3) from the principal Biot strains e1 >= e2 >= e3; Lode angle of eq 23. App. 2 orders
// the principal stretches the other way (F^1 >= F^2 >= F^3, b_F = (F^2 - F^3)/(F^1 - F^3)); with
// eps = 1 - U this is b_F = 1 - b_eps, reported as `b_stretch`.
#pragma once

#include <Eigen/Core>

namespace gs::analysis {

struct StressInvariants {
  double p = 0.0, q = 0.0, eta = 0.0, b = 0.0, lode_deg = 0.0, phi_mob_deg = 0.0;
  double j2d = 0.0, j3d = 0.0;
  Eigen::Vector3d principal = Eigen::Vector3d::Zero();   // s1 >= s2 >= s3
  Eigen::Matrix3d directions = Eigen::Matrix3d::Zero();  // columns: n1, n2, n3
  double asymmetry = 0.0;  // |skew sigma| / |sigma| (0 for an exactly symmetric tensor)
};

/// Invariants of the symmetric part of sigma; dim = 2 uses the in-plane (x, y) block.
/// Undefined ratios (p = 0, s1 = s3, s1 + s3 <= 0) are NaN.
StressInvariants stress_invariants(const Eigen::Matrix3d& sigma, int dim = 3);

struct StrainInvariants {
  double J = 1.0, eps_v = 0.0, eps_q = 0.0, b_eps = 0.0, b_stretch = 0.0, lode_deg = 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();       // rotation of F = R U
  Eigen::Matrix3d U = Eigen::Matrix3d::Identity();       // right stretch
  Eigen::Matrix3d biot = Eigen::Matrix3d::Zero();        // I - U
  Eigen::Matrix3d Fv = Eigen::Matrix3d::Identity();      // J^(1/3) I
  Eigen::Matrix3d Fd = Eigen::Matrix3d::Identity();      // J^(-1/3) F
  Eigen::Vector3d principal = Eigen::Vector3d::Zero();   // Biot e1 >= e2 >= e3
  Eigen::Matrix3d directions = Eigen::Matrix3d::Zero();  // columns (reference configuration)
};

/// Invariants of a deformation gradient. Throws std::invalid_argument when det F <= 0 or F is
/// not finite.
StrainInvariants strain_invariants(const Eigen::Matrix3d& F);

/// Principal values F_d^1 >= F_d^2 >= F_d^3 of the deviatoric stretch with given eps_q and
/// b_F = (F^2 - F^3)/(F^1 - F^3) (App. 2, eq 23–26: Lode angle, then the real root of the cubic
/// det Fd = 1). Used to rebuild loading paths and to check strain_invariants.
Eigen::Vector3d deviatoric_stretch(double eps_q, double b_stretch);

}  // namespace gs::analysis
