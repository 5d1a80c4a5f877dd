#include "material_zones.hpp"

#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "errors.hpp"

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

std::vector<Zone> material_zones(const std::string& file, bool drum,
                                 const std::vector<std::string>& specs) {
  std::vector<Zone> zones;
  if (drum) {
    const double inf = HUGE_VAL;
    zones.push_back({"x+z-", {0, -inf, -inf}, {inf, inf, 0}});
    zones.push_back({"x-z+", {-inf, -inf, 0}, {0, inf, inf}});
  }
  for (const auto& spec : specs) {
    try {
      zones.push_back(parse_zone(spec));
    } catch (const std::invalid_argument& e) {
      throw InputError(file, std::string("--zone: ") + e.what(), spec);
    }
  }
  std::set<std::string> seen;
  for (const auto& z : zones)
    if (!seen.insert(z.name).second) throw InputError(file, "--zone: name used twice", z.name);
  return zones;
}

std::vector<VtkArray> material_table(const std::string& file, long frames,
                                     const std::function<Frame(long)>& frame, long every,
                                     const std::vector<Zone>& zones,
                                     const std::vector<std::string>& names,
                                     std::size_t* material_count) {
  if (every < 1) throw InputError(file, "--every: must be at least 1", std::to_string(every));
  std::vector<double> step, time;
  std::vector<std::vector<MaterialStats>> rows;
  std::set<std::int32_t> materials;
  for (long i = 0; i < frames; i += every) {
    const Frame f = frame(i);
    rows.push_back(material_zone_stats(f.particles, zones));
    for (const auto& s : rows.back()) materials.insert(s.material);
    step.push_back(static_cast<double>(f.step));
    time.push_back(f.time);
  }
  auto name_of = [&](std::int32_t m) {
    return m >= 0 && static_cast<std::size_t>(m) < names.size() ? names[static_cast<std::size_t>(m)]
                                                                : "material" + std::to_string(m);
  };
  std::vector<VtkArray> cols = {{"step", 1, step}, {"time_s", 1, time}};
  for (const std::int32_t m : materials) {
    const std::string n = name_of(m);
    std::vector<double> count, x, y, z;
    std::vector<std::vector<double>> in(zones.size());
    for (const auto& r : rows) {
      const MaterialStats* s = nullptr;
      for (const auto& q : r)
        if (q.material == m) s = &q;
      const double nan = std::nan("");
      count.push_back(s ? static_cast<double>(s->count) : 0.0);
      x.push_back(s ? s->centre_m.x() : nan);
      y.push_back(s ? s->centre_m.y() : nan);
      z.push_back(s ? s->centre_m.z() : nan);
      for (std::size_t k = 0; k < zones.size(); ++k)
        in[k].push_back(s ? static_cast<double>(s->in_zone[k]) : 0.0);
    }
    cols.push_back({n + "_count", 1, count});
    cols.push_back({n + "_com_x_m", 1, x});
    cols.push_back({n + "_com_y_m", 1, y});
    cols.push_back({n + "_com_z_m", 1, z});
    for (std::size_t k = 0; k < zones.size(); ++k)
      cols.push_back({zones[k].name + "_" + n + "_count", 1, in[k]});
  }
  if (material_count) *material_count = materials.size();
  return cols;
}

std::vector<std::string> recorded_material_names(
    const std::vector<std::pair<std::string, std::string>>& parameters) {
  std::vector<std::string> names;
  for (const auto& [key, v] : parameters)
    if (key == "material_names") {
      std::stringstream in(v);
      std::string name;
      while (std::getline(in, name, ',')) names.push_back(name);
    }
  return names;
}

}  // namespace gs::analysis
