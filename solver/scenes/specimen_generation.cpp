#include "specimen_generation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace gs::solver {

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double draw_diameter(const SizeSpec& s, std::mt19937_64& rng) {
  if (!(s.dmin_m > 0) || !(s.dmax_m >= s.dmin_m))
    throw std::invalid_argument("size distribution needs 0 < dmin <= dmax");
  const double u = uniform01(rng);
  if (s.distribution == SizeDistribution::Uniform) return s.dmin_m + u * (s.dmax_m - s.dmin_m);
  // Number density ∝ d⁻³ on [dmin, dmax]: F(d) = (dmin⁻² − d⁻²)/(dmin⁻² − dmax⁻²).
  const double a = 1 / (s.dmin_m * s.dmin_m), b = 1 / (s.dmax_m * s.dmax_m);
  return 1 / std::sqrt(a - u * (a - b));
}

std::vector<double> draw_diameters(const SizeSpec& size, double solid_volume_m3,
                                   std::mt19937_64& rng) {
  if (!(solid_volume_m3 > 0)) throw std::invalid_argument("solid volume must be positive");
  const double vmin = M_PI / 6 * std::pow(size.dmin_m, 3);
  if (solid_volume_m3 / vmin > 2e7)
    throw std::invalid_argument("more than 20 million particles requested");
  std::vector<double> d;
  double v = 0;
  while (v < solid_volume_m3) {
    d.push_back(draw_diameter(size, rng));
    v += M_PI / 6 * std::pow(d.back(), 3);
  }
  std::sort(d.begin(), d.end(), std::greater<>());
  return d;
}

std::vector<Particle> random_sequential_packing(const std::vector<double>& diameters,
                                                const Eigen::Vector3d& lo,
                                                const Eigen::Vector3d& hi, std::mt19937_64& rng,
                                                int max_attempts) {
  std::vector<Particle> out;
  if (diameters.empty()) return out;
  const double dmax = *std::max_element(diameters.begin(), diameters.end());
  if (((hi - lo).array() <= dmax).any())
    throw std::invalid_argument("generation box is smaller than the largest sphere");
  // Hash grid of cell size dmax: a sphere can only overlap spheres in the 27 cells around it.
  const double cell = dmax;
  Eigen::Array3i dims;
  for (int k = 0; k < 3; ++k)
    dims[k] = std::max(1, static_cast<int>(std::floor((hi[k] - lo[k]) / cell)));
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> grid;
  auto cell_of = [&](const Eigen::Vector3d& x) {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>((x[k] - lo[k]) / cell), 0, dims[k] - 1);
    return c;
  };
  auto key = [&](int x, int y, int z) {
    return (static_cast<std::int64_t>(z) * dims[1] + y) * dims[0] + x;
  };
  out.reserve(diameters.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) {
    const double r = 0.5 * diameters[i];
    bool placed = false;
    for (int attempt = 0; attempt < max_attempts && !placed; ++attempt) {
      Eigen::Vector3d x;
      for (int k = 0; k < 3; ++k) x[k] = lo[k] + r + uniform01(rng) * (hi[k] - lo[k] - 2 * r);
      const auto c = cell_of(x);
      bool free = true;
      for (int dz = -1; dz <= 1 && free; ++dz)
        for (int dy = -1; dy <= 1 && free; ++dy)
          for (int dx = -1; dx <= 1 && free; ++dx) {
            const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
            if (cx < 0 || cy < 0 || cz < 0 || cx >= dims[0] || cy >= dims[1] || cz >= dims[2])
              continue;
            const auto it = grid.find(key(cx, cy, cz));
            if (it == grid.end()) continue;
            for (const auto j : it->second) {
              const double reach = r + out[j].radius;
              if ((out[j].position - x).squaredNorm() < reach * reach) {
                free = false;
                break;
              }
            }
          }
      if (!free) continue;
      Particle p;
      p.id = static_cast<std::int64_t>(i);
      p.position = x;
      p.radius = r;
      grid[key(c[0], c[1], c[2])].push_back(static_cast<std::uint32_t>(out.size()));
      out.push_back(p);
      placed = true;
    }
    if (!placed)
      throw std::invalid_argument("random packing: sphere " + std::to_string(i) + " of " +
                                  std::to_string(diameters.size()) + " found no free place after " +
                                  std::to_string(max_attempts) +
                                  " draws (generation box too small for the solid volume)");
  }
  return out;
}

double void_ratio(const std::vector<double>& radii, double box_volume_m3) {
  double vs = 0;
  for (double r : radii) vs += 4.0 / 3.0 * M_PI * r * r * r;
  if (!(vs > 0)) return std::numeric_limits<double>::quiet_NaN();
  return box_volume_m3 / vs - 1;
}

}  // namespace gs::solver
