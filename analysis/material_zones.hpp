// Per-material counts in zones and centres of mass of one frame: the mixing monitor of the
// DEM8 benchmark's rotating drum (Dosta et al. 2024, Case 2: the M1 and M2 particles counted in
// the quadrants x > 0, z < 0 and x < 0, z > 0 of the drum's cross-section, and each material's
// centre of mass, against time). A particle's material is its `material_id` in the frame.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

/// An open box lo < x < hi (componentwise; bounds may be infinite): the benchmark's quadrant
/// tests are strict (YADE's script counts pos[0] > 0 and pos[2] < 0).
struct Zone {
  std::string name;
  Eigen::Vector3d lo, hi;
};

struct MaterialStats {
  std::int32_t material = 0;
  std::size_t count = 0;
  double mass_kg = 0;  // Σ m (Σ r³ when a particle's mass is not recorded: then centre by volume)
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // Σ m·x / Σ m
  std::vector<std::size_t> in_zone;                    // per zone, the particles inside
};

/// The materials present in the particles, in increasing id, with their counts, masses, centres
/// of mass and counts in each zone. Throws std::invalid_argument for a zone with lo ≥ hi on an
/// axis.
std::vector<MaterialStats> material_zone_stats(const std::vector<Particle>& particles,
                                               const std::vector<Zone>& zones);

/// Parses "NAME:xlo,ylo,zlo,xhi,yhi,zhi" (bounds may be inf or -inf); std::invalid_argument
/// saying what is wrong.
Zone parse_zone(const std::string& spec);

}  // namespace gs::analysis
