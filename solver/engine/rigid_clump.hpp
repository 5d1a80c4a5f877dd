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

/// integrate_clump for clumps[0, count) with loads[0, count), several at a time (vectorised
/// across clumps, the same bits as one by one); damp[k]: clump k's damping estimate.
void integrate_clump_bodies(ClumpBody* clumps, const ClumpLoad* loads, std::size_t count,
                            const Eigen::Vector3d& gravity, double damping, double dt,
                            double* damp);

/// Kinetic energy ½Mv² + ½ω·(R I Rᵀ)ω.
double clump_kinetic_energy(const ClumpBody& c);

/// YADE's Clump::moveMembers for member m: pos = X + q·l, ori = q·q_l, vel = V + ω × (pos − X),
/// written out in the order in which Eigen evaluates those expressions (its _transformVector
/// uv = 2 (v × l), l + w uv + v × uv; its SSE2 quaternion product), the same bits without the
/// temporaries.
inline void place_member(const ClumpBody& c, std::size_t m, Eigen::Vector3d& pos,
                         Eigen::Quaterniond& ori, Eigen::Vector3d& vel) {
  const double qw = c.ori.w(), qx = c.ori.x(), qy = c.ori.y(), qz = c.ori.z();
  const Eigen::Vector3d& l = c.local_pos[m];
  const double l0 = l[0], l1 = l[1], l2 = l[2];
  double u0 = qy * l2 - qz * l1, u1 = qz * l0 - qx * l2, u2 = qx * l1 - qy * l0;
  u0 += u0;
  u1 += u1;
  u2 += u2;
  const double p0 = c.pos[0] + ((l0 + qw * u0) + (qy * u2 - qz * u1));
  const double p1 = c.pos[1] + ((l1 + qw * u1) + (qz * u0 - qx * u2));
  const double p2 = c.pos[2] + ((l2 + qw * u2) + (qx * u1 - qy * u0));
  pos[0] = p0;
  pos[1] = p1;
  pos[2] = p2;
  const Eigen::Quaterniond& b = c.local_ori[m];
  const double bw = b.w(), bx = b.x(), by = b.y(), bz = b.z();
  ori = Eigen::Quaterniond((qw * bw - qy * by) - (qz * bz + qx * bx),   // w
                           (qw * bx + qy * bz) - (qz * by - qx * bw),   // x
                           (qw * by + qy * bw) + (qz * bx - qx * bz),   // y
                           (qw * bz - qy * bx) + (qz * bw + qx * by));  // z
  const double d0 = p0 - c.pos[0], d1 = p1 - c.pos[1], d2 = p2 - c.pos[2];
  const double w0 = c.angvel[0], w1 = c.angvel[1], w2 = c.angvel[2];
  vel[0] = c.vel[0] + (w1 * d2 - w2 * d1);
  vel[1] = c.vel[1] + (w2 * d0 - w0 * d2);
  vel[2] = c.vel[2] + (w0 * d1 - w1 * d0);
}

}  // namespace gs::solver
