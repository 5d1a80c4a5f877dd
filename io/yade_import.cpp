// YADE export.VTKExporter legacy files (spheres + interactions).
#include <cmath>
#include <unordered_map>

#include "errors.hpp"
#include "vtk_io.hpp"
#include "vtk_legacy.hpp"

namespace gs {

namespace {

const LegacyPolyData::Array* find(const std::map<std::string, LegacyPolyData::Array>& m,
                                  std::initializer_list<const char*> names, int comps,
                                  const std::string& file) {
  for (const char* n : names) {
    auto it = m.find(n);
    if (it == m.end()) continue;
    if (it->second.components != comps)
      throw InputError(file, std::string("array ") + n + " has wrong component count",
                       std::to_string(it->second.components));
    return &it->second;
  }
  return nullptr;
}

// Ids are written as floating-point values: integral and exact, or the file is rejected.
std::int64_t id_value(double v, const std::string& file, const char* what) {
  if (!(std::abs(v) <= 9e15) || v != std::round(v))
    throw InputError(file, std::string(what) + " is not an integer", value_str(v));
  return static_cast<std::int64_t>(v);
}

Eigen::Vector3d v3(const LegacyPolyData::Array& a, std::size_t i) {
  return {a.values[3 * i], a.values[3 * i + 1], a.values[3 * i + 2]};
}

}  // namespace

Frame read_yade_legacy(const std::filesystem::path& spheres,
                       const std::filesystem::path& intrs_in) {
  const std::string name = spheres.string();
  const LegacyPolyData s = read_legacy_polydata(spheres);
  const std::size_t n = s.points.size() / 3;
  const auto* rad = find(s.point_data, {"radius", "radii"}, 1, name);
  if (!rad) throw InputError(name, "missing point array", "radius");
  const auto* id = find(s.point_data, {"id", "ids"}, 1, name);
  const auto* vel = find(s.point_data, {"linVel", "linVelVec", "velocity"}, 3, name);
  const auto* av = find(s.point_data, {"angVel", "angVelVec", "angular_velocity"}, 3, name);
  const auto* mass = find(s.point_data, {"mass"}, 1, name);
  Frame f;
  f.particles.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    auto& p = f.particles[i];
    p.position = {s.points[3 * i], s.points[3 * i + 1], s.points[3 * i + 2]};
    p.radius = rad->values[i];
    p.id = id ? id_value(id->values[i], name, "particle id") : static_cast<std::int64_t>(i);
    if (vel) p.velocity = v3(*vel, i);
    if (av) p.angular_velocity = v3(*av, i);
    if (mass) p.mass = mass->values[i];
  }
  validate_frame(f, name);
  std::tie(f.domain.lo, f.domain.hi) = particle_bounds(f);

  std::filesystem::path intrs = intrs_in;
  if (intrs.empty()) {
    std::string fn = spheres.filename().string();
    const auto k = fn.rfind("-spheres-");
    if (k != std::string::npos) {
      fn.replace(k, 9, "-intrs-");
      std::error_code ec;
      if (std::filesystem::is_regular_file(spheres.parent_path() / fn, ec))
        intrs = spheres.parent_path() / fn;
    }
  }
  if (intrs.empty()) return f;
  const std::string iname = intrs.string();
  const LegacyPolyData d = read_legacy_polydata(intrs);
  const std::size_t m = d.lines.size();
  for (const auto& [k, a] : d.cell_data)
    if (a.values.size() != m * static_cast<std::size_t>(a.components))
      throw InputError(iname, "cell array length differs from the number of lines", k);
  const auto* id1 = find(d.cell_data, {"id1"}, 1, iname);
  const auto* id2 = find(d.cell_data, {"id2"}, 1, iname);
  if (!id1 || !id2)
    throw InputError(iname,
                     "interactions need cell arrays id1 and id2 (export them with "
                     "what=dict(id1='i.id1', id2='i.id2', ...))");
  const auto* fn = find(d.cell_data, {"forceN", "normalForce"}, 3, iname);
  const auto* fs = find(d.cell_data, {"forceT", "shearForce"}, 3, iname);
  const auto* nn = find(d.cell_data, {"normal"}, 3, iname);
  const auto* cp = find(d.cell_data, {"contactPoint"}, 3, iname);
  const auto* pen = find(d.cell_data, {"penetrationDepth"}, 1, iname);
  std::unordered_map<std::int64_t, const Particle*> byid;
  for (const auto& p : f.particles) byid[p.id] = &p;
  f.contacts.resize(m);
  for (std::size_t i = 0; i < m; ++i) {
    auto& c = f.contacts[i];
    c.id1 = id_value(id1->values[i], iname, "interaction id1");
    c.id2 = id_value(id2->values[i], iname, "interaction id2");
    if (d.lines[i].size() != 2)
      throw InputError(iname, "interaction line without 2 points", std::to_string(i));
    const auto a = static_cast<std::size_t>(d.lines[i][0]),
               b = static_cast<std::size_t>(d.lines[i][1]);
    const Eigen::Vector3d xa(d.points[3 * a], d.points[3 * a + 1], d.points[3 * a + 2]);
    const Eigen::Vector3d xb(d.points[3 * b], d.points[3 * b + 1], d.points[3 * b + 2]);
    if (nn) {
      c.normal = v3(*nn, i);
    } else {
      const Eigen::Vector3d br = xb - xa;
      if (!(br.norm() > 0))
        throw InputError(iname, "interaction of zero length and no normal", std::to_string(i));
      c.normal = br.normalized();
    }
    c.point = cp ? v3(*cp, i) : 0.5 * (xa + xb);
    if (fn) c.normal_force = v3(*fn, i);  // YADE: force exerted by id1 on id2, as ours
    if (fs) c.shear_force = v3(*fs, i);
    if (pen) c.overlap = pen->values[i];
  }
  validate_frame(f, iname);
  return f;
}

}  // namespace gs
