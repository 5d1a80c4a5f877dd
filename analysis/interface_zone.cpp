#include "interface_zone.hpp"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <unordered_map>

#include "errors.hpp"
#include "selection.hpp"
#include "shear_zone.hpp"

namespace gs::analysis {

InterfaceZone interface_zone(const Frame& f, const InterfaceZoneOptions& o) {
  if (!(o.bin > 0)) throw std::invalid_argument("interface zone bin must be positive");
  if (!(o.x_inset >= 0)) throw std::invalid_argument("interface zone x inset must not be negative");
  if (f.particles.empty()) throw std::invalid_argument("the frame has no particles");
  InterfaceZone r;
  // The specimen in the frame: the x extent of the particles in the upper half.
  double zlo = HUGE_VAL, top = -HUGE_VAL;
  for (const auto& p : f.particles) {
    zlo = std::min(zlo, p.position.z());
    top = std::max(top, p.position.z() + p.radius);
  }
  const double mid = 0.5 * (std::max(zlo, o.surface_z) + top);
  double xlo = HUGE_VAL, xhi = -HUGE_VAL;
  for (const auto& p : f.particles)
    if (p.position.z() > mid) {
      xlo = std::min(xlo, p.position.x() - p.radius);
      xhi = std::max(xhi, p.position.x() + p.radius);
    }
  r.x_lo = xlo + o.x_inset;
  r.x_hi = xhi - o.x_inset;
  if (!(r.x_hi > r.x_lo)) throw std::invalid_argument("the x inset leaves no specimen");
  std::unordered_map<std::int64_t, double> x0;
  if (o.reference)
    for (const auto& p : o.reference->particles) x0[p.id] = p.position.x();
  // Bins from the lowest centre in the range up to the highest.
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const auto& p : f.particles) {
    const double x = p.position.x();
    if (x < r.x_lo || x > r.x_hi) continue;
    lo = std::min(lo, p.position.z());
    hi = std::max(hi, p.position.z());
  }
  if (!(hi >= lo)) throw std::invalid_argument("no particle in the profiles' x range");
  const double z0 = o.surface_z + std::floor((lo - o.surface_z) / o.bin) * o.bin;
  const int n = std::max(1, static_cast<int>(std::floor((hi - z0) / o.bin)) + 1);
  std::vector<double> rot(n, 0.0), dx(n, 0.0), cnt(n, 0.0), ndx(n, 0.0);
  for (const auto& p : f.particles) {
    const double x = p.position.x();
    if (x < r.x_lo || x > r.x_hi) continue;
    const int b = std::clamp(static_cast<int>((p.position.z() - z0) / o.bin), 0, n - 1);
    rot[b] += p.rotation.y();
    cnt[b] += 1;
    if (o.reference) {
      const auto it = x0.find(p.id);
      if (it != x0.end()) {
        dx[b] += x - it->second;
        ndx[b] += 1;
      }
    }
  }
  for (int b = 0; b < n; ++b) {
    r.height.push_back(z0 + (b + 0.5) * o.bin - o.surface_z);
    r.rotation.push_back(cnt[b] > 0 ? rot[b] / cnt[b] : 0.0);
    r.displacement.push_back(ndx[b] > 0 ? dx[b] / ndx[b] : NAN);
    r.count.push_back(cnt[b]);
  }
  // The zone from the smoothed |rotation| profile.
  std::vector<double> s(n);
  for (int b = 0; b < n; ++b) {
    const double c = std::abs(r.rotation[b]);
    s[b] = (b == 0 || b == n - 1)
               ? c
               : 0.25 * (std::abs(r.rotation[b - 1]) + 2 * c + std::abs(r.rotation[b + 1]));
  }
  const int pk = static_cast<int>(std::max_element(s.begin(), s.end()) - s.begin());
  r.peak_height = r.height[pk];
  const double base = r.height[0];  // profile_inflection counts from bin 0's centre
  const double up = profile_inflection(s, pk, +1, o.bin);
  const double down = pk > 0 ? profile_inflection(s, pk, -1, o.bin) : NAN;
  r.upper = std::isnan(up) ? NAN : base + up;
  r.lower = std::isnan(down) || base + down < 0 ? 0.0 : base + down;
  r.thickness = r.upper - r.lower;
  if (o.reference) {
    for (int b = n - 1; b >= 0 && std::isnan(r.u_top); --b)
      if (ndx[b] > 0) r.u_top = r.displacement[b];
    for (int b = 0; b < n && std::isnan(r.u_surface); ++b)
      if (ndx[b] > 0 && r.height[b] >= 0) r.u_surface = r.displacement[b];
    r.slip_ratio = r.u_surface / r.u_top;
  }
  return r;
}

InterfaceZoneOptions interface_zone_options(const std::string& file, double d50,
                                            const InterfaceSpec& a,
                                            std::optional<double> recorded) {
  InterfaceZoneOptions o;
  if (a.surface_z) {
    if (!std::isfinite(*a.surface_z))
      throw InputError(file, "--surface-z: not finite", value_str(*a.surface_z));
    o.surface_z = *a.surface_z;
  } else if (recorded) {
    o.surface_z = *recorded;
  } else {
    throw InputError(file,
                     "--surface-z: needed (the file does not record an interface shear surface)");
  }
  o.bin = length_option(file, "--bin", a.bin, a.bin_d50, 1.0, d50);
  if (!(a.inset_d50 >= 0) || !std::isfinite(a.inset_d50))
    throw InputError(file, "--inset-d50: must not be negative", value_str(a.inset_d50));
  o.x_inset = a.inset_d50 * d50;
  return o;
}

std::optional<double> recorded_surface(
    const std::vector<std::pair<std::string, std::string>>& parameters) {
  for (const auto& [key, v] : parameters)
    if (key == "interface_shear.surface_mean_z_m") {
      char* end = nullptr;
      const double z = std::strtod(v.c_str(), &end);
      if (end != v.c_str() && std::isfinite(z)) return z;
    }
  return std::nullopt;
}

}  // namespace gs::analysis
