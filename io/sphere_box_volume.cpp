// Exact sphere–box volume by the octant function (derivation in the header and docs/analysis.md).
#include "sphere_box_volume.hpp"

#include <cmath>
#include <numbers>

namespace gs {
namespace {

constexpr double kPi = std::numbers::pi;

/// Area of the disc of squared radius rho2 cut by p' > p, q' > q (p, q >= 0, p^2 + q^2 < rho2),
/// with hp = sqrt(rho2 - p^2), hq = sqrt(rho2 - q^2) the other coordinates of the two corners.
/// Also returns the arc angle phi between the corners (p, hp) and (hq, q).
double face_area(double rho2, double p, double q, double hp, double hq, double& phi) {
  phi = std::atan2(hq * hp - q * p, hq * p + q * hp);
  return 0.5 * rho2 * phi - 0.5 * (hq * q + p * hp) + p * q;
}

}  // namespace

double disc_quadrant_area(double r, double a, double b) {
  const double r2 = r * r;
  if (a * a + b * b >= r2) return 0.0;
  if (a == 0.0 && b == 0.0) return 0.25 * kPi * r2;
  double phi = 0.0;
  return face_area(r2, a, b, std::sqrt(r2 - a * a), std::sqrt(r2 - b * b), phi);
}

double sphere_octant_volume(double r, double a, double b, double c) {
  const double r2 = r * r, a2 = a * a, b2 = b * b, c2 = c * c;
  if (a2 + b2 + c2 >= r2) return 0.0;
  const int zeros = (a == 0.0) + (b == 0.0) + (c == 0.0);
  if (zeros == 3) return kPi * r2 * r / 6.0;
  if (zeros == 2) {  // a quarter of the cap beyond the one non-zero offset h
    const double h = a + b + c;
    return kPi * (r - h) * (r - h) * (2.0 * r + h) / 12.0;
  }
  // Corner heights: z_ab is the third coordinate of the corner on the planes x = a, y = b.
  const double zab = std::sqrt(r2 - a2 - b2), zbc = std::sqrt(r2 - b2 - c2),
               zca = std::sqrt(r2 - c2 - a2);
  double phi_a = 0.0, phi_b = 0.0, phi_c = 0.0;
  const double area_a = face_area(r2 - a2, b, c, zab, zca, phi_a);
  const double area_b = face_area(r2 - b2, c, a, zbc, zab, phi_b);
  const double area_c = face_area(r2 - c2, a, b, zca, zbc, phi_c);
  const double exterior =
      std::atan2(r * zab, -a * b) + std::atan2(r * zbc, -b * c) + std::atan2(r * zca, -c * a);
  const double omega = 2.0 * kPi - (a * phi_a + b * phi_b + c * phi_c) / r - exterior;
  return (r2 * r * omega - a * area_a - b * area_b - c * area_c) / 3.0;
}

int half_space_terms(double offset, double r, HalfSpaceTerm out[2]) {
  if (offset >= r) return 0;  // misses the ball
  if (offset <= -r) {         // whole ball
    out[0] = {0.0, 2.0};
    return 1;
  }
  if (offset >= 0.0) {
    out[0] = {offset, 1.0};
    return 1;
  }
  out[0] = {0.0, 2.0};  // whole ball minus the mirror image x > |offset|
  out[1] = {-offset, -1.0};
  return 2;
}

namespace {

/// Terms of the slab lo < x < hi: up to 3 after merging alpha = 0.
int interval_terms(double lo, double hi, double r, HalfSpaceTerm out[4]) {
  HalfSpaceTerm t[2];
  int n = 0;
  auto add = [&](double alpha, double coef) {
    for (int k = 0; k < n; ++k) {
      if (out[k].alpha == alpha) {
        out[k].coef += coef;
        return;
      }
    }
    out[n++] = {alpha, coef};
  };
  for (int k = 0, m = half_space_terms(lo, r, t); k < m; ++k) add(t[k].alpha, t[k].coef);
  for (int k = 0, m = half_space_terms(hi, r, t); k < m; ++k) add(t[k].alpha, -t[k].coef);
  return n;
}

}  // namespace

double sphere_box_volume(const Eigen::Vector3d& centre, double r, const Eigen::Vector3d& lo,
                         const Eigen::Vector3d& hi) {
  HalfSpaceTerm t[3][4];
  int n[3];
  bool inside = true;
  for (int d = 0; d < 3; ++d) {
    const double l = lo[d] - centre[d], h = hi[d] - centre[d];
    if (!(h > l) || l >= r || h <= -r) return 0.0;
    inside = inside && l <= -r && h >= r;
    n[d] = interval_terms(l, h, r, t[d]);
  }
  if (inside) return 4.0 / 3.0 * kPi * r * r * r;
  double v = 0.0;
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j)
      for (int k = 0; k < n[2]; ++k) {
        const double coef = t[0][i].coef * t[1][j].coef * t[2][k].coef;
        if (coef != 0.0)
          v += coef * sphere_octant_volume(r, t[0][i].alpha, t[1][j].alpha, t[2][k].alpha);
      }
  return v;
}

double disc_rectangle_area(const Eigen::Vector2d& centre, double r, const Eigen::Vector2d& lo,
                           const Eigen::Vector2d& hi) {
  HalfSpaceTerm t[2][4];
  int n[2];
  bool inside = true;
  for (int d = 0; d < 2; ++d) {
    const double l = lo[d] - centre[d], h = hi[d] - centre[d];
    if (!(h > l) || l >= r || h <= -r) return 0.0;
    inside = inside && l <= -r && h >= r;
    n[d] = interval_terms(l, h, r, t[d]);
  }
  if (inside) return kPi * r * r;
  double a = 0.0;
  for (int i = 0; i < n[0]; ++i)
    for (int j = 0; j < n[1]; ++j) {
      const double coef = t[0][i].coef * t[1][j].coef;
      if (coef != 0.0) a += coef * disc_quadrant_area(r, t[0][i].alpha, t[1][j].alpha);
    }
  return a;
}

}  // namespace gs
