// Value types of the DEM solver: materials, walls, particle state (structure of arrays) and
// contact histories. Units SI.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "contact_stiffness.hpp"
#include "triangle_facet.hpp"

namespace gs::solver {

/// YADE CohFrictMat (non-cohesive) parameters, seed 000 eq 1-8 / seed 004 Table 4.3.
struct Material {
  double young_ec = 0;         // Pa, contact modulus Ec (Kn = Ec·2RaRb/(Ra+Rb))
  double stiffness_ratio = 0;  // νc = Ks/Kn
  double friction_deg = 0;     // μ, inter-particle friction angle
  double density = 0;          // kg/m³
  double rolling_beta = 0;     // β, Kr = β·Ks·Ra·Rb (0 disables contact moments)
  double rolling_eta = 0;      // η, |M| ≤ η·R_roll·|Fn| (negative: no limit)
  RollingRadius rolling_radius = RollingRadius::Min;
  // Hertz–Mindlin law only (young_ec is then the material's Young's modulus E):
  double poisson = 0;      // ν
  double restitution = 1;  // en of a pair of these grains (and of a grain on a wall)
  // Linear law only: > 0: every contact (sphere pairs and walls) has this constant normal stiffness
  // instead of the modulus-based Kn (PFC's linear model with constant kn, seed 003 §2.4); Ks =
  // νc·Kn.
  double normal_stiffness_N_m = 0;
};

/// The contact law of a scene.
enum class ContactLaw {
  CohesiveFrictional,  // YADE CohFrictMat, linear (default)
  HertzMindlin,        // YADE MindlinPhys (hertz_mindlin_law.hpp)
};

/// Facets: triangles of a mesh wall (one triangle per wall in YADE's layout, or the triangles
/// of one flat region; boundaries/mesh_walls.hpp), relative to the wall's position.
enum class WallShape { Box, Plane, Facets };

/// A rigid wall. Boxes are axis-aligned (centre, half-extents); planes are infinite (point,
/// unit normal pointing into the granular domain). Walls move with `velocity` (m/s); planes
/// may rotate with `angular_velocity` (rad/s) about their point, facet walls about
/// `rotation_center` (which moves with `velocity`). A servo wall adjusts its velocity along its
/// servo axis to hold the normal stress on it (on all walls of its `body`: the walls of one
/// rigid mesh) at `servo_stress_Pa`.
struct WallSpec {
  std::string name;
  WallShape shape = WallShape::Box;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();        // box centre or plane point
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  // box only
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();       // plane only
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // plane only
  // Servo control (off when servo_area_m2 == 0).
  double servo_stress_Pa = 0;     // target compressive stress
  double servo_area_m2 = 0;       // area the force is divided by
  double servo_gain = 0;          // m/s per Pa of stress error
  double servo_max_velocity = 0;  // m/s cap
  double friction_deg = -1;       // wall–sphere friction angle; negative: the material's
  bool active = true;             // false: starts switched off (a later stage turns it on)
  // Facets only: the triangles (offsets from `center`), and the contact convention: YADE's
  // (a facet counts as radius 2R: Kn = 4/3·Ec·R) or a plane wall's (Kn = Ec·R).
  std::vector<TriangleFacet> facets;
  bool plane_radii = false;
  std::string group;  // the mesh's named facet group (forces are summed per group)
  std::string mesh;   // the name of the mesh the wall belongs to
  Eigen::Vector3d rotation_center = Eigen::Vector3d::Zero();  // facets only
  int body = -1;  // walls with the same body ≥ 0 form one rigid mesh (servo on their sum)
  double off_at_s = HUGE_VAL;  // switched off once the time reaches this (an outlet opening)
  int material = 0;            // index into the scene's materials (Hertz–Mindlin law)
};

/// Per-particle state, structure of arrays (index = particle index, not id).
struct ParticleState {
  std::vector<std::int64_t> id;
  std::vector<double> radius, mass, inertia;
  std::vector<Eigen::Vector3d> pos, vel, angvel, rot, force, torque;
  std::vector<Eigen::Quaterniond> ori;
  std::vector<std::uint8_t> fixed;        // 1: velocities imposed (not integrated from forces)
  std::vector<std::uint8_t> rot_blocked;  // 1: angular velocity imposed, translation free
  std::vector<Eigen::Vector3d> external_force;  // N, applied loads (e.g. membrane pressure)
  std::vector<std::int32_t> clump;  // index of the clump the particle is a member of; -1: none
  std::vector<std::uint8_t>
      removed;  // 1: left through an outlet (frozen, in no contact, not output)
  std::vector<std::uint8_t> material;  // index into the scene's materials (0: `material`)

  std::size_t size() const { return pos.size(); }
};

/// Wall kinematic state and accumulated loads.
struct WallState {
  WallSpec spec;
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();  // current centre (box) or point (plane)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d vel = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
  // Facets: the rotation since the start (spec.facets → facets) and the current centre of it;
  // `reach` bounds the distance of the facets' points from pos (m).
  Eigen::Quaterniond ori = Eigen::Quaterniond::Identity();
  Eigen::Vector3d rot_center = Eigen::Vector3d::Zero();
  std::vector<TriangleFacet> facets;  // current (rotated) triangles, relative to pos
  double reach = 0;
  std::vector<Eigen::Vector3d> facet_force;  // N per facet (Simulation::set_facet_forces)
  bool active = true;            // an inactive wall touches nothing (e.g. replaced by a membrane)
  double contact_stiffness = 0;  // Σ Kn of its contacts in the last step, N/m
  std::size_t contacts = 0;      // its contacts in the last step
};

/// History of one contact (YADE's CohFrictPhys + ScGeom state that survives between steps).
/// `b` is a particle index, or walls are encoded as b = kWallBase + wall index.
/// One is kept per candidate pair and streamed through every step: the fields a step reads and
/// writes come first (without the twist, the first 113 bytes), the pair's names after them,
/// 152 bytes in all (the checkpoint keeps its own record; see Simulation::save_checkpoint).
struct ContactHistory {
  // Results of the current step (for output and monitors).
  double fn = 0, overlap = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // last step's unit normal (a -> b)
  Eigen::Vector3d shear_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d bending = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // (of the current step)
  bool real = false;                                // in contact after this step's geometry
  std::uint32_t a = 0, b = 0;
  Eigen::Vector3d twist = Eigen::Vector3d::Zero();  // (zero unless twisting moments are on)
};

static_assert(sizeof(ContactHistory) == 152, "the layout the contact pass prefetches");

inline constexpr std::uint32_t kWallBase = 0x80000000u;

/// Makes room for n elements in a per-pair buffer, with 1/16 to spare, so that a list a little
/// longer at the next neighbour-list build does not reallocate: a fresh block that large is
/// mapped anew and costs a page fault per page every time.
template <class Vec>
void with_room(Vec& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(n + n / 16);
}

}  // namespace gs::solver
