// LIGGGHTS / LAMMPS text dumps: `dump custom` atom snapshots and `dump local` pair entries.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "snapshot.hpp"

namespace gs {

struct LiggghtsImportOptions {
  /// Local (pair) dump with contacts; matched to the atom frames by timestep.
  std::optional<std::filesystem::path> pairs;
  /// Meaning of the pair dump's columns, in order. Default: LIGGGHTS
  /// `compute pair/gran/local pos id force` (force = force on the first atom).
  std::vector<std::string> pair_columns{"x1",  "y1",  "z1",       "x2", "y2", "z2",
                                        "id1", "id2", "periodic", "fx", "fy", "fz"};
  /// Time step (s): frame time = timestep × dt. 0 leaves times at 0.
  double dt = 0;
};

/// Reads every frame of an atom dump. Required columns: id, x|xu, y|yu, z|zu, radius; optional:
/// type (material id), vx vy vz, omegax omegay omegaz, mass. Contacts (when `pairs` is given)
/// carry YADE's convention (force by id1 on id2, normal from id1 to id2).
Trajectory read_liggghts_dump(const std::filesystem::path& atoms,
                              const LiggghtsImportOptions& options = {});

/// The pairs file conventionally next to an atom dump: `X.atoms` -> `X.pairs`,
/// `dump*.atoms*` -> same name with "atoms" replaced by "pairs"; empty if none exists.
std::optional<std::filesystem::path> liggghts_pairs_sibling(const std::filesystem::path& atoms);

}  // namespace gs
