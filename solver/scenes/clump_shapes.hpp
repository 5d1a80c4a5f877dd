// Clump shapes of the seeds and how they enter a specimen:
//  * seed 003 §2.4: two equal spheres with centres 1.4·r apart;
//  * seed 004 §4.3 (Fig 4.34): an asymmetric convex clump of four spheres with diameters 0.5–0.6
//    of the clump's, aspect ratio 1.50, convexity indices 2.07 (smallest enclosing sphere / clump
//    volume) and 1.16 (convex hull / clump volume). The seed gives these measures and a picture,
//    not the member positions: the template here was fitted to them (see asymmetric_clump4) and
//    its own measures are computed by clump_shape;
//  * seed 003 §2.4's preparation: "the spheres are replaced with clumps of equal volume and
//    random orientations" (replace_by_clumps).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "rigid_clump.hpp"
#include "snapshot.hpp"

namespace gs::solver {

/// Seed 003's dimer: two spheres of radius r, centres at ∓0.7·r on x.
std::vector<ClumpMember> dimer_clump(double member_radius, double spacing_ratio = 1.4);

/// Seed 004's four-sphere asymmetric clump scaled to the clump diameter (its largest Feret
/// diameter) `diameter`: members (in units of D) at (0, 0, 0), (0.329, 0, 0), (0.323, 0.314, 0)
/// and (0.034, 0.226, 0.281) with radii 0.264, 0.266, 0.260 and 0.268, shifted so that the
/// union's centroid is the origin. Fitted (least squares over the centres and radii, member
/// diameters held in [0.5, 0.6]·D) to aspect ratio 1.50 and convexity indices 2.07 and 1.16;
/// clump_shape gives what this template has (docs/physics.md).
std::vector<ClumpMember> asymmetric_clump4(double diameter);

/// Shape measures of a clump (seed 004 §4.3's definitions).
struct ClumpShape {
  double volume = 0;            // m³, union of the members
  double max_feret = 0;         // m, largest caliper width (the clump diameter)
  double min_feret = 0;         // m, smallest caliper width
  double aspect_ratio = 0;      // max_feret / min_feret
  double enclosing_radius = 0;  // m, smallest sphere containing every member
  double hull_volume = 0;       // m³, convex hull of the union
  double convexity_sphere = 0;  // enclosing sphere volume / volume ("index 1")
  double convexity_hull = 0;    // hull volume / volume ("index 2")
};
/// Feret widths over `directions` directions (a Fibonacci sphere, refined around the extremes),
/// the smallest enclosing sphere of the members (CGAL Min_sphere_of_spheres_d, exact), the
/// hull of `surface_points` points on each member's surface (CGAL convex_hull_3; the volume
/// converges from below as 1/points), the union volume from union_mass_properties.
ClumpShape clump_shape(const std::vector<ClumpMember>& members, int directions = 20000,
                       int surface_points = 20000);

/// A uniformly distributed random rotation (Shoemake's method on three uniform variates).
Eigen::Quaterniond random_orientation(std::mt19937_64& rng);

/// Replaces each sphere by a clump of the template shape with the sphere's volume (the union's
/// volume: the template scaled by cbrt(V_sphere / V_union)), its centroid at the sphere's
/// centre and a random orientation (seed 003 §2.4). Members get ids from `first_id` on; the
/// clumps' member indices count from `first_index` (where the members will sit in the
/// simulation's particle list). Clump ids are left at −1.
struct ClumpReplacement {
  std::vector<Particle> members;
  std::vector<ClumpBody> clumps;
};
ClumpReplacement replace_by_clumps(const std::vector<Particle>& spheres,
                                   const std::vector<ClumpMember>& shape, double density,
                                   ClumpMassModel model, std::mt19937_64& rng,
                                   std::int64_t first_id, std::uint32_t first_index);

}  // namespace gs::solver
