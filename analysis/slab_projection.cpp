// Seed 000 §5: 2D data from a 3D slab projected onto its plane.
#include "slab_projection.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::analysis {

Eigen::Matrix3d slab_axes(const Slab& slab) {
  if (!(slab.thickness > 0.0) || !std::isfinite(slab.thickness)) {
    throw std::invalid_argument("slab thickness must be > 0 (" + std::to_string(slab.thickness) +
                                ")");
  }
  const double nn = slab.normal.norm();
  if (!(nn > 0.0) || !slab.normal.allFinite()) throw std::invalid_argument("slab normal is zero");
  const Eigen::Vector3d n = slab.normal / nn;
  Eigen::Vector3d e1 = slab.axis1 - slab.axis1.dot(n) * n;
  if (!(e1.norm() > 1e-12 * slab.axis1.norm())) {
    throw std::invalid_argument("slab axis1 is parallel to the normal");
  }
  e1.normalize();
  Eigen::Matrix3d axes;
  axes.row(0) = e1;
  axes.row(1) = n.cross(e1);
  axes.row(2) = n;
  return axes;
}

SlabProjection project_slab(const std::vector<Eigen::Vector3d>& positions,
                            const std::vector<Eigen::Vector3d>& vectors, const Slab& slab) {
  const Eigen::Matrix3d axes = slab_axes(slab);
  if (!vectors.empty() && vectors.size() != positions.size()) {
    throw std::invalid_argument("one vector per particle needed (" +
                                std::to_string(vectors.size()) + " for " +
                                std::to_string(positions.size()) + ")");
  }
  const Eigen::Vector3d n = axes.row(2);
  SlabProjection p;
  p.e1 = axes.row(0);
  p.e2 = axes.row(1);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Eigen::Vector3d d = positions[i] - slab.origin;
    if (std::abs(d.dot(n)) > 0.5 * slab.thickness) continue;
    p.index.push_back(static_cast<std::int32_t>(i));
    p.position.emplace_back(d.dot(p.e1), d.dot(p.e2));
    if (!vectors.empty()) p.vector.emplace_back(vectors[i].dot(p.e1), vectors[i].dot(p.e2));
  }
  return p;
}

}  // namespace gs::analysis
