// A triangular facet of a mesh wall as YADE's Facet stores it (utils.facet + Facet::postLoad):
// the body sits at the incircle centre, the vertices are kept relative to it, with the unit
// normal, the in-plane outward edge normals, the incircle radius and each vertex as length and
// unit direction. Its contact with a sphere is facet_sphere_geometry (contact_geometry.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "scalar_vec3.hpp"

namespace gs::solver {

struct TriangleFacet {
  V3 offset;          // incircle centre relative to the wall's reference point (m)
  V3 vertex[3];       // vertices relative to the incircle centre (m)
  V3 normal;          // unit, (v1 − v0) × (v2 − v1) normalised
  V3 edge_normal[3];  // in-plane outward unit normal of edge i (vertex i → i+1)
  V3 vertex_unit[3];
  double vertex_length[3] = {0, 0, 0};
  double incircle_radius = 0;  // m
  double area = 0;             // m²
};

/// YADE's inscribedCircleCenter: v0 + ((v2 − v0)|v1 − v0| + (v1 − v0)|v2 − v0|) / perimeter.
Eigen::Vector3d incircle_centre(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1,
                                const Eigen::Vector3d& v2);

/// The facet of triangle (v0, v1, v2), global coordinates, relative to `reference` (the wall's
/// position; pass the incircle centre for YADE's one-body-per-facet layout). Throws
/// std::invalid_argument for a degenerate (zero-area) or non-finite triangle.
TriangleFacet make_triangle_facet(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1,
                                  const Eigen::Vector3d& v2, const Eigen::Vector3d& reference);

/// The facet rotated rigidly by q about the wall's reference point: offset, vertices, normals
/// and vertex directions rotated; lengths, area and incircle radius kept.
TriangleFacet rotated_facet(const TriangleFacet& f, const Eigen::Quaterniond& q);

}  // namespace gs::solver
