// Flexible lateral boundary (the membrane of a plane-strain test, seed 000 §3: "flexible
// vertical walls ... model the membrane surrounding the specimen"): a confining pressure applied
// as forces on the particles that currently form the specimen's two lateral faces.
//
// Method. The faces normal to x are sampled by rays parallel to x on a regular (y, z) grid of
// spacing `bin_m` over the specimen's span. Each ray, cast from outside, hits one sphere first:
// that sphere carries the ray's tributary area ΔyΔz. The hits form the face x_s(y, z); its slopes
// (central differences over ±`normal_stencil_m`, capped at 1) give the outward vector area
// dA = (∓1, ±∂x_s/∂y, ±∂x_s/∂z)·ΔyΔz, and the load on the sphere is −σc·dA. Summed over a face the
// loads are exactly σc × (projected area) along x, whatever the roughness; the lateral
// components follow the face's inclination (bulging, shear-band offsets). The volume between the
// faces, Σ (x₊ − x₋)·ΔyΔz, gives the specimen volume. The rubber's own stiffness is neglected.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "dem_types.hpp"

namespace gs::solver {

struct MembraneSpec {
  double pressure_Pa = 0;
  double bin_m = 0;             // ray spacing in y and z
  double normal_stencil_m = 0;  // half-width of the slope estimate (0: one bin)
};

struct MembraneLoads {
  std::vector<std::uint32_t> particle;  // loaded particles (each once)
  std::vector<Eigen::Vector3d> force;   // their loads, N (parallel to `particle`)
  int ny = 0, nz = 0;                   // ray grid
  double bin_area_m2 = 0;
  std::vector<double> x_minus, x_plus;  // hit position of each ray (NaN: missed), z-major
  double volume_m3 = 0;                 // between the faces, over the rays that hit on both
  double mean_width_m = 0;              // volume / (span area)
  std::size_t missed_rays = 0;
  Eigen::Vector3d total_minus = Eigen::Vector3d::Zero();  // Σ loads on the x− face
  Eigen::Vector3d total_plus = Eigen::Vector3d::Zero();
};

/// Loads of the two membranes normal to x over y ∈ [y_lo, y_hi], z ∈ [z_lo, z_hi].
MembraneLoads membrane_loads(const ParticleState& p, double y_lo, double y_hi, double z_lo,
                             double z_hi, const MembraneSpec& spec);
/// The same from the spheres' centres and radii.
MembraneLoads membrane_loads(const std::vector<Eigen::Vector3d>& pos,
                             const std::vector<double>& radius, double y_lo, double y_hi,
                             double z_lo, double z_hi, const MembraneSpec& spec);

}  // namespace gs::solver
