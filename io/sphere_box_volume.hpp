// Exact volume of a sphere cut by an axis-aligned box (and the area of a disc cut by a
// (In io/, the model both the solver and the analyses use: the solver prepares specimens to an
// exact core void ratio, the REV analysis measures it.)
// rectangle): the solid volume of a REV cell (seed 000 §3, seed 004 §4.2.3) without counting
// particle centres. Closed form, exact to round-off:
//
//  * Octant function. For a ball of radius r centred at 0 and offsets a, b, c >= 0,
//    V(a, b, c) = vol{|x| < r, x > a, y > b, z > c}. By the divergence theorem,
//      V = (r^3 Omega - a A_a - b A_b - c A_c) / 3,
//    A_a the area of the flat face x = a (a disc of radius sqrt(r^2 - a^2) cut by y > b, z > c)
//    and Omega the solid angle of the spherical face, from Gauss–Bonnet for a spherical triangle
//    bounded by three small circles: Omega = 2 pi - sum_k (a_k / r) phi_k - sum_corners E, where
//    phi_k is the arc angle on the circle x_k = a_k (also the angle of face k) and E the exterior
//    angle at a corner, E_ab = atan2(r sqrt(r^2 - a^2 - b^2), -a b).
//  * Negative offsets by the mirror symmetry of the ball: the half-space x > a with a < 0 is the
//    whole ball (= 2 x (x > 0)) minus the mirror of x > |a|.
//  * A box is the inclusion–exclusion of its planes: 1[lo < x < hi] = 1[x > lo] - 1[x > hi] per
//    axis, so the box volume is a signed sum of octant values (at most 3^3 terms).
#pragma once

#include <Eigen/Core>

namespace gs {

/// vol{|x| < r, x > a, y > b, z > c} for a, b, c >= 0 (offsets from the centre, any order).
double sphere_octant_volume(double r, double a, double b, double c);

/// area{|x| < r, x > a, y > b} for a, b >= 0.
double disc_quadrant_area(double r, double a, double b);

/// Volume of the ball (centre, r) inside the box lo <= x <= hi (0 when hi <= lo on an axis).
double sphere_box_volume(const Eigen::Vector3d& centre, double r, const Eigen::Vector3d& lo,
                         const Eigen::Vector3d& hi);

/// Area of the disc (centre, r) inside the rectangle lo <= x <= hi.
double disc_rectangle_area(const Eigen::Vector2d& centre, double r, const Eigen::Vector2d& lo,
                           const Eigen::Vector2d& hi);

/// One term of the half-space x > offset on a ball of radius r as a combination of
/// half-spaces x > alpha with alpha >= 0: value += coef * [x > alpha] (alpha = 0 with coef 2
/// stands for the whole ball). Returns the number of terms written (0, 1 or 2).
struct HalfSpaceTerm {
  double alpha = 0.0;
  double coef = 0.0;
};
int half_space_terms(double offset, double r, HalfSpaceTerm out[2]);

}  // namespace gs
