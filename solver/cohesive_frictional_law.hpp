// YADE's Law2_ScGeom6D_CohFrictPhys_CohesionMoment for non-cohesive contacts, incremental form
// (seed 000 eq 1-7; seed 004 eqs 3.1-3.18). docs/physics.md lists each convention.
#pragma once

#include <Eigen/Core>

#include "contact_geometry.hpp"
#include "dem_types.hpp"

namespace gs::solver {

/// Constant contact parameters, set when the contact is created.
struct ContactParams {
  double kn = 0, ks = 0, kr = 0, ktw = 0;
  double tan_friction = 0;
  double max_roll = -1;   // η·R_roll (m); negative: rolling moment unbounded
  double max_twist = -1;  // likewise for twisting
};

ContactParams contact_params(const Material& m, double r1, double r2, double twist_beta,
                             double twist_eta);

/// Kinematics of the two bodies at the contact.
struct BodyMotion {
  Eigen::Vector3d pos, vel, angvel;
};

/// Loads the contact puts on the bodies, split as YADE accumulates them: body 1 receives
/// force1 and the torques arm1 − moment; body 2 receives −force1 and arm2 + moment.
struct ContactLoads {
  Eigen::Vector3d force1, arm1, arm2, moment;
  double fn = 0;                                             // |normal force|, N
  double friction_dissipation = 0, rolling_dissipation = 0;  // J, this step
};

/// One step of the law on a contact that exists this step (penetration ≥ 0). `fresh` starts
/// the history at zero. Updates the history (normal, shear force, moments) in place.
ContactLoads cohesive_frictional_step(ContactHistory& h, bool fresh, const ContactGeometry& g,
                                      const ContactParams& p, const BodyMotion& b1,
                                      const BodyMotion& b2, double dt);

}  // namespace gs::solver
