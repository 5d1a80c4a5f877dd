// Seed 003's tangential polyhedron (§2.3, App. 3): the specimen boundary of the principal stress
// rotation tests, n-sided (n even, n >= 4) and tangent in every face to a sphere of radius R
// centred at the origin. Two end walls (regular n-gons at z = ±R) and (n/2 - 1) n side walls
// (quadrangles) whose tangent points have the spherical coordinates (R, 2 i ϖ, 2 (j - 1) ϖ),
// ϖ = 180°/n; n²/2 vertices in n/2 layers. n = 4 is the cube of half-width R; n = 8 (the paper's)
// has 32 vertices and 26 walls.
//
// The walls follow an imposed deformation gradient F (§2.1.2): a wall's centre moves to F X_o
// (Eq 5), its in-plane vectors to F T (Eq 6), its normal to the normalised t1 × t2 (Eq 7); over a
// step dt the centre gets the velocity ΔF X_o / dt (Eq 8) and the normal the spin n × n_t / dt
// (Eq 9). F is measured back from the faces' polygons (Eq 4).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dem_types.hpp"

namespace gs::solver {

struct TangentialPolyhedron {
  int n = 0;
  double R = 0.0;                         // m, the inscribed sphere's radius
  std::vector<Eigen::Vector3d> vertices;  // App. 3 order: layer i (top down), then j ccw from +x
  // Faces in App. 3's wall order: the (n/2 - 1) n side walls (ID (i - 1) n + j, 1-based), then
  // the top and the bottom end wall. Vertex indices counter-clockwise seen from outside.
  std::vector<std::vector<int>> faces;
  std::vector<Eigen::Vector3d> normals;      // outward unit normals
  std::vector<Eigen::Vector3d> tangent;      // tangent points on the sphere (= R · normal)
  std::vector<Eigen::Vector3d> face_normal;  // outward, of the vertex polygons (Eq 4's N)
  std::vector<double> area;                  // face areas, m² (Eq 4's reference ΔS)
  double volume = 0.0;                       // m³ (Eq 4's reference V)
};

/// The polyhedron of App. 3. Throws std::invalid_argument for n odd or below 4, or R <= 0 (or
/// not finite).
TangentialPolyhedron tangential_polyhedron(int n, double R);

/// Area (m²), area centre, and unit normal (by the right-hand rule of the vertex order) of a
/// planar polygon.
struct PolygonMeasure {
  double area = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};
PolygonMeasure polygon_measure(const std::vector<Eigen::Vector3d>& polygon);

/// Volume (m³) enclosed by the faces (outward vertex order), by the divergence theorem.
double polyhedron_volume(const std::vector<Eigen::Vector3d>& vertices,
                         const std::vector<std::vector<int>>& faces);

/// Eq 4: F_iJ = -(1/V) Σ x_i^c N_J ΔS over the faces, with V, N (inward) and ΔS of the reference
/// polyhedron and x^c the area centres of the same faces with the `current` vertices. Exact for a
/// homogeneous deformation (an affine map keeps area centres).
Eigen::Matrix3d deformation_gradient_from_faces(const TangentialPolyhedron& reference,
                                                const std::vector<Eigen::Vector3d>& current);

/// The current vertices from the walls' current planes (point p_w, unit normal n_w per face, in
/// face order): each vertex is the least-squares intersection of the planes of its faces.
std::vector<Eigen::Vector3d> vertices_from_planes(const TangentialPolyhedron& reference,
                                                  const std::vector<Eigen::Vector3d>& point,
                                                  const std::vector<Eigen::Vector3d>& normal);

/// The walls' planes under deformation gradient F: each centre (the reference tangent point X_o)
/// mapped to F X_o (Eq 5), each normal to Eq 7's (t1 × t2 of the mapped in-plane vectors, Eq 6).
struct WallPlane {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // outward
};
std::vector<WallPlane> wall_planes(const TangentialPolyhedron& reference, const Eigen::Matrix3d& F);

/// A wall's motion over one step towards deformation gradient F_target from F (Eqs 5-9): the
/// velocity of its centre (the reference tangent point X_o mapped by F) and its spin.
struct WallMotion {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // F X_o, m
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // Eq 7 with F
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};
std::vector<WallMotion> wall_motions(const TangentialPolyhedron& reference,
                                     const Eigen::Matrix3d& F, const Eigen::Matrix3d& F_target,
                                     double dt);

class Simulation;

/// The faces as the engine's plane walls, in face order: the point is the tangent point, the
/// normal points into the specimen (the engine's plane convention); frictional at the
/// material's angle unless `friction_deg` >= 0. Named poly1, poly2, ... by App. 3's wall IDs
/// (the end walls are poly<(n/2 - 1) n + 1> top and poly<(n/2 - 1) n + 2> bottom).
std::vector<WallSpec> polyhedron_walls(const TangentialPolyhedron& P, double friction_deg = -1);

/// Sets the velocities (Eq 8) and spins (Eq 9) of the engine's walls first .. first + faces - 1
/// so that the next step of length dt carries each from its current plane to the plane of the
/// target deformation gradient: the point to F_target X_o, the normal to Eq 7's. Taken from the
/// walls' current planes (not from the previous target), so no error accumulates.
void drive_polyhedron(Simulation& sim, std::size_t first, const TangentialPolyhedron& P,
                      const Eigen::Matrix3d& F_target, double dt);

/// Eq 4 from the engine's walls first .. first + faces - 1: the vertices rebuilt as their planes'
/// intersections, then F from the faces' area centres.
Eigen::Matrix3d polyhedron_deformation_gradient(const Simulation& sim, std::size_t first,
                                                const TangentialPolyhedron& P);

/// The volume (m³) enclosed by the engine's walls first .. first + faces - 1 (their planes'
/// intersections).
double polyhedron_current_volume(const Simulation& sim, std::size_t first,
                                 const TangentialPolyhedron& P);

/// Eq 14: the specimen's stress from its boundary, σ = -(1/v)(Σ x ⊗ F + Σ x_P ⊗ m_P g) over
/// the contacts of the walls first .. first + faces - 1 and the particles (v: the polyhedron's
/// current volume from the walls' planes). Compression positive. Pa.
Eigen::Matrix3d polyhedron_stress(const Simulation& sim, std::size_t first,
                                  const TangentialPolyhedron& P);

/// The stress servo of §2.2.2. Eq 15 maps a stress error Δσ = σ_t - σ to a strain increment by
/// isotropic elasticity, Δε = ((1 + ν)/E) Δσ - (ν/E) tr(Δσ) 1 (principal directions shared),
/// imposed in one step (F → F - Δε: Biot strain, Eq 2, no rigid rotation). Eq 16 sets E = kn L /
/// (ς A), A = (2 r̄)², L = 2 R_e (R_e the circumscribed radius), ς = 0.8. The paper's ν = 0.5
/// makes tr(Δε) = (1 - 2ν) tr(Δσ)/E = 0: the walls never move to correct the mean stress. ν is
/// a parameter here (default 0.25); `volumetric_gain` scales the volumetric part of Δε on top.
/// `max_strain_step` caps the largest principal value of Δε in one step (the paper has no
/// cap: far from the target, before the walls touch the grains, Eq 15 would move them at
/// Δσ L / (E dt), metres per second).
struct PolyhedronServo {
  double E = 0.0;  // Pa, Eq 16
  double nu = 0.25;
  double volumetric_gain = 1.0;
  double max_strain_step = 1e-6;
};

/// Eq 16's nominal modulus. Throws std::invalid_argument for a non-positive argument.
double servo_modulus(double kn, double mean_radius, double circumradius, double relaxation = 0.8);

/// One servo step: the walls are driven from their current F (Eq 4) towards F - Δε (Eq 15);
/// returns that target F. `sigma_now` and `F_now` (when given) receive the stress (Eq 14) and F
/// the step started from.
Eigen::Matrix3d servo_step(Simulation& sim, std::size_t first, const TangentialPolyhedron& P,
                           const Eigen::Matrix3d& sigma_target, const PolyhedronServo& servo,
                           double dt, Eigen::Matrix3d* sigma_now = nullptr,
                           Eigen::Matrix3d* F_now = nullptr);

/// Eq 17 (§2.2.3): the stress of mean p, ratio η = q/p and b = (σ2 - σ3)/(σ1 - σ3) (Lode
/// angle tan θ = √3 b / (2 - b)), with σ1 in the x-z plane at angle alpha (rad) from x, σ2 along
/// y and σ3 normal to both: the states of the rotation path (§2.2.3, Fig 3). Pa, compression
/// positive.
Eigen::Matrix3d principal_stress_state(double p, double eta, double b, double alpha);

/// Whether x lies inside the polyhedron at least `margin` from every face.
bool inside_polyhedron(const TangentialPolyhedron& P, const Eigen::Vector3d& x, double margin);

/// §2.4's carving: the indices of the spheres to keep, those whole inside (a sphere touching or
/// crossing a face goes). With `clump` (per sphere, -1: free) a clump stays only if all its
/// members do.
std::vector<std::size_t> carve_polyhedron(const TangentialPolyhedron& P,
                                          const std::vector<Eigen::Vector3d>& centre,
                                          const std::vector<double>& radius,
                                          const std::vector<std::int64_t>& clump = {});

}  // namespace gs::solver
