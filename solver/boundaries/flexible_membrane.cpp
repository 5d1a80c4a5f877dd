#include "flexible_membrane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace gs::solver {

MembraneLoads membrane_loads(const ParticleState& p, double y_lo, double y_hi, double z_lo,
                             double z_hi, const MembraneSpec& spec) {
  return membrane_loads(p.pos, p.radius, y_lo, y_hi, z_lo, z_hi, spec);
}

MembraneLoads membrane_loads(const std::vector<Eigen::Vector3d>& pos,
                             const std::vector<double>& radius, double y_lo, double y_hi,
                             double z_lo, double z_hi, const MembraneSpec& spec) {
  if (pos.size() != radius.size())
    throw std::invalid_argument("membrane: positions and radii differ in number");
  if (!(spec.bin_m > 0)) throw std::invalid_argument("membrane bin size must be positive");
  if (!(y_hi > y_lo) || !(z_hi > z_lo)) throw std::invalid_argument("membrane span is empty");
  MembraneLoads out;
  out.ny = std::max(1, static_cast<int>(std::ceil((y_hi - y_lo) / spec.bin_m)));
  out.nz = std::max(1, static_cast<int>(std::ceil((z_hi - z_lo) / spec.bin_m)));
  const double dy = (y_hi - y_lo) / out.ny, dz = (z_hi - z_lo) / out.nz;
  out.bin_area_m2 = dy * dz;
  const std::size_t nb = static_cast<std::size_t>(out.ny) * static_cast<std::size_t>(out.nz);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
  out.x_minus.assign(nb, nan);
  out.x_plus.assign(nb, nan);
  std::vector<std::uint32_t> hit_minus(nb, none), hit_plus(nb, none);
  // First sphere along each ray from either side: per sphere, the rays through its disc.
  const std::size_t n = pos.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& c = pos[i];
    const double r = radius[i];
    const int j0 = std::max(0, static_cast<int>(std::ceil((c.y() - r - y_lo) / dy - 0.5)));
    const int j1 =
        std::min(out.ny - 1, static_cast<int>(std::floor((c.y() + r - y_lo) / dy - 0.5)));
    const int k0 = std::max(0, static_cast<int>(std::ceil((c.z() - r - z_lo) / dz - 0.5)));
    const int k1 =
        std::min(out.nz - 1, static_cast<int>(std::floor((c.z() + r - z_lo) / dz - 0.5)));
    for (int k = k0; k <= k1; ++k) {
      const double ez = z_lo + (k + 0.5) * dz - c.z();
      for (int j = j0; j <= j1; ++j) {
        const double ey = y_lo + (j + 0.5) * dy - c.y();
        const double d2 = r * r - ey * ey - ez * ez;
        if (d2 < 0) continue;
        const double h = std::sqrt(d2);
        const std::size_t b = static_cast<std::size_t>(k) * out.ny + static_cast<std::size_t>(j);
        if (hit_minus[b] == none || c.x() - h < out.x_minus[b]) {
          out.x_minus[b] = c.x() - h;
          hit_minus[b] = static_cast<std::uint32_t>(i);
        }
        if (hit_plus[b] == none || c.x() + h > out.x_plus[b]) {
          out.x_plus[b] = c.x() + h;
          hit_plus[b] = static_cast<std::uint32_t>(i);
        }
      }
    }
  }
  const int sj = std::max(1, static_cast<int>(std::lround(spec.normal_stencil_m / dy)));
  const int sk = std::max(1, static_cast<int>(std::lround(spec.normal_stencil_m / dz)));
  // Slope of a face by central differences over ±s rays (one-sided at the span's ends, skipping
  // missed rays), capped at 1.
  auto slope = [&](const std::vector<double>& x, int j, int k, bool along_y) {
    const int s = along_y ? sj : sk, n = along_y ? out.ny : out.nz, at = along_y ? j : k;
    const int a = std::max(0, at - s), b = std::min(n - 1, at + s);
    if (b == a) return 0.0;
    auto value = [&](int m) {
      const int jj = along_y ? m : j, kk = along_y ? k : m;
      return x[static_cast<std::size_t>(kk) * out.ny + static_cast<std::size_t>(jj)];
    };
    const double xa = value(a), xb = value(b);
    if (!std::isfinite(xa) || !std::isfinite(xb)) return 0.0;
    const double g = (xb - xa) / ((b - a) * (along_y ? dy : dz));
    return std::clamp(g, -1.0, 1.0);
  };
  std::vector<Eigen::Vector3d> load(n, Eigen::Vector3d::Zero());
  std::vector<std::uint8_t> loaded(n, 0);
  const double f = spec.pressure_Pa * out.bin_area_m2;
  for (int k = 0; k < out.nz; ++k) {
    for (int j = 0; j < out.ny; ++j) {
      const std::size_t b = static_cast<std::size_t>(k) * out.ny + static_cast<std::size_t>(j);
      if (hit_minus[b] == none) {
        ++out.missed_rays;
        continue;
      }
      // x− face: outward vector area (−1, ∂x/∂y, ∂x/∂z)·ΔyΔz; load = −σ·dA.
      const Eigen::Vector3d fm(f, -f * slope(out.x_minus, j, k, true),
                               -f * slope(out.x_minus, j, k, false));
      // x+ face: outward (1, −∂x/∂y, −∂x/∂z)·ΔyΔz.
      const Eigen::Vector3d fp(-f, f * slope(out.x_plus, j, k, true),
                               f * slope(out.x_plus, j, k, false));
      load[hit_minus[b]] += fm;
      load[hit_plus[b]] += fp;
      loaded[hit_minus[b]] = loaded[hit_plus[b]] = 1;
      out.total_minus += fm;
      out.total_plus += fp;
      out.volume_m3 += (out.x_plus[b] - out.x_minus[b]) * out.bin_area_m2;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!loaded[i]) continue;
    out.particle.push_back(static_cast<std::uint32_t>(i));
    out.force.push_back(load[i]);
  }
  const double hit_area = static_cast<double>(nb - out.missed_rays) * out.bin_area_m2;
  out.mean_width_m = hit_area > 0 ? out.volume_m3 / hit_area : 0.0;
  return out;
}

}  // namespace gs::solver
