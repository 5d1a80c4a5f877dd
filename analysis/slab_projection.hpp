// Projection of the particles of a slab onto its mid-plane (seed 000 §5: a slice of thickness
// 5 d50 whose sphere centres are projected onto the plane, no averaging over the thickness).
// Gives 2D data for the void-cell and triangle analyses from a 3D assembly.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace gs::analysis {

struct Slab {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // a point on the mid-plane
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // plane normal (normalised internally)
  Eigen::Vector3d axis1 = Eigen::Vector3d::UnitX();   // in-plane x axis (made orthogonal)
  double thickness = 0.0;                             // m, > 0
};

struct SlabProjection {
  std::vector<std::int32_t> index;        // input index of each selected particle
  std::vector<Eigen::Vector2d> position;  // in-plane coordinates (axis1, normal x axis1)
  std::vector<Eigen::Vector2d> vector;    // projected vectors (velocity or displacement)
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
};

/// Orthonormal axes of the slab as the rows of a matrix: e1 (axis1 made orthogonal to the
/// normal), e2 = n x e1, n; local coordinates are axes * (x - origin). Throws std::invalid_argument
/// for a thickness <= 0, a zero normal, or axis1 parallel to the normal.
Eigen::Matrix3d slab_axes(const Slab& slab);

/// Selects |(x - origin) . n| <= thickness / 2 and projects positions and `vectors` (same size
/// as `positions`, may be empty) onto the plane. Throws std::invalid_argument for a thickness
/// <= 0, a zero normal, or axis1 parallel to the normal.
SlabProjection project_slab(const std::vector<Eigen::Vector3d>& positions,
                            const std::vector<Eigen::Vector3d>& vectors, const Slab& slab);

}  // namespace gs::analysis
