#include "triangle_facet.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::solver {

namespace {
// Norms as YADE's Eigen evaluates them (x + (y + z), scalar_vec3.hpp).
double norm(const V3& a) {
  return std::sqrt(squared_norm(a));
}
V3 normalized(const V3& a) {
  return a / std::sqrt(squared_norm(a));
}
}  // namespace

Eigen::Vector3d incircle_centre(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1,
                                const Eigen::Vector3d& v2) {
  const V3 a(v0), b(v1), c(v2);
  const double l01 = norm(b - a), l12 = norm(c - b), l20 = norm(a - c), l02 = norm(c - a);
  return (a + ((c - a) * l01 + (b - a) * l02) / (l01 + l12 + l20)).eigen();
}

TriangleFacet make_triangle_facet(const Eigen::Vector3d& v0, const Eigen::Vector3d& v1,
                                  const Eigen::Vector3d& v2, const Eigen::Vector3d& reference) {
  if (!v0.allFinite() || !v1.allFinite() || !v2.allFinite())
    throw std::invalid_argument("triangle vertex is not finite");
  const V3 centre(incircle_centre(v0, v1, v2));
  TriangleFacet f;
  f.offset = centre - V3(reference);
  f.vertex[0] = V3(v0) - centre;
  f.vertex[1] = V3(v1) - centre;
  f.vertex[2] = V3(v2) - centre;
  const V3 e[3] = {f.vertex[1] - f.vertex[0], f.vertex[2] - f.vertex[1], f.vertex[0] - f.vertex[2]};
  // Facet::postLoad, expression by expression.
  const V3 n = cross(e[0], e[1]);
  f.area = 0.5 * norm(n);
  if (!(f.area > 0) || !std::isfinite(f.area))
    throw std::invalid_argument("triangle has zero area (" + std::to_string(f.area) + " m^2)");
  f.normal = n / (2 * f.area);
  for (int i = 0; i < 3; ++i) {
    f.edge_normal[i] = normalized(cross(e[i], f.normal));
    f.vertex_length[i] = norm(f.vertex[i]);
    f.vertex_unit[i] = f.vertex[i] / f.vertex_length[i];
  }
  const double p = norm(e[0]) + norm(e[1]) + norm(e[2]);
  f.incircle_radius = norm(e[0]) * dot(f.edge_normal[0], e[2]) / p;
  return f;
}

TriangleFacet rotated_facet(const TriangleFacet& f, const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  auto rot = [&](const V3& v) { return V3(R * v.eigen()); };
  TriangleFacet g = f;
  g.offset = rot(f.offset);
  g.normal = rot(f.normal);
  for (int i = 0; i < 3; ++i) {
    g.vertex[i] = rot(f.vertex[i]);
    g.edge_normal[i] = rot(f.edge_normal[i]);
    g.vertex_unit[i] = rot(f.vertex_unit[i]);
  }
  return g;
}

}  // namespace gs::solver
