// Per-material counts in zones and centres of mass of one frame: the mixing monitor of the
// DEM8 benchmark's rotating drum (Dosta et al. 2024, Case 2: the M1 and M2 particles counted in
// the quadrants x > 0, z < 0 and x < 0, z > 0 of the drum's cross-section, and each material's
// centre of mass, against time). A particle's material is its `material_id` in the frame.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "field_output.hpp"
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

/// The zones of `analyze materials`: with `drum` the benchmark's quadrants x+z- and x-z+, then
/// `specs` parsed. Throws InputError (naming `file`) for a bad spec or a name used twice.
std::vector<Zone> material_zones(const std::string& file, bool drum,
                                 const std::vector<std::string>& specs);

/// Per frame (0, every, 2 every, ... of `frames`, read by `frame(i)`): columns step, time_s, then
/// for each material (named by `names[id]`, else "material<id>") NAME_count, NAME_com_x_m,
/// NAME_com_y_m, NAME_com_z_m and per zone ZONE_NAME_count; `materials` gets their number.
std::vector<VtkArray> material_table(const std::string& file, long frames,
                                     const std::function<Frame(long)>& frame, long every,
                                     const std::vector<Zone>& zones,
                                     const std::vector<std::string>& names,
                                     std::size_t* materials = nullptr);

/// The material names a granoscope run recorded (metadata "material_names", comma-separated).
std::vector<std::string> recorded_material_names(
    const std::vector<std::pair<std::string, std::string>>& parameters);

}  // namespace gs::analysis
