// Triangle-mesh walls (seed 004 §5.2 silo walls, §4.3-4.4 interface-shear surfaces): a mesh
// becomes facet walls of the engine (WallShape::Facets), in one of two contact conventions.
//  * YadeParity: one wall per triangle, as YADE's utils.facet bodies: two-sided
//    Ig2_Facet_Sphere_ScGeom contacts, the facet counted as radius 2R (Kn = 4/3·Ec·R), and no
//    merging across edges: a sphere near an edge shared by two coplanar triangles gets a contact
//    with each (up to twice the force), and one touching a tooth tip gets two.
//  * Merged (the default): one wall per flat region (coplanar triangles of one group joined
//    through shared edges); a sphere has one contact with a region, at the closest point of its
//    triangles, with the stiffness convention of a plane wall (Kn = Ec·R), so that a mesh and
//    the analytic wall it approximates give the same physics, and a sphere rolling across
//    internal edges keeps one contact (and its shear history).
// Forces are those of the engine's walls: per triangle (parity) or per region (merged), summed
// per named group by group_forces.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "simulation.hpp"

namespace gs::solver {

enum class MeshContact { Merged, YadeParity };

/// A scene's name for a mesh contact convention: "merged" or "yade"; nothing for another name.
std::optional<MeshContact> mesh_contact_named(const std::string& name);

struct MeshTriangles {
  std::vector<std::array<Eigen::Vector3d, 3>> triangles;  // global vertices, m
  std::vector<std::string> group;                         // per triangle
};

/// Walls for the triangles, named "<group>:<index>" and carrying their group; all move with
/// `velocity`. Throws std::invalid_argument (naming the triangle) for a degenerate triangle.
std::vector<WallSpec> mesh_walls(const MeshTriangles& mesh, MeshContact mode,
                                 const Eigen::Vector3d& velocity = Eigen::Vector3d::Zero(),
                                 double friction_deg = -1);

/// Flat regions: for each triangle the index of its region (triangles of one group, coplanar
/// within `angle_tol` rad and `offset_tol` m, joined through shared edges).
std::vector<int> flat_regions(const MeshTriangles& mesh, double angle_tol = 1e-9,
                              double offset_tol = 1e-12);

/// Σ of the wall forces (N, exerted by the particles on the walls) over each group's walls, and
/// their torque (N·m) about the walls' rotation centre (a scene's mesh: the centre of its
/// bounding box unless it says otherwise).
struct GroupForce {
  std::string group;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  std::size_t walls = 0;
};
std::vector<GroupForce> group_forces(const Simulation& sim);
/// The same per mesh (WallSpec::mesh), for the meshes of more than one group.
std::vector<GroupForce> mesh_forces(const Simulation& sim);

}  // namespace gs::solver
