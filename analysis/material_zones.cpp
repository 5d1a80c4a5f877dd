#include "material_zones.hpp"

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace gs::analysis {

std::vector<MaterialStats> material_zone_stats(const std::vector<Particle>& particles,
                                               const std::vector<Zone>& zones) {
  for (const auto& z : zones)
    if (!(z.lo.array() < z.hi.array()).all())
      throw std::invalid_argument("zone " + z.name + ": lo must be below hi on every axis");
  bool masses = !particles.empty();
  for (const auto& p : particles) masses = masses && p.mass > 0;
  std::map<std::int32_t, MaterialStats> by;
  for (const auto& p : particles) {
    MaterialStats& s = by[p.material_id];
    if (s.in_zone.empty()) {
      s.material = p.material_id;
      s.in_zone.assign(zones.size(), 0);
    }
    const double w = masses ? p.mass : p.radius * p.radius * p.radius;
    ++s.count;
    s.mass_kg += w;
    s.centre_m += w * p.position;
    for (std::size_t k = 0; k < zones.size(); ++k)
      s.in_zone[k] += (p.position.array() > zones[k].lo.array()).all() &&
                      (p.position.array() < zones[k].hi.array()).all();
  }
  std::vector<MaterialStats> out;
  for (auto& [id, s] : by) {
    s.centre_m /= s.mass_kg;
    if (!masses) s.mass_kg = 0;  // (only the weights were radii cubed)
    out.push_back(s);
  }
  return out;
}

Zone parse_zone(const std::string& spec) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos || colon == 0)
    throw std::invalid_argument("expected NAME:xlo,ylo,zlo,xhi,yhi,zhi");
  Zone z;
  z.name = spec.substr(0, colon);
  std::vector<double> v;
  std::stringstream in(spec.substr(colon + 1));
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || std::isnan(x))
      throw std::invalid_argument("not a number: '" + item + "'");
    v.push_back(x);
  }
  if (v.size() != 6) throw std::invalid_argument("expected 6 bounds xlo,ylo,zlo,xhi,yhi,zhi");
  z.lo = Eigen::Vector3d(v[0], v[1], v[2]);
  z.hi = Eigen::Vector3d(v[3], v[4], v[5]);
  if (!(z.lo.array() < z.hi.array()).all())
    throw std::invalid_argument("lo must be below hi on every axis");
  return z;
}

}  // namespace gs::analysis
