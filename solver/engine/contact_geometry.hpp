// Contact geometry of sphere–sphere, box–sphere and plane–sphere pairs, with YADE's ScGeom
// conventions (Ig2_Sphere_Sphere_ScGeom, Ig2_Box_Sphere_ScGeom; docs/physics.md).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "scalar_vec3.hpp"
#include "triangle_facet.hpp"

namespace gs::solver {

/// Geometry of one pair at the current positions. Body 1 is the wall for wall contacts (YADE
/// orders box–sphere interactions box first); the normal points from body 1 to body 2.
struct ContactGeometry {
  V3 normal, point;
  double penetration = 0;  // > 0 when overlapping
  double radius1 = 0, radius2 = 0;
  /// YADE's avoidGranularRatcheting: relative velocity from the radii (true) or from the
  /// contact point (false; box–sphere with the sphere centre outside the box).
  bool ratchet_free = true;
};

/// Sphere–sphere: normal = (x2 − x1)/|x2 − x1|, penetration = r1 + r2 − |x2 − x1|, contact
/// point x1 + (r1 − pen/2)·n. Returns false when the centres coincide.
[[gnu::always_inline]] inline bool sphere_sphere_geometry(const V3& x1, double r1, const V3& x2,
                                                          double r2, ContactGeometry& g) {
  V3 n = x2 - x1;
  const double d = std::sqrt(squared_norm(n));
  if (!(d > 0)) return false;
  n = n / d;
  g.normal = n;
  g.penetration = r1 + r2 - d;
  g.point = x1 + (r1 - 0.5 * g.penetration) * n;
  g.radius1 = r1;
  g.radius2 = r2;
  g.ratchet_free = true;
  return true;
}

/// Axis-aligned box (centre c, half-extents h) and a sphere. Sphere centre outside the box:
/// normal from the closest box point to the centre, penetration r − distance, contact point
/// half-way between the box point and the sphere surface. Centre inside: normal along the
/// nearest face's outward normal. Both radii are the sphere radius (YADE's convention).
void box_sphere_geometry_inside(const V3& h, const V3& x, const V3& on_box, double r,
                                ContactGeometry& g);
[[gnu::always_inline]] inline void box_sphere_geometry(const V3& c, const V3& h, const V3& x,
                                                       double r, ContactGeometry& g) {
  const V3 rel = x - c;
  V3 on_box = rel;
  bool inside = true;
  auto clamp = [&](double& v, double half) {
    if (v < -half) {
      v = -half;
      inside = false;
    }
    if (v > half) {
      v = half;
      inside = false;
    }
  };
  clamp(on_box.x, h.x);
  clamp(on_box.y, h.y);
  clamp(on_box.z, h.z);
  g.radius1 = g.radius2 = r;
  if (inside) return box_sphere_geometry_inside(h, x, on_box, r, g);
  V3 to_box = on_box - rel;  // from the sphere centre to the closest box point
  const double len2 = squared_norm(to_box);
  g.penetration = r - std::sqrt(len2);
  const V3 pt1 = on_box + c;
  if (len2 > 0) to_box = to_box / std::sqrt(len2);
  const V3 pt2 = x + to_box * r;
  g.point = 0.5 * (pt1 + pt2);
  g.normal = -to_box;
  g.ratchet_free = false;
}

/// Infinite plane (point p, unit normal m into the domain) and a sphere: normal m,
/// penetration r − (x − p)·m, contact point x − (r − pen/2)·m. Both radii = r.
[[gnu::always_inline]] inline void plane_sphere_geometry(const V3& p, const V3& m, const V3& x,
                                                         double r, ContactGeometry& g) {
  const double dist = dot(x - p, m);
  g.normal = m;
  g.penetration = r - dist;
  g.point = x - (r - 0.5 * g.penetration) * m;
  g.radius1 = g.radius2 = r;
  g.ratchet_free = false;
}

/// Triangular facet (at wall position w) and a sphere, as YADE's Ig2_Facet_Sphere_ScGeom:
/// two-sided (the normal is flipped to the sphere's side); the in-plane branch vector's largest
/// edge-normal component decides face (projection inside: penetration r − L along the facet
/// normal), edge (closest point on the edge's line) or vertex contact (normal from the closest
/// point to the centre, penetration r − distance); contact point x − (r − pen/2)·n. The radii
/// are (2r, r) (YADE gives the facet twice the sphere's radius) unless `plane_radii`, which
/// gives (r, r) as for plane walls. Returns the distance from the centre to the closest point.
[[gnu::always_inline]] inline double facet_sphere_geometry(const TriangleFacet& f, const V3& w,
                                                           const V3& x, double r, bool plane_radii,
                                                           ContactGeometry& g) {
  const V3 cl = x - (w + f.offset);
  V3 n = f.normal;
  double l = dot(n, cl);
  if (l < 0) {
    n = -n;
    l = -l;
  }
  V3 cp = cl - l * n;
  double bm = dot(f.edge_normal[0], cp);
  int m = 0;
  for (int i = 1; i < 3; ++i) {
    const double b = dot(f.edge_normal[i], cp);
    if (bm < b) {
      bm = b;
      m = i;
    }
  }
  const double icr = f.incircle_radius;
  double dist;
  if (bm < icr) {
    g.penetration = r - l;
    dist = l;
    n = n / std::sqrt(squared_norm(n));  // (YADE normalises the unit normal again)
  } else {
    cp = cp + f.edge_normal[m] * (icr - bm);
    if (dot(cp, f.edge_normal[m == 0 ? 2 : m - 1]) > icr) {
      cp = f.vertex_unit[m] * f.vertex_length[m];
    } else if (dot(cp, f.edge_normal[m = (m == 2 ? 0 : m + 1)]) > icr) {
      cp = f.vertex_unit[m] * f.vertex_length[m];
    }
    n = cl - cp;
    dist = std::sqrt(squared_norm(n));
    n = n / dist;
    g.penetration = r - dist;
  }
  g.normal = n;
  g.point = x - (r - 0.5 * g.penetration) * n;
  g.radius1 = plane_radii ? r : 2 * r;
  g.radius2 = r;
  g.ratchet_free = false;
  return dist;
}

/// Distance from a point to an axis-aligned box (0 inside).
double box_distance(const Eigen::Vector3d& c, const Eigen::Vector3d& h, const Eigen::Vector3d& x);

}  // namespace gs::solver
