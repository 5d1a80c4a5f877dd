// Packing CSV: header `id,x,y,z,r` (any column order, extra columns ignored), metres;
// optional velocities `vx,vy,vz` (m/s).
#pragma once

#include <filesystem>

#include "snapshot.hpp"

namespace gs {

/// One frame of particles at rest; mass left 0 (unknown); domain = bounding box of the spheres.
Frame read_packing_csv(const std::filesystem::path& path);

/// Writes `id,x,y,z,r` with 17 significant digits (exact round trip), atomically.
void write_packing_csv(const std::filesystem::path& path, const Frame& frame);

}  // namespace gs
