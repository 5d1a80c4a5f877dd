// Local strain of a frame's motion as `granoscope analyze strain` computes it (and Python's
// granoscope.strain): Delaunay tetrahedra in 3D, triangles in 2D or on a slab projected onto its
// plane; per-particle and per-simplex measures, and on triangles seed 002's alignment alpha and
// vorticity w (eqs 18, 20, with the Bagi eq 4 triangle gradient). One implementation for both.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "frame_motion.hpp"
#include "selection.hpp"
#include "tet_strain.hpp"

namespace gs::analysis {

struct StrainSpec {
  double min_quality = 0.02;  // simplices below are slivers, left out of averages
  ProjectionSlabSpec slab;    // given: the particles of this slab, projected on its plane
  bool weighted = false;      // 3D: regular triangulation with weights radius^2
};

struct StrainReport {
  SimplexStrain strain;
  bool slab = false, weighted = false;
  std::vector<std::int64_t> id;           // particles that take part, by id
  std::vector<Eigen::Vector3d> position;  // their positions (slab: in-plane u, v, 0), m
  std::vector<double> volumetric, shear;  // per particle, from its gradient
  std::vector<double> rotation_xy;        // per particle: in-plane rotation (about z)
  std::vector<double> simplex_volumetric, simplex_shear;
  std::vector<double> alpha, w;  // per triangle (2D only)
  std::size_t slivers = 0;
};

/// Strain of motion `m` (velocities or displacements; file names the input in messages).
/// Throws InputError on bad options or a degenerate point set.
StrainReport strain_report(const std::string& file, const FrameMotion& m, const StrainSpec& spec);

}  // namespace gs::analysis
