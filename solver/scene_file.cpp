#include "scene_file.hpp"

#include <toml++/toml.h>
#include <cmath>
#include <sstream>

#include "errors.hpp"
#include "trajectory_io.hpp"

namespace gs::solver {

namespace {

struct Reader {
  std::string file;
  const toml::table& root;

  [[noreturn]] void fail(const std::string& key, const std::string& what,
                         const std::string& value = {}) const {
    throw InputError(file, key + ": " + what, value);
  }

  const toml::table* table(const std::string& name, bool required) const {
    const auto* t = root[name].as_table();
    if (!t && required) fail("[" + name + "]", "missing section");
    return t;
  }

  double number(const toml::table* t, const std::string& sec, const std::string& key, bool required,
                double fallback) const {
    if (!t || !t->contains(key)) {
      if (required) fail(sec + "." + key, "missing");
      return fallback;
    }
    const auto node = (*t)[key];
    double v;
    if (auto d = node.value<double>())
      v = *d;
    else
      fail(sec + "." + key, "not a number");
    if (!std::isfinite(v)) fail(sec + "." + key, "not finite", value_str(v));
    return v;
  }

  double positive(const toml::table* t, const std::string& sec, const std::string& key,
                  bool required, double fallback) const {
    const double v = number(t, sec, key, required, fallback);
    if (!(v > 0)) fail(sec + "." + key, "must be positive", value_str(v));
    return v;
  }

  Eigen::Vector3d vec3(const toml::table* t, const std::string& sec, const std::string& key,
                       bool required, Eigen::Vector3d fallback) const {
    if (!t || !t->contains(key)) {
      if (required) fail(sec + "." + key, "missing");
      return fallback;
    }
    const auto* a = (*t)[key].as_array();
    if (!a || a->size() != 3) fail(sec + "." + key, "expected an array of 3 numbers");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
      const auto d = (*a)[static_cast<std::size_t>(k)].value<double>();
      if (!d || !std::isfinite(*d)) fail(sec + "." + key, "expected an array of 3 finite numbers");
      v[k] = *d;
    }
    return v;
  }

  std::string string(const toml::table* t, const std::string& sec, const std::string& key,
                     bool required, const std::string& fallback) const {
    if (!t || !t->contains(key)) {
      if (required) fail(sec + "." + key, "missing");
      return fallback;
    }
    const auto s = (*t)[key].value<std::string>();
    if (!s) fail(sec + "." + key, "not a string");
    return *s;
  }

  std::int64_t integer(const toml::table* t, const std::string& sec, const std::string& key,
                       bool required, std::int64_t fallback, std::int64_t min) const {
    if (!t || !t->contains(key)) {
      if (required) fail(sec + "." + key, "missing");
      return fallback;
    }
    const auto v = (*t)[key].value<std::int64_t>();
    if (!v) fail(sec + "." + key, "not an integer");
    if (*v < min)
      fail(sec + "." + key, "must be at least " + std::to_string(min), std::to_string(*v));
    return *v;
  }
};

}  // namespace

