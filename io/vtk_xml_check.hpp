// A check of a VTK XML file's structure before VTK's readers see it: VTK trusts the header
// (negative or huge NumberOfPoints, a compression header claiming 2^30 blocks, elements nested
// 200 000 deep) and crashes, allocates gigabytes, or reads fewer values than the file holds.
#pragma once

#include <filesystem>

namespace gs {

/// Throws InputError naming the file when: elements nest deeper than 64 levels; a Piece count
/// (NumberOfPoints, NumberOfCells, NumberOfVerts, ...) is not a non-negative integer or exceeds
/// what a file of this size can hold; a numeric DataArray of Points, PointData, CellData or a
/// Cells offsets/types array holds a different number of values than the counts declare (ASCII
/// tokens, or the byte count in a binary / appended header); or a compression header claims more
/// blocks or bytes than the file can hold.
void check_vtk_xml_structure(const std::filesystem::path& path);

}  // namespace gs
