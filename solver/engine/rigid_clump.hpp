// Rigid clumps of (possibly overlapping) member spheres: mass properties and YADE's aspherical
// leapfrog (NewtonIntegrator::leapfrogAsphericalRotate), the clump bodies of seed 003 §2.4 and
// seed 004 §4.3. Units SI.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace gs::solver {

/// One member sphere of a clump template: centre in the template frame (m) and radius (m).
struct ClumpMember {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  double radius = 0;
};

/// How a clump's mass and inertia are obtained from its members.
enum class ClumpMassModel {
  /// YADE's default (`appendClumped(..., discretization=0)`): the members' masses and
  /// inertias summed with the parallel-axis theorem, overlaps counted as often as they occur.
  MemberSum,
  /// The true volume of the union of the members: exact for one or two spheres (piecewise
  /// polynomial integrals along the axis), integrated on a grid for more (see union_resolution).
  Union,
};

/// Mass (kg), centre of mass and inertia tensor about it (kg·m²), in the frame the members
/// are given in.
struct MassProperties {
  double mass = 0;
  double volume = 0;  // m³ (the volume the mass is ρ times)
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

/// YADE's Clump::updateProperties with discretization = 0: M = Σ ρ·(4/3)π r³,
/// X = Σ m x / M, I = Σ [(2/5) m r² 𝟙 + m (|d|² 𝟙 − d dᵀ)], d = x − X.
MassProperties member_sum_mass_properties(const std::vector<ClumpMember>& members, double density);

/// Mass properties of the union of the member spheres. One sphere, or two: exact (to
/// round-off). More: midpoint quadrature over a grid of `resolution`² lines across the
/// bounding box along the x axis, each line's chord set (a union of intervals) integrated
/// exactly; the relative error falls as resolution^-1.5 (about 1e-5 at 400).
MassProperties union_mass_properties(const std::vector<ClumpMember>& members, double density,
                                     int resolution = 400);

MassProperties clump_mass_properties(const std::vector<ClumpMember>& members, double density,
                                     ClumpMassModel model);

/// Principal moments (ascending) and the rotation whose columns are the principal axes, from
/// Eigen's SelfAdjointEigenSolver as YADE takes them; the rotation is made proper (det +1).
struct PrincipalAxes {
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // principal -> global
};
PrincipalAxes principal_axes(const Eigen::Matrix3d& inertia);

/// A clump body placed in the scene: which particles are its members, its mass properties in
/// its principal frame, and its state. Members' local positions/orientations are those in the
/// principal frame (YADE's Clump.members).
struct ClumpBody {
  std::int64_t id = -1;
  std::string template_name;                  // the scene's template (output only)
  std::vector<std::uint32_t> members;         // particle indices
  std::vector<Eigen::Vector3d> local_pos;     // member centre in the principal frame
  std::vector<Eigen::Quaterniond> local_ori;  // member orientation relative to the clump
  double mass = 0;
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();  // principal moments, kg·m²
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();      // centre of mass
  Eigen::Quaterniond ori = Eigen::Quaterniond::Identity();
  Eigen::Vector3d vel = Eigen::Vector3d::Zero(), angvel = Eigen::Vector3d::Zero();
  Eigen::Vector3d angmom = Eigen::Vector3d::Zero();  // global frame (what the integrator advances)
};

/// Builds a clump body from member spheres at their global positions: mass properties by
/// `model`, principal frame from principal_axes unless `orientation` is given (YADE's frame is
/// not unique for axisymmetric clumps), members' local positions l = q̄·(x − X). Members start
/// with the identity orientation, the clump at rest.
ClumpBody make_clump_body(const std::vector<std::uint32_t>& member_indices,
                          const std::vector<Eigen::Vector3d>& member_pos,
                          const std::vector<double>& member_radius, double density,
                          ClumpMassModel model, const Eigen::Quaterniond* orientation = nullptr);

/// Loads a step sums onto a clump from its members (YADE's Clump::addForceTorqueFromMembers):
/// F = Σ f_i, T = Σ [t_i + (x_i − X) × f_i], in member order.
struct ClumpLoad {
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
};

/// One step of YADE's NewtonIntegrator for an aspherical body (exactAsphericalRot): the
/// translation as for spheres (a = F/M + g, Cundall's second-order damping per component),
/// the torque damped to first order with the stored angular velocity, then the angular
/// momentum and orientation advanced by leapfrogAsphericalRotate. Returns the damping
/// estimate |v|·|F + M g|·damping·dt + |ω|·|T|·damping·dt (the ledger's, as for spheres).
double integrate_clump(ClumpBody& c, const ClumpLoad& load, const Eigen::Vector3d& gravity,
                       double damping, double dt);

/// Kinetic energy ½Mv² + ½ω·(R I Rᵀ)ω.
double clump_kinetic_energy(const ClumpBody& c);

}  // namespace gs::solver