Scene load_scene(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(file, "no such scene file");
  toml::table root;
  try {
    root = toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    std::ostringstream where;
    where << "line " << e.source().begin.line;
    throw InputError(file, "TOML syntax error at " + where.str(), std::string(e.description()));
  }
  const Reader r{file, root};
  Scene s;
  s.file = path;
  const auto* scene = r.table("scene", true);
  s.name = r.string(scene, "scene", "name", true, "");
  const std::string packing = r.string(scene, "scene", "packing", true, "");
  const auto packing_path = path.parent_path() / packing;
  {
    const Trajectory t = read_snapshots(packing_path);
    if (t.frames.empty() || t.frames.back().particles.empty())
      throw InputError(packing_path.string(), "packing holds no particles");
    s.particles = t.frames.back().particles;
  }
  s.parameters.emplace_back("scene.name", s.name);
  s.parameters.emplace_back("scene.packing", packing);

  const auto* mat = r.table("material", true);
  auto& m = s.config.material;
  m.young_ec = r.positive(mat, "material", "young_Pa", true, 0);
  m.stiffness_ratio = r.number(mat, "material", "stiffness_ratio", true, 0);
  if (m.stiffness_ratio < 0)
    r.fail("material.stiffness_ratio", "must not be negative", value_str(m.stiffness_ratio));
  m.friction_deg = r.number(mat, "material", "friction_deg", true, 0);
  if (m.friction_deg < 0 || m.friction_deg >= 90)
    r.fail("material.friction_deg", "outside [0, 90)", value_str(m.friction_deg));
  m.density = r.positive(mat, "material", "density_kg_m3", true, 0);
  m.rolling_beta = r.number(mat, "material", "rolling_stiffness", false, 0);
  m.rolling_eta = r.number(mat, "material", "rolling_limit", false, -1);
  const std::string rr = r.string(mat, "material", "rolling_limit_radius", false, "min");
  if (rr == "min")
    m.rolling_radius = RollingRadius::Min;
  else if (rr == "mean")
    m.rolling_radius = RollingRadius::Mean;
  else
    r.fail("material.rolling_limit_radius", "expected \"min\" or \"mean\"", rr);
  s.config.twist_beta = r.number(mat, "material", "twisting_stiffness", false, 0);
  s.config.twist_eta = r.number(mat, "material", "twisting_limit", false, -1);

  const auto* sol = r.table("solver", true);
  std::vector<double> radii;
  for (const auto& p : s.particles) radii.push_back(p.radius);
  s.dt_pwave = pwave_timestep(radii, m.density, m.young_ec);
  if (sol->contains("dt_s") && (*sol)["dt_s"].is_string()) {
    if (r.string(sol, "solver", "dt_s", true, "") != "auto")
      r.fail("solver.dt_s", "expected a number or \"auto\"");
    s.config.dt = r.positive(sol, "solver", "dt_safety", false, 0.3) * s.dt_pwave;
  } else {
    s.config.dt = r.positive(sol, "solver", "dt_s", true, 0);
  }
  s.config.damping = r.number(sol, "solver", "damping", false, 0);
  if (s.config.damping < 0 || s.config.damping >= 1)
    r.fail("solver.damping", "outside [0, 1)", value_str(s.config.damping));
  s.config.gravity = r.vec3(sol, "solver", "gravity_m_s2", false, Eigen::Vector3d::Zero());
  s.steps = r.integer(sol, "solver", "steps", true, 0, 0);
  s.config.threads = static_cast<int>(r.integer(sol, "solver", "threads", false, 1, 1));
  s.config.skin = r.number(sol, "solver", "skin_m", false, 0);
  s.config.max_overlap_ratio = r.positive(sol, "solver", "max_overlap_ratio", false, 0.1);
  s.config.max_energy_residual = r.positive(sol, "solver", "max_energy_residual", false, 0.2);

  const auto* out = r.table("output", false);
  s.output.trajectory = r.string(out, "output", "trajectory", false, s.output.trajectory);
  s.output.every = r.integer(out, "output", "every", false, s.output.every, 1);
  s.output.contacts = out && out->contains("contacts") ? (*out)["contacts"].value_or(true) : true;
  s.output.history = r.string(out, "output", "history", false, s.output.history);
  s.output.history_every =
      r.integer(out, "output", "history_every", false, s.output.history_every, 1);
  s.output.checkpoint_every =
      r.integer(out, "output", "checkpoint_every", false, s.output.checkpoint_every, 1);

  if (const auto* walls = root["walls"].as_array()) {
    for (std::size_t i = 0; i < walls->size(); ++i) {
      const auto* w = (*walls)[i].as_table();
      const std::string sec = "walls[" + std::to_string(i) + "]";
      if (!w) r.fail(sec, "expected a table");
      WallSpec spec;
      spec.name = r.string(w, sec, "name", false, "wall" + std::to_string(i));
      const std::string shape = r.string(w, sec, "shape", true, "");
      if (shape == "box") {
        spec.shape = WallShape::Box;
        spec.center = r.vec3(w, sec, "center_m", true, {});
        spec.half_extents = r.vec3(w, sec, "half_extents_m", true, {});
        if ((spec.half_extents.array() <= 0).any())
          r.fail(sec + ".half_extents_m", "must be positive");
      } else if (shape == "plane") {
        spec.shape = WallShape::Plane;
        spec.center = r.vec3(w, sec, "point_m", true, {});
        spec.normal = r.vec3(w, sec, "normal", true, {});
        if (!(spec.normal.norm() > 0)) r.fail(sec + ".normal", "zero vector");
        spec.normal.normalize();
        spec.angular_velocity =
            r.vec3(w, sec, "angular_velocity_rad_s", false, Eigen::Vector3d::Zero());
      } else {
        r.fail(sec + ".shape", "expected \"box\" or \"plane\"", shape);
      }
      spec.velocity = r.vec3(w, sec, "velocity_m_s", false, Eigen::Vector3d::Zero());
      if (const auto* servo = (*w)["servo"].as_table()) {
        const std::string ss = sec + ".servo";
        spec.servo_stress_Pa = r.number(servo, ss, "stress_Pa", true, 0);
        spec.servo_area_m2 = r.positive(servo, ss, "area_m2", true, 0);
        spec.servo_gain = r.positive(servo, ss, "gain_m_s_per_Pa", true, 0);
        spec.servo_max_velocity = r.positive(servo, ss, "max_velocity_m_s", true, 0);
        if (spec.shape == WallShape::Box) spec.normal = r.vec3(servo, ss, "axis", true, {});
      }
      s.walls.push_back(spec);
    }
  }
  std::ostringstream flat;
  flat << root;
  s.parameters.emplace_back("scene.toml", flat.str());
  return s;
}

}  // namespace gs::solver
