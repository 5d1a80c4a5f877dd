// `analyze invariants` on a frame (the CLI and the Python package both call this): the
// specimen's stress from its contacts (Love–Weber over a box, or over the periodic cell; with
// wall contacts also the boundary stress of seed 003 eq 14), and the deformation gradient
// fitted to the motion between two frames.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>

#include "snapshot.hpp"

namespace gs::analysis {

struct SpecimenStress {
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();  // Pa (2D: N/m), compression positive
  double volume = 0.0;                              // m^3 (2D: m^2 per unit depth)
  std::optional<Eigen::Matrix3d> boundary_eq14;     // from the wall contacts, when there are any
  int dim = 3;
};

/// Love–Weber stress over `region` (lo, hi) when given; else over the periodic cell of a
/// periodic frame (every minimum-image branch in full), else over the particles' bounding box
/// (2D frames: per unit depth). Throws InputError naming `file`.
SpecimenStress specimen_stress(
    const std::string& file, const Frame& f,
    const std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& region);

/// Least-squares deformation gradient of the particles matched by id: x - <x> = F (X - <X>)
/// (2D frames: the in-plane block). Throws InputError naming `file` when the matched particles
/// are degenerate (coplanar) or too few.
Eigen::Matrix3d fit_deformation_gradient(const std::string& file, const Frame& from,
                                         const Frame& to);

}  // namespace gs::analysis
