// Particle text files of the DEM8 benchmark (../shared/dem8: MercuryDPM's OSBenchmark inputs):
// a header naming the columns `Radius[m] PosX[m] PosY[m] PosZ[m]` (any order, units in
// brackets optional), then one particle per line, whitespace separated, CRLF allowed.
#pragma once

#include <cstddef>
#include <filesystem>
#include <limits>

#include "snapshot.hpp"

namespace gs {

/// One frame of particles at rest (ids 0, 1, … in file order, mass 0). `max_rows` stops after
/// that many particles: the DEM8 penetration beds end with a row that is not a particle
/// (MercuryDPM's driver reads the count it expects and ignores the rest). Every row read must have
/// the header's number of columns. Throws InputError naming the file, the line and the value.
Frame read_particle_text(const std::filesystem::path& path,
                         std::size_t max_rows = std::numeric_limits<std::size_t>::max());

/// True when the file's first non-blank line starts with "Radius" (the format above).
bool is_particle_text(const std::filesystem::path& path);

}  // namespace gs
