// Points with vectors from CSV (the `--csv` input of `granoscope analyze hhd`): a header naming
// the columns x,y,ux,uy (2D) or x,y,z,ux,uy,uz (3D), in any order, optional `id`, extra columns
// ignored; one row per point; blank lines and lines starting with '#' skipped. Lengths in m,
// vectors in the user's unit (a displacement increment in m, or a velocity in m/s).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace gs {

struct PointVectors {
  int dim = 3;
  std::vector<std::int64_t> id;       // from the `id` column, else the row number from 0
  std::vector<Eigen::Vector3d> x, u;  // 2D: z = 0
};

/// Throws InputError naming the file, line and column: missing file, missing column (z without
/// uz or the reverse included), wrong field count, bad or non-finite number, no data rows.
PointVectors read_point_vectors_csv(const std::filesystem::path& path);

}  // namespace gs
