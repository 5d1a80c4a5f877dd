#include "contact_geometry.hpp"

#include <cmath>

namespace gs::solver {

bool sphere_sphere_geometry(const Eigen::Vector3d& x1, double r1, const Eigen::Vector3d& x2,
                            double r2, ContactGeometry& g) {
  Eigen::Vector3d n = x2 - x1;
  const double d = n.norm();
  if (!(d > 0)) return false;
  n /= d;
  g.normal = n;
  g.penetration = r1 + r2 - d;
  g.point = x1 + (r1 - 0.5 * g.penetration) * n;
  g.radius1 = r1;
  g.radius2 = r2;
  g.ratchet_free = true;
  return true;
}

void box_sphere_geometry(const Eigen::Vector3d& c, const Eigen::Vector3d& h,
                         const Eigen::Vector3d& x, double r, ContactGeometry& g) {
  const Eigen::Vector3d rel = x - c;
  Eigen::Vector3d on_box = rel;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    if (on_box[k] < -h[k]) {
      on_box[k] = -h[k];
      inside = false;
    }
    if (on_box[k] > h[k]) {
      on_box[k] = h[k];
      inside = false;
    }
  }
  g.radius1 = g.radius2 = r;
  if (inside) {
    int kmin = 0;
    double dmin = h[0] - std::abs(on_box[0]);
    for (int k = 1; k < 3; ++k) {
      const double t = h[k] - std::abs(on_box[k]);
      if (t < dmin) {
        dmin = t;
        kmin = k;
      }
    }
    Eigen::Vector3d face = Eigen::Vector3d::Zero();
    face[kmin] = on_box[kmin] > 0 ? 1.0 : -1.0;
    const Eigen::Vector3d pt1 = x + face * dmin, pt2 = x - face * r;
    g.normal = (pt1 - pt2).normalized();
    g.point = 0.5 * (pt1 + pt2);
    g.penetration = (pt1 - pt2).norm();
    g.ratchet_free = true;
    return;
  }
  Eigen::Vector3d to_box = on_box - rel;  // from the sphere centre to the closest box point
  g.penetration = r - to_box.norm();
  const Eigen::Vector3d pt1 = on_box + c;
  to_box.normalize();
  const Eigen::Vector3d pt2 = x + to_box * r;
  g.point = 0.5 * (pt1 + pt2);
  g.normal = -to_box;
  g.ratchet_free = false;
}

void plane_sphere_geometry(const Eigen::Vector3d& p, const Eigen::Vector3d& m,
                           const Eigen::Vector3d& x, double r, ContactGeometry& g) {
  const double dist = (x - p).dot(m);
  g.normal = m;
  g.penetration = r - dist;
  g.point = x - (r - 0.5 * g.penetration) * m;
  g.radius1 = g.radius2 = r;
  g.ratchet_free = false;
}

double box_distance(const Eigen::Vector3d& c, const Eigen::Vector3d& h, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = ((x - c).cwiseAbs() - h).cwiseMax(0.0);
  return d.norm();
}

}  // namespace gs::solver
