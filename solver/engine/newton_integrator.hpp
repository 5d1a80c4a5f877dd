// Leapfrog integration with Cundall's local non-viscous damping, as YADE's NewtonIntegrator
// does it for spheres (seed 000 eq 8; seed 004 eqs 3.17-3.18).
#pragma once

#include <Eigen/Core>

#include "dem_types.hpp"
#include "scalar_vec3.hpp"

namespace gs::solver {

/// YADE's cundallDamp2nd: a_i *= 1 − damping·sign(a_i·(v_i + a_i·dt/2)), per component.
inline double cundall_factor(double damping, double dt, double vel, double accel) {
  const double s = accel * (vel + 0.5 * dt * accel);
  // sign(s) without branches: the signs are random at equilibrium, and mispredicted branches
  // cost more than the arithmetic.
  return 1 - damping * static_cast<double>(static_cast<int>(s > 0) - static_cast<int>(s < 0));
}

/// Sums over the particles one call integrated, in particle order (J/s and J).
struct IntegrationSums {
  double gravity_power = 0;   // Σ m·g·v at the velocities before the update
  double external_power = 0;  // Σ F_ext·v, likewise
  double damping = 0;         // energy removed by damping in this step
  bool finite = true;         // every updated position and velocity is finite
};

/// Advances particles [begin, end) by one step from their accumulated forces and torques.
/// Gravity is added to the acceleration before damping (YADE's default). The damping estimate
/// is YADE's |v|·|F + m g|·damping·dt per component, before the update. Two passes: velocities
/// and positions, then orientations (whose square root and division then overlap across
/// particles instead of stalling each one). Fixed clump members (p.clump[i] >= 0) keep their
/// velocities and only advance their rotation vectors (and count in the finite check): their
/// positions and orientations are left for the clump update (Simulation::integrate_clumps),
/// which overwrites them. `clump_members` false: the caller knows there are none (no check).
/// `roles` (a domain decomposition's ParticleRole per particle, or nullptr): only the owned
/// particles (2) are integrated; the others are left as they are and add nothing to the sums.
IntegrationSums integrate_particles(ParticleState& p, std::size_t begin, std::size_t end,
                                    const Eigen::Vector3d& gravity, double damping, double dt,
                                    bool clump_members = true, const std::uint8_t* roles = nullptr);

/// The homogeneous-deformation terms of YADE's NewtonIntegrator in a periodic cell
/// (Cell.homoDeform = 2), and YADE's 2D emulation blockedDOFs = 'zXY'.
struct HomogeneousField {
  Eigen::Matrix3d prev_vel_grad = Eigen::Matrix3d::Zero();  // L of the previous step
  Eigen::Matrix3d d_vel_grad = Eigen::Matrix3d::Zero();     // L − L_prev
  Eigen::Vector3d d_spin = Eigen::Vector3d::Zero();  // (−W_yz, W_xz, −W_xy), W = ½(ΔL − ΔLᵀ)
  bool planar = false;  // no translation along z, no rotation about x or y
};

/// integrate_particles with a homogeneous field, per particle in YADE's order: damping of the
/// force part of the acceleration against the fluctuation velocity v − L_prev·x, the convective
/// term a += L_prev·v, v += dt·a, then v += ΔL·x and x += dt·v; ω += dt·α, then ω += Δspin and
/// the orientation turned by |ω|·dt (AngleAxis, as leapfrogSphericalRotate). Blocked degrees of
/// freedom get no acceleration (their velocities keep what the field gives them). No clumps.
/// `roles` as in integrate_particles: only the owned particles move (and count in the sums).
IntegrationSums integrate_particles_homogeneous(ParticleState& p, std::size_t begin,
                                                std::size_t end, const Eigen::Vector3d& gravity,
                                                double damping, double dt,
                                                const HomogeneousField& field,
                                                const std::uint8_t* roles = nullptr);

}  // namespace gs::solver
