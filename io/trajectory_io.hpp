// Reading and writing snapshots by file type, for `granoscope info` / `convert` and for every
// analysis that accepts "any snapshot".
#pragma once

#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "liggghts_dump.hpp"
#include "snapshot.hpp"

namespace gs {

enum class SnapshotFormat { Hdf5, Vtu, Pvd, YadeLegacyVtk, PackingCsv, LiggghtsDump, ParticleText };

std::string format_name(SnapshotFormat f);

/// By content where it is unambiguous (HDF5 signature, "ITEM: TIMESTEP", "# vtk DataFile", a
/// first line starting "Radius": DEM8 particle text), else by extension (.h5 .hdf5 .vtu .pvd
/// .vtk .csv). Throws InputError when unknown.
SnapshotFormat detect_format(const std::filesystem::path& path);
/// By extension only, for outputs: .h5/.hdf5, .vtu, .pvd, .csv.
SnapshotFormat output_format(const std::filesystem::path& path);

struct ImportOptions {
  /// Contacts file for formats that keep them apart (YADE legacy interactions, LIGGGHTS local
  /// dump). Default: the sibling found by naming convention, if any.
  std::optional<std::filesystem::path> contacts;
  LiggghtsImportOptions liggghts;
  /// DEM8 particle text only: read at most this many particles (particle_text.hpp).
  std::size_t max_particles = std::numeric_limits<std::size_t>::max();
};

Trajectory read_snapshots(const std::filesystem::path& path, const ImportOptions& options = {});

/// Writes all frames (.h5, .pvd) or one frame (.vtu plus contacts in a .vtp of the same stem,
/// .csv): `frame` < 0 counts from the end (-1 = last).
void write_snapshots(const std::filesystem::path& path, const Trajectory& trajectory,
                     long frame = -1);

}  // namespace gs
