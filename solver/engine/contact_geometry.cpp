#include "contact_geometry.hpp"

#include <cmath>

namespace gs::solver {

void box_sphere_geometry_inside(const V3& h, const V3& x, const V3& on_box, double r,
                                ContactGeometry& g) {
  const double hv[3] = {h.x, h.y, h.z}, ov[3] = {on_box.x, on_box.y, on_box.z};
  int kmin = 0;
  double dmin = hv[0] - std::abs(ov[0]);
  for (int k = 1; k < 3; ++k) {
    const double t = hv[k] - std::abs(ov[k]);
    if (t < dmin) {
      dmin = t;
      kmin = k;
    }
  }
  Eigen::Vector3d face = Eigen::Vector3d::Zero();
  face[kmin] = ov[kmin] > 0 ? 1.0 : -1.0;
  const Eigen::Vector3d xe = x.eigen();
  const Eigen::Vector3d pt1 = xe + face * dmin, pt2 = xe - face * r;
  g.normal = V3((pt1 - pt2).normalized());
  g.point = V3(0.5 * (pt1 + pt2));
  g.penetration = (pt1 - pt2).norm();
  g.ratchet_free = true;
}

double box_distance(const Eigen::Vector3d& c, const Eigen::Vector3d& h, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = ((x - c).cwiseAbs() - h).cwiseMax(0.0);
  return d.norm();
}

}  // namespace gs::solver
