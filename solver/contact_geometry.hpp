// Contact geometry of sphere–sphere, box–sphere and plane–sphere pairs, with YADE's ScGeom
// conventions (Ig2_Sphere_Sphere_ScGeom, Ig2_Box_Sphere_ScGeom; docs/physics.md).
#pragma once

#include <Eigen/Core>

namespace gs::solver {

/// Geometry of one pair at the current positions. Body 1 is the wall for wall contacts (YADE
/// orders box–sphere interactions box first); the normal points from body 1 to body 2.
struct ContactGeometry {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double penetration = 0;  // > 0 when overlapping
  double radius1 = 0, radius2 = 0;
  /// YADE's avoidGranularRatcheting: relative velocity from the radii (true) or from the
  /// contact point (false; box–sphere with the sphere centre outside the box).
  bool ratchet_free = true;
};

/// Sphere–sphere: normal = (x2 − x1)/|x2 − x1|, penetration = r1 + r2 − |x2 − x1|, contact
/// point x1 + (r1 − pen/2)·n. Returns false when the centres coincide.
bool sphere_sphere_geometry(const Eigen::Vector3d& x1, double r1, const Eigen::Vector3d& x2,
                            double r2, ContactGeometry& g);

/// Axis-aligned box (centre c, half-extents h) and a sphere. Sphere centre outside the box:
/// normal from the closest box point to the centre, penetration r − distance, contact point
/// half-way between the box point and the sphere surface. Centre inside: normal along the
/// nearest face's outward normal. Both radii are the sphere radius (YADE's convention).
void box_sphere_geometry(const Eigen::Vector3d& c, const Eigen::Vector3d& h,
                         const Eigen::Vector3d& x, double r, ContactGeometry& g);

/// Infinite plane (point p, unit normal m into the domain) and a sphere: normal m,
/// penetration r − (x − p)·m, contact point x − (r − pen/2)·m. Both radii = r.
void plane_sphere_geometry(const Eigen::Vector3d& p, const Eigen::Vector3d& m,
                           const Eigen::Vector3d& x, double r, ContactGeometry& g);

/// Distance from a point to an axis-aligned box (0 inside).
double box_distance(const Eigen::Vector3d& c, const Eigen::Vector3d& h, const Eigen::Vector3d& x);

}  // namespace gs::solver
