// A spatial order of the particles: their indices sorted along a Morton (Z-order) curve through
// a grid of cells about one largest diameter wide, so that particles near each other in space
// are near each other in memory. The engine's per-particle arrays, its candidate pairs (sorted by
// index) and its threads' shares (contiguous index ranges) all follow the index order: a packing
// listed in random spatial order (DEM8's drum bed) makes every pass gather from scattered memory
// and interleaves the threads' particles in space. LIGGGHTS sorts its atoms the same way
// (atom_modify sort, on by default); YADE keeps the file's order.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace gs::solver {

/// The Morton code of integer cell coordinates (each in [0, 2^21)): their bits interleaved,
/// x in bit 0, y in bit 1, z in bit 2, then the next bit of each.
std::uint64_t morton_code(std::uint32_t ix, std::uint32_t iy, std::uint32_t iz);

/// The permutation `order` (new index -> old index) that lists `centres` along the Morton curve
/// through cells of edge `cell_m` anchored at the centres' lower corner; cells are widened when
/// the extent would need more than 2^21 of them per axis. Ties (one cell) keep their index
/// order. Throws std::invalid_argument on a non-finite centre or a cell_m that is not positive
/// and finite.
std::vector<std::uint32_t> spatial_order(const std::vector<Eigen::Vector3d>& centres,
                                         double cell_m);

}  // namespace gs::solver
