#include "spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace gs::solver {

namespace {

// The 21 low bits of v spread to every third bit of the result.
std::uint64_t spread3(std::uint32_t v) {
  std::uint64_t x = v & 0x1fffffu;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

}  // namespace

std::uint64_t morton_code(std::uint32_t ix, std::uint32_t iy, std::uint32_t iz) {
  return spread3(ix) | spread3(iy) << 1 | spread3(iz) << 2;
}

std::vector<std::uint32_t> spatial_order(const std::vector<Eigen::Vector3d>& centres,
                                         double cell_m) {
  if (!(cell_m > 0) || !std::isfinite(cell_m))
    throw std::invalid_argument("spatial order: cell size not positive and finite (" +
                                std::to_string(cell_m) + ")");
  std::vector<std::uint32_t> order(centres.size());
  std::iota(order.begin(), order.end(), 0u);
  if (centres.empty()) return order;
  Eigen::Vector3d lo = centres[0], hi = centres[0];
  for (std::size_t i = 0; i < centres.size(); ++i) {
    if (!centres[i].allFinite())
      throw std::invalid_argument("spatial order: particle " + std::to_string(i) +
                                  " has a non-finite centre");
    lo = lo.cwiseMin(centres[i]);
    hi = hi.cwiseMax(centres[i]);
  }
  constexpr double kCells = 2097151.0;  // 2^21 - 1: the largest coordinate a code holds
  const double cell = std::max(cell_m, (hi - lo).maxCoeff() / kCells);
  std::vector<std::uint64_t> code(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d c = ((centres[i] - lo) / cell).array().floor().min(kCells);
    code[i] = morton_code(static_cast<std::uint32_t>(c.x()), static_cast<std::uint32_t>(c.y()),
                          static_cast<std::uint32_t>(c.z()));
  }
  std::stable_sort(order.begin(), order.end(),
                   [&code](std::uint32_t a, std::uint32_t b) { return code[a] < code[b]; });
  return order;
}

}  // namespace gs::solver
