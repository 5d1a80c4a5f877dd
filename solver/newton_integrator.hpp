// Leapfrog integration with Cundall's local non-viscous damping, as YADE's NewtonIntegrator
// does it for spheres (seed 000 eq 8; seed 004 eqs 3.17-3.18).
#pragma once

#include <Eigen/Core>

#include "dem_types.hpp"

namespace gs::solver {

/// YADE's cundallDamp2nd: a_i *= 1 − damping·sign(a_i·(v_i + a_i·dt/2)), per component.
inline void cundall_damp(double damping, double dt, const Eigen::Vector3d& vel,
                         Eigen::Vector3d& accel) {
  for (int i = 0; i < 3; ++i) {
    const double s = accel[i] * (vel[i] + 0.5 * dt * accel[i]);
    accel[i] *= 1 - damping * (s > 0 ? 1.0 : (s < 0 ? -1.0 : 0.0));
  }
}

/// Advances particle i by one step from its accumulated force and torque. Gravity is added to
/// the acceleration before damping (YADE's default). Returns the energy removed by damping in
/// this step (YADE's estimate |v|·|F + m g|·damping·dt per component, before the update).
double integrate_particle(ParticleState& p, std::size_t i, const Eigen::Vector3d& gravity,
                          double damping, double dt);

}  // namespace gs::solver
