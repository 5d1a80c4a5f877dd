// Contact stiffnesses of the YADE CohFrictMat law (seed 000 eq 1-7; seed 004 eqs 3.1-3.16).
#pragma once

namespace gs::solver {

/// Which radius scales the rolling-moment limit eta * R_roll * |Fn|.
enum class RollingRadius {
  Mean,  // (RA + RB) / 2 (seed 000 eq 7, seed 004 eq 3.16)
  Min,   // min(RA, RB), what YADE 2023.02a does
};

struct ContactStiffness {
  double kn = 0;                // N/m, normal
  double ks = 0;                // N/m, shear
  double kr = 0;                // N·m/rad, rolling (bending)
  double rolling_radius_m = 0;  // R_roll of the moment limit
};

/// Kn = Ec·2RA·RB/(RA+RB), Ks = νc·Kn, Kr = β·Ks·RA·RB. A sphere–wall contact passes rb = ra
/// (YADE's box–sphere convention: Kn = Ec·R, Kr = β·Ks·R²). Throws std::invalid_argument for
/// non-positive radii or modulus.
ContactStiffness contact_stiffness(double young_ec, double stiffness_ratio_nu_c,
                                   double rolling_beta, double ra, double rb,
                                   RollingRadius rolling_radius);

}  // namespace gs::solver
