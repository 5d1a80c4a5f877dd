// A REV map of one frame as `granoscope analyze rev` computes it (and the Python package's
// granoscope.rev): REV cell averages (box method, seed 000 §3) or Gaussian coarse-graining on a
// 3D grid or in a slab, named cell fields with their stress invariants, and profiles along a
// line; and the shear band located on a REV map (`analyze shearzone`). One implementation for
// the CLI and Python: apps/ and python/ only parse options and write or wrap the results.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "field_output.hpp"
#include "rev_cells.hpp"
#include "selection.hpp"
#include "shear_zone.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

/// REV grid sizes: cell L and step s, each in m or in d50 (defaults 5 d50 and 1 d50).
struct GridSpec {
  std::optional<double> cell, cell_d50, step, step_d50;
  double cell_size(const std::string& file, double d50) const;
  double step_size(const std::string& file, double d50) const;
};

/// Named cell fields of a map, in output order: scalars, 3-vectors, 3x3 tensors (row i, col j).
struct MapFields {
  std::vector<std::pair<std::string, std::vector<double>>> scalar;
  std::vector<std::pair<std::string, std::vector<Eigen::Vector3d>>> vector;
  std::vector<std::pair<std::string, std::vector<Eigen::Matrix3d>>> tensor;
  /// Every field flattened (tensors row-major), in the order above.
  std::vector<VtkArray> arrays() const;
};

struct RevMapSpec {
  std::string method = "box";  // box (REV cells) | gaussian (coarse-graining)
  GridSpec grid;
  std::optional<double> width, width_d50;  // gaussian kernel width (default 1 d50)
  double particle_density = 2650.0;        // kg/m^3 for particles without a mass
  SelectionSpec selection;                 // slab (a map in its plane) or region (3D)
};

struct RevMap {
  std::string method;
  RevGrid grid;
  double d50 = 0.0, cell = 0.0, step = 0.0, width = 0.0, slab_thickness = 0.0;  // m
  MapFields fields;
  std::size_t particle_contacts = 0, wall_contacts = 0;
  double seconds = 0.0;  // the averaging itself
  /// "2d", "slab" or "3d".
  std::string mode() const;
};

/// Per-particle displacement of `f`'s particles to frame `to` (matched by id).
ParticleMotion particle_motion(const Frame& f, const Frame& to, const std::string& file);

/// The map of frame `f` (with `to`: also the displacement from f to it). Throws InputError
/// (naming `file`) for bad options or a degenerate grid.
RevMap rev_map(const std::string& file, const Frame& f, const Frame* to, double d50,
               const RevMapSpec& spec);

/// All cells as table columns: centre (global), local (map coordinates), then every field.
std::vector<VtkArray> rev_cell_table(const RevMap& map);

/// A profile from p0 to p1 (6 numbers, m) at `points` points (0: one every half step), the
/// fields interpolated between cell centres (NaN outside): columns distance, point, fields.
std::vector<VtkArray> rev_profile(const std::string& file, const RevMap& map,
                                  const std::vector<double>& line, int points);

/// Rotation about the map normal (slab normal; z for 2D frames): the in-plane rotation.
std::vector<double> rotation_normal(const RevGrid& g, const std::vector<Eigen::Vector3d>& r);

struct ShearZoneSpec {
  std::string field = "rotation";  // rotation (|about the slab normal|) | shear (needs `to`)
  GridSpec grid;
  SelectionSpec selection;  // 3D frames: always a slab (default the front view)
};

struct ShearZoneMap {
  RevGrid grid;
  double d50 = 0.0, cell = 0.0, step = 0.0;  // m
  ScalarMap map;                             // the field, rows v, columns u
  ShearZone zone;
};

/// The shear band of frame `f` (seed 000 §5: ridge of the rotation map, thickness from the
/// profile across it). Throws InputError (naming `file`).
ShearZoneMap shear_zone_map(const std::string& file, const Frame& f, const Frame* to, double d50,
                            const ShearZoneSpec& spec);

}  // namespace gs::analysis
