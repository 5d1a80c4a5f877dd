// The Hertz–Mindlin contact law with viscous damping from a coefficient of restitution, as
// YADE 2023.02a's Ip2_FrictMat_FrictMat_MindlinPhys + Law2_ScGeom_MindlinPhys_Mindlin compute it
// (the law the DEM8 benchmark prescribes, Dosta et al. 2024 §2). docs/physics.md, "Hertz–Mindlin".
#pragma once

#include <vector>

#include "cohesive_frictional_law.hpp"

namespace gs::solver {

/// Thornton et al. (2013) Eq B6–B7: the damping ratio β (of the critical 2·sqrt(m*·k)) that
/// gives the coefficient of restitution en in a Hertzian impact; 0 for en = 1. Throws
/// std::invalid_argument outside (0, 1].
double thornton_damping_ratio(double en);

/// The constant parameters of a Hertz–Mindlin contact, stored in ContactParams' fields as:
/// kn = kno = 4/3·E*·sqrt(R*) (N/m^1.5), ks = kso = 8·G*·sqrt(R*) (N/m^1.5), kr = βn, ktw = βs,
/// max_roll = m* (kg), tan_friction; max_twist unused (−1). E* = 1/((1−νa²)/Ea + (1−νb²)/Eb),
/// G* = 1/((2−νa)/Ga + (2−νb)/Gb), R* = ra·rb/(ra+rb), m* = ma·mb/(ma+mb), or the mass of the one
/// dynamic body (pass mb = 0 for a wall or a fixed particle b, ma = 0 for a fixed a).
struct HertzMaterial {
  double young = 0, poisson = 0;
};
ContactParams hertz_mindlin_params(const HertzMaterial& a, const HertzMaterial& b, double ra,
                                   double rb, double ma, double mb, double restitution,
                                   double tan_friction);

/// The Rayleigh time step of the Hertzian contacts, min over the radii of
/// π·r·sqrt(ρ/G)/(0.1631·ν + 0.8766) with G = E/(2(1+ν)); the DEM8 benchmark's dt are 0.09–0.2
/// of it.
double rayleigh_timestep(const std::vector<double>& radii, double density, double young,
                         double poisson);

/// One step of the law on lanes [0, count) (fields as for cohesive_frictional_batch, with the
/// parameters above in KN, KS, KR, KTW, MAX_ROLL and TAN_FRICTION): Fn = kno·δ^1.5, the tangent
/// stiffnesses kn = 3/2·kno·δ^0.5 and ks = kso·δ^0.5, the shear force incremented with ks and
/// rotated as the linear law's, viscous forces cn·vn and cs·vs with cn = 2·sqrt(m*·kn)·βn (the
/// normal force never attractive), Coulomb's limit on the elastic shear force (no viscous shear
/// force while sliding). No contact moments (MX..MZ come out zero). FRICTION_DISSIPATION is
/// the work of sliding, ROLLING_DISSIPATION carries the viscous forces' work of this step.
void hertz_mindlin_batch(ContactBatch& batch, int count, double dt, bool periodic = false);

}  // namespace gs::solver
