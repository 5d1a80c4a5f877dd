#include "scene_file.hpp"

#include <omp.h>

#include <toml++/toml.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <sstream>

#include "clump_shapes.hpp"
#include "errors.hpp"
#include "hertz_mindlin_law.hpp"
#include "mesh_walls.hpp"
#include "text_parse.hpp"
#include "trajectory_io.hpp"
#include "triangle_mesh.hpp"

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

  // An optional true/false (absent: the fallback).
  bool boolean(const toml::table* t, const std::string& sec, const std::string& key,
               bool fallback) const {
    if (!t || !t->contains(key)) return fallback;
    const auto* v = (*t)[key].as_boolean();
    if (!v) fail(sec + "." + key, "expected true or false");
    return v->get();
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

  /// A 3×3 matrix as 3 rows of 3 finite numbers (row i, column j).
  Eigen::Matrix3d matrix3(const toml::table* t, const std::string& sec, const std::string& key,
                          bool required, const Eigen::Matrix3d& fallback) const {
    if (!t || !t->contains(key)) {
      if (required) fail(sec + "." + key, "missing");
      return fallback;
    }
    const auto* a = (*t)[key].as_array();
    const std::string what = "expected 3 rows of 3 finite numbers";
    if (!a || a->size() != 3) fail(sec + "." + key, what);
    Eigen::Matrix3d m;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto* row = (*a)[i].as_array();
      if (!row || row->size() != 3) fail(sec + "." + key, what, "row " + std::to_string(i));
      for (std::size_t j = 0; j < 3; ++j) {
        const auto d = (*row)[j].value<double>();
        if (!d || !std::isfinite(*d)) fail(sec + "." + key, what, "row " + std::to_string(i));
        m(static_cast<int>(i), static_cast<int>(j)) = *d;
      }
    }
    return m;
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

  /// Rejects keys a section does not know (a misspelt key or a unit in its name, such as
  /// `young_MPa`, must not be silently ignored).
  void only(const toml::table* t, const std::string& sec,
            std::initializer_list<const char*> keys) const {
    if (!t) return;
    for (const auto& [k, v] : *t) {
      bool known = false;
      for (const char* allowed : keys) known = known || k.str() == allowed;
      if (!known) fail(sec + "." + std::string(k.str()), "unknown key");
    }
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

// [stress_rotation]: seed 003's test (stress_rotation.hpp, docs/rotation.md).
void read_stress_rotation(const Reader& r, const toml::table& root, Scene& s) {
  const auto* t = r.table("stress_rotation", true);
  const std::string sec = "stress_rotation";
  r.only(t, sec,
         {"sides",
          "radius_m",
          "p_Pa",
          "eta",
          "b",
          "eta_step",
          "alpha_step_deg",
          "cycles",
          "tolerance",
          "deposition_tolerance",
          "stress_tolerance",
          "deposition_gravity_m_s2",
          "deposition_friction_deg",
          "deposition_damping",
          "damping",
          "min_stage_steps",
          "check_every",
          "max_increment_steps",
          "max_stage_steps",
          "frame_every_deg",
          "servo_poisson",
          "servo_volumetric_gain",
          "servo_max_strain_step",
          "servo_relaxation",
          "servo_modulus_Pa",
          "quasi_static_dt_s"});
  auto& x = s.stress_rotation;
  const std::int64_t n = r.integer(t, sec, "sides", false, x.sides, 4);
  if (n % 2 != 0 || n > 1000) r.fail(sec + ".sides", "must be even (4 to 1000)", std::to_string(n));
  x.sides = static_cast<int>(n);
  x.radius_m = r.positive(t, sec, "radius_m", false, x.radius_m);
  x.p_Pa = r.positive(t, sec, "p_Pa", false, x.p_Pa);
  x.eta = r.positive(t, sec, "eta", true, 0);
  if (!(x.eta < 3))
    r.fail(sec + ".eta", "must be below 3 (q/p of a compression)", value_str(x.eta));
  x.b = r.number(t, sec, "b", false, x.b);
  if (!(x.b >= 0 && x.b <= 1)) r.fail(sec + ".b", "outside [0, 1]", value_str(x.b));
  x.eta_step = r.positive(t, sec, "eta_step", false, x.eta_step);
  x.alpha_step_deg = r.positive(t, sec, "alpha_step_deg", false, x.alpha_step_deg);
  if (!(x.alpha_step_deg <= 90))
    r.fail(sec + ".alpha_step_deg", "must be at most 90", value_str(x.alpha_step_deg));
  x.cycles = r.positive(t, sec, "cycles", false, x.cycles);
  x.tolerance = r.positive(t, sec, "tolerance", false, x.tolerance);
  x.deposition_tolerance = r.positive(t, sec, "deposition_tolerance", false, x.tolerance);
  x.stress_tolerance = r.positive(t, sec, "stress_tolerance", false, x.stress_tolerance);
  x.deposition_gravity = r.vec3(t, sec, "deposition_gravity_m_s2", false, x.deposition_gravity);
  x.deposition_friction_deg =
      r.number(t, sec, "deposition_friction_deg", false, x.deposition_friction_deg);
  if (!(x.deposition_friction_deg >= 0 && x.deposition_friction_deg < 90))
    r.fail(sec + ".deposition_friction_deg", "outside [0, 90)",
           value_str(x.deposition_friction_deg));
  for (const auto& [k, v] :
       {std::pair{"deposition_damping", &x.deposition_damping}, std::pair{"damping", &x.damping}}) {
    *v = r.number(t, sec, k, false, *v);
    if (!(*v >= 0 && *v < 1)) r.fail(sec + "." + k, "outside [0, 1)", value_str(*v));
  }
  x.min_stage_steps = r.integer(t, sec, "min_stage_steps", false, x.min_stage_steps, 0);
  x.check_every = r.integer(t, sec, "check_every", false, x.check_every, 1);
  x.max_increment_steps = r.integer(t, sec, "max_increment_steps", false, x.max_increment_steps, 1);
  x.max_stage_steps = r.integer(t, sec, "max_stage_steps", false, x.max_stage_steps, 1);
  x.frame_every_deg = r.positive(t, sec, "frame_every_deg", false, x.frame_every_deg);
  x.servo.nu = r.number(t, sec, "servo_poisson", false, x.servo.nu);
  if (!(x.servo.nu > -1 && x.servo.nu <= 0.5))
    r.fail(sec + ".servo_poisson", "outside (-1, 0.5]", value_str(x.servo.nu));
  x.servo.volumetric_gain =
      r.positive(t, sec, "servo_volumetric_gain", false, x.servo.volumetric_gain);
  if (x.servo.nu == 0.5 && t->contains("servo_volumetric_gain"))
    r.fail(sec + ".servo_volumetric_gain",
           "has no effect with servo_poisson = 0.5 (Eq 15 then has no volumetric part)");
  x.servo.max_strain_step =
      r.positive(t, sec, "servo_max_strain_step", false, x.servo.max_strain_step);
  x.relaxation = r.positive(t, sec, "servo_relaxation", false, x.relaxation);
  if (t->contains("servo_modulus_Pa")) x.servo.E = r.positive(t, sec, "servo_modulus_Pa", true, 0);
  if (t->contains("quasi_static_dt_s"))
    x.quasi_static_dt_s = r.positive(t, sec, "quasi_static_dt_s", true, 0);
  if (!root.contains("specimen"))
    r.fail("[specimen]", "missing (the stress rotation test deposits its specimen)");
}

void read_lab_sections(const Reader& r, const toml::table& root, Scene& s) {
  for (const char* name : {"triaxial", "plane_strain", "direct_shear", "interface_shear",
                           "biaxial_periodic", "silo", "stress_rotation"}) {
    if (root.contains(name) && s.test != name)
      r.fail(std::string("[") + name + "]", "does not match scene.test", s.test);
  }
  if (s.test == "triaxial") {
    const auto* t = r.table("triaxial", true);
    r.only(t, "triaxial",
           {"confining_Pa", "strain_rate_1_s", "max_strain", "frame_every_strain", "servo_gain",
            "max_wall_speed_m_s", "inertial_warning"});
    auto& x = s.triaxial;
    x.confining_Pa = r.positive(t, "triaxial", "confining_Pa", true, 0);
    x.strain_rate_1_s = r.positive(t, "triaxial", "strain_rate_1_s", true, 0);
    x.max_strain = r.positive(t, "triaxial", "max_strain", true, 0);
    if (x.max_strain >= 1)
      r.fail("triaxial.max_strain", "must be below 1", value_str(x.max_strain));
    x.frame_every_strain =
        r.positive(t, "triaxial", "frame_every_strain", false, x.frame_every_strain);
    x.servo_gain = r.positive(t, "triaxial", "servo_gain", false, x.servo_gain);
    x.max_wall_speed_m_s =
        r.positive(t, "triaxial", "max_wall_speed_m_s", false, x.max_wall_speed_m_s);
    x.inertial_warning = r.positive(t, "triaxial", "inertial_warning", false, x.inertial_warning);
  } else if (s.test == "plane_strain") {
    const auto* t = r.table("plane_strain", true);
    r.only(t, "plane_strain",
           {"confining_Pa", "strain_rate_1_s", "max_strain", "frame_every_strain", "membrane_bin_m",
            "membrane_stencil_m", "refresh_steps", "clamp_height_m", "top_cap", "sledge_gain",
            "inertial_warning"});
    auto& x = s.plane_strain;
    x.confining_Pa = r.positive(t, "plane_strain", "confining_Pa", true, 0);
    x.strain_rate_1_s = r.positive(t, "plane_strain", "strain_rate_1_s", true, 0);
    x.max_strain = r.positive(t, "plane_strain", "max_strain", true, 0);
    if (x.max_strain >= 1)
      r.fail("plane_strain.max_strain", "must be below 1", value_str(x.max_strain));
    x.frame_every_strain =
        r.positive(t, "plane_strain", "frame_every_strain", false, x.frame_every_strain);
    x.membrane_bin_m = r.number(t, "plane_strain", "membrane_bin_m", false, 0);
    x.membrane_stencil_m = r.number(t, "plane_strain", "membrane_stencil_m", false, 0);
    x.refresh_steps = r.integer(t, "plane_strain", "refresh_steps", false, x.refresh_steps, 1);
    x.clamp_height_m = r.number(t, "plane_strain", "clamp_height_m", false, 0);
    const std::string cap = r.string(t, "plane_strain", "top_cap", false, "sledge");
    if (cap == "sledge")
      x.top_sledge = true;
    else if (cap == "fixed")
      x.top_sledge = false;
    else
      r.fail("plane_strain.top_cap", "expected \"sledge\" or \"fixed\"", cap);
    x.sledge_gain = r.positive(t, "plane_strain", "sledge_gain", false, x.sledge_gain);
    x.inertial_warning =
        r.positive(t, "plane_strain", "inertial_warning", false, x.inertial_warning);
  } else if (s.test == "biaxial_periodic") {
    const char* sec = "biaxial_periodic";
    const auto* t = r.table(sec, true);
    r.only(t, sec,
           {"lateral_stress_Pa", "strain_rate_1_s", "max_strain", "frame_every_strain",
            "frame_strains", "servo_fraction", "max_rate_1_s", "inertial_warning"});
    auto& x = s.biaxial_periodic;
    x.lateral_stress_Pa = r.positive(t, sec, "lateral_stress_Pa", true, 0);
    x.strain_rate_1_s = r.positive(t, sec, "strain_rate_1_s", true, 0);
    x.max_strain = r.positive(t, sec, "max_strain", true, 0);
    if (x.max_strain >= 1)
      r.fail("biaxial_periodic.max_strain", "must be below 1", value_str(x.max_strain));
    x.frame_every_strain = r.number(t, sec, "frame_every_strain", false, x.frame_every_strain);
    if (x.frame_every_strain < 0)
      r.fail("biaxial_periodic.frame_every_strain", "negative", value_str(x.frame_every_strain));
    if (t->contains("frame_strains")) {
      const auto* arr = (*t)["frame_strains"].as_array();
      if (!arr) r.fail("biaxial_periodic.frame_strains", "expected an array of strains");
      for (const auto& v : *arr) {
        const auto e = v.value<double>();
        if (!e || !(*e > 0) || !(*e < 1))
          r.fail("biaxial_periodic.frame_strains", "expected strains in (0, 1)");
        x.frame_strains.push_back(*e);
      }
    }
    x.servo_fraction = r.positive(t, sec, "servo_fraction", false, x.servo_fraction);
    if (x.servo_fraction > 1)
      r.fail("biaxial_periodic.servo_fraction", "must be at most 1", value_str(x.servo_fraction));
    if (t->contains("max_rate_1_s")) x.max_rate_1_s = r.positive(t, sec, "max_rate_1_s", true, 0);
    x.inertial_warning = r.positive(t, sec, "inertial_warning", false, x.inertial_warning);
  } else if (s.test == "direct_shear") {
    const auto* t = r.table("direct_shear", true);
    r.only(
        t, "direct_shear",
        {"normal_stress_Pa", "shear_velocity_m_s", "max_displacement_m", "frame_every_m", "gap_m",
         "side_friction_deg", "platen_friction_deg", "servo_gain", "max_platen_speed_m_s"});
    auto& x = s.direct_shear;
    x.normal_stress_Pa = r.positive(t, "direct_shear", "normal_stress_Pa", true, 0);
    x.shear_velocity_m_s = r.positive(t, "direct_shear", "shear_velocity_m_s", true, 0);
    x.max_displacement_m = r.positive(t, "direct_shear", "max_displacement_m", true, 0);
    x.frame_every_m = r.number(t, "direct_shear", "frame_every_m", false, 0);
    x.servo_gain = r.positive(t, "direct_shear", "servo_gain", false, x.servo_gain);
    x.max_platen_speed_m_s =
        r.positive(t, "direct_shear", "max_platen_speed_m_s", false, x.max_platen_speed_m_s);
    auto& g = s.shear_box;
    g.gap_m = r.number(t, "direct_shear", "gap_m", false, -1);
    g.side_friction_deg = r.number(t, "direct_shear", "side_friction_deg", false, 0);
    g.platen_friction_deg = r.number(t, "direct_shear", "platen_friction_deg", false, -1);
  } else if (s.test == "interface_shear") {
    // Seed 004 §4.3–4.4 (interface_shear.hpp, docs/interface_shear.md).
    const std::string sec = "interface_shear";
    const auto* t = r.table(sec, true);
    r.only(t, sec,
           {"surface",
            "roughness",
            "d50_m",
            "tooth_slope_deg",
            "tooth_spacing_ratio",
            "depth_ratio",
            "wavelength_m",
            "segments_per_wavelength",
            "surface_friction_deg",
            "surface_contact",
            "frame_friction_deg",
            "platen_friction_deg",
            "gap_m",
            "normal_stress_Pa",
            "shear_velocity_m_s",
            "max_displacement_m",
            "frame_every_m",
            "servo_gain",
            "max_platen_speed_m_s",
            "residual_fraction",
            "peak_fraction",
            "internal_friction_deg",
            "flat_friction",
            "frame"});
    auto& f = s.interface_surface;
    f.kind = r.string(t, sec, "surface", true, "");
    if (f.kind != "saw_tooth" && f.kind != "sinusoid" && f.kind != "flat")
      r.fail(sec + ".surface", "expected \"saw_tooth\", \"sinusoid\" or \"flat\"", f.kind);
    const bool saw = f.kind == "saw_tooth", sine = f.kind == "sinusoid";
    for (const char* k : {"roughness", "d50_m", "tooth_slope_deg", "tooth_spacing_ratio"})
      if (!saw && t->contains(k)) r.fail(sec + "." + k, "is for surface = \"saw_tooth\"");
    for (const char* k : {"depth_ratio", "wavelength_m", "segments_per_wavelength"})
      if (!sine && t->contains(k)) r.fail(sec + "." + k, "is for surface = \"sinusoid\"");
    if (saw) {
      f.roughness = r.number(t, sec, "roughness", true, 0);
      if (!(f.roughness > 0))
        r.fail(sec + ".roughness", "must be positive (a flat plate: surface = \"flat\")",
               value_str(f.roughness));
      f.d50_m = r.number(t, sec, "d50_m", false, 0);
      f.tooth_slope_deg = r.number(t, sec, "tooth_slope_deg", false, f.tooth_slope_deg);
      f.tooth_spacing_ratio =
          r.positive(t, sec, "tooth_spacing_ratio", false, f.tooth_spacing_ratio);
    }
    if (sine) {
      f.depth_ratio = r.number(t, sec, "depth_ratio", true, 0);
      if (!(f.depth_ratio >= 0 && f.depth_ratio < 1))
        r.fail(sec + ".depth_ratio", "outside [0, 1)", value_str(f.depth_ratio));
      f.wavelength_m = r.positive(t, sec, "wavelength_m", true, 0);
      f.segments_per_wavelength = static_cast<int>(
          r.integer(t, sec, "segments_per_wavelength", false, f.segments_per_wavelength, 4));
      if (f.segments_per_wavelength > 4096)
        r.fail(sec + ".segments_per_wavelength", "more than 4096",
               std::to_string(f.segments_per_wavelength));
    }
    auto angle = [&](const char* k, double fallback) {
      const double v = r.number(t, sec, k, false, fallback);
      if (t->contains(k) && !(v >= 0 && v < 90))
        r.fail(sec + "." + k, "outside [0, 90)", value_str(v));
      return v;
    };
    f.friction_deg = angle("surface_friction_deg", -1);
    f.contact = r.string(t, sec, "surface_contact", false, "merged");
    if (!mesh_contact_named(f.contact))
      r.fail(sec + ".surface_contact", "expected \"merged\" or \"yade\"", f.contact);
    auto& g = s.interface_geometry;
    g.frame_friction_deg = angle("frame_friction_deg", 0);
    g.platen_friction_deg = angle("platen_friction_deg", -1);
    g.gap_m = r.number(t, sec, "gap_m", false, -1);
    if (t->contains("gap_m") && !(g.gap_m >= 0))
      r.fail(sec + ".gap_m", "must not be negative", value_str(g.gap_m));
    auto& x = s.interface_shear;
    x.normal_stress_Pa = r.positive(t, sec, "normal_stress_Pa", true, 0);
    x.shear_velocity_m_s = r.positive(t, sec, "shear_velocity_m_s", true, 0);
    x.max_displacement_m = r.positive(t, sec, "max_displacement_m", true, 0);
    x.frame_every_m = r.number(t, sec, "frame_every_m", false, 0);
    x.servo_gain = r.positive(t, sec, "servo_gain", false, x.servo_gain);
    x.max_platen_speed_m_s =
        r.positive(t, sec, "max_platen_speed_m_s", false, x.max_platen_speed_m_s);
    x.residual_fraction = r.positive(t, sec, "residual_fraction", false, x.residual_fraction);
    if (!(x.residual_fraction < 1))
      r.fail(sec + ".residual_fraction", "must be below 1", value_str(x.residual_fraction));
    x.peak_fraction = r.positive(t, sec, "peak_fraction", false, x.peak_fraction);
    if (!(x.peak_fraction <= 0.5))
      r.fail(sec + ".peak_fraction", "must be at most 0.5", value_str(x.peak_fraction));
    const std::string frame = r.string(t, sec, "frame", false, "held");
    if (frame != "held" && frame != "free")
      r.fail(sec + ".frame", "expected \"held\" or \"free\"", frame);
    x.frame_free = frame == "free";
    x.internal_friction_deg = angle("internal_friction_deg", x.internal_friction_deg);
    if (!(x.internal_friction_deg > 0))
      r.fail(sec + ".internal_friction_deg", "must be positive",
             value_str(x.internal_friction_deg));
    x.flat_friction = r.number(t, sec, "flat_friction", false, -1);
    if (t->contains("flat_friction") && !(x.flat_friction >= 0 && x.flat_friction < 10))
      r.fail(sec + ".flat_friction", "outside [0, 10)", value_str(x.flat_friction));
    if (!root.contains("specimen"))
      r.fail("[specimen]", "missing (the interface shear test generates its specimen)");
  } else if (s.test == "silo") {
    // Seed 004 §5.2 (silo_flow.hpp, docs/silo.md).
    const auto* t = r.table("silo", true);
    const std::string sec = "silo";
    r.only(t, sec,
           {"width_m",
            "height_m",
            "depth_m",
            "roughness",
            "d50_m",
            "tooth_slope_deg",
            "tooth_spacing_ratio",
            "wall_friction_deg",
            "front_back_friction_deg",
            "bottom_friction_deg",
            "mode",
            "flow_damping",
            "bottom_velocity_m_s",
            "bottom_travel_m",
            "frame_every_m",
            "settle_s",
            "outlet",
            "outlet_width_m",
            "max_discharge_s",
            "end_fraction",
            "stop_after_s",
            "frame_every_s"});
    auto& x = s.silo;
    x.width_m = r.positive(t, sec, "width_m", true, 0);
    x.height_m = r.positive(t, sec, "height_m", true, 0);
    x.depth_m = r.positive(t, sec, "depth_m", true, 0);
    x.roughness = r.number(t, sec, "roughness", true, 0);
    x.d50_m = r.number(t, sec, "d50_m", false, 0);
    x.tooth_slope_deg = r.number(t, sec, "tooth_slope_deg", false, x.tooth_slope_deg);
    x.tooth_spacing_ratio = r.positive(t, sec, "tooth_spacing_ratio", false, x.tooth_spacing_ratio);
    x.wall_friction_deg = r.number(t, sec, "wall_friction_deg", false, x.wall_friction_deg);
    x.front_back_friction_deg =
        r.number(t, sec, "front_back_friction_deg", false, x.front_back_friction_deg);
    x.bottom_friction_deg = r.number(t, sec, "bottom_friction_deg", false, -1);
    for (const auto& [k, v] : {std::pair{"wall_friction_deg", x.wall_friction_deg},
                               std::pair{"front_back_friction_deg", x.front_back_friction_deg}})
      if (!(v >= 0 && v < 90)) r.fail(sec + "." + k, "outside [0, 90)", value_str(v));
    x.mode = r.string(t, sec, "mode", false, x.mode);
    if (x.mode != "quasi_static" && x.mode != "gravitational")
      r.fail("silo.mode", "expected \"quasi_static\" or \"gravitational\"", x.mode);
    const bool quasi = x.mode == "quasi_static";
    for (const char* k : {"bottom_velocity_m_s", "bottom_travel_m", "frame_every_m"})
      if (!quasi && t->contains(k)) r.fail(sec + "." + k, "is for mode = \"quasi_static\"");
    for (const char* k : {"settle_s", "outlet", "outlet_width_m", "max_discharge_s", "end_fraction",
                          "stop_after_s", "frame_every_s"})
      if (quasi && t->contains(k)) r.fail(sec + "." + k, "is for mode = \"gravitational\"");
    x.flow_damping = r.number(t, sec, "flow_damping", false, x.flow_damping);
    x.bottom_velocity_m_s = r.positive(t, sec, "bottom_velocity_m_s", false, x.bottom_velocity_m_s);
    x.bottom_travel_m = r.positive(t, sec, "bottom_travel_m", false, x.bottom_travel_m);
    x.frame_every_m = r.number(t, sec, "frame_every_m", false, x.frame_every_m);
    x.settle_s = r.number(t, sec, "settle_s", false, x.settle_s);
    x.outlet = r.string(t, sec, "outlet", false, x.outlet);
    x.outlet_width_m = r.number(t, sec, "outlet_width_m", false, x.outlet_width_m);
    x.max_discharge_s = r.positive(t, sec, "max_discharge_s", false, x.max_discharge_s);
    x.end_fraction = r.number(t, sec, "end_fraction", false, x.end_fraction);
    x.stop_after_s = r.number(t, sec, "stop_after_s", false, x.stop_after_s);
    x.frame_every_s = r.number(t, sec, "frame_every_s", false, x.frame_every_s);
    if (!root.contains("fill")) r.fail("[fill]", "missing (the silo is filled in layers)");
  } else if (s.test == "stress_rotation") {
    read_stress_rotation(r, root, s);
  }
  const auto* prep = r.table("preparation", false);
  if (s.test == "stress_rotation" && prep)
    r.fail("[preparation]",
           "the stress rotation test prepares its specimen itself (deposition "
           "and carving: [stress_rotation])");
  if (s.test == "silo" && (prep || s.specimen))
    r.fail(prep ? "[preparation]" : "[specimen]", "the silo is filled by its [fill]; remove it");
  if (!s.test.empty() && s.test != "stress_rotation" && (prep || s.specimen)) {
    auto& p = s.preparation.emplace();
    r.only(prep, "preparation",
           {"pressure_Pa", "void_ratio", "core_inset_m", "friction_start_deg", "friction_factor",
            "stage_steps", "check_every", "stress_tolerance", "unbalanced_force", "kinetic_ratio",
            "servo_gain", "max_wall_speed_m_s", "max_rate_1_s", "deposition", "max_steps"});
    // Default: the stress of the test (σc, σn of the direct shear, σ11 of the biaxial test).
    const double test_stress = s.test == "triaxial"           ? s.triaxial.confining_Pa
                               : s.test == "plane_strain"     ? s.plane_strain.confining_Pa
                               : s.test == "biaxial_periodic" ? s.biaxial_periodic.lateral_stress_Pa
                               : s.test == "interface_shear"  ? s.interface_shear.normal_stress_Pa
                                                              : s.direct_shear.normal_stress_Pa;
    p.pressure_Pa = r.number(prep, "preparation", "pressure_Pa", false, test_stress);
    if (p.pressure_Pa < 0) r.fail("preparation.pressure_Pa", "negative", value_str(p.pressure_Pa));
    p.void_ratio_target = r.number(prep, "preparation", "void_ratio", false,
                                   s.specimen ? s.specimen->void_ratio : -1);
    p.core_inset_m = r.number(prep, "preparation", "core_inset_m", false, -1);
    p.friction_start_deg = r.number(prep, "preparation", "friction_start_deg", false, -1);
    p.friction_factor =
        r.positive(prep, "preparation", "friction_factor", false, p.friction_factor);
    if (p.friction_factor >= 1)
      r.fail("preparation.friction_factor", "must be below 1", value_str(p.friction_factor));
    p.stage_steps = r.integer(prep, "preparation", "stage_steps", false, p.stage_steps, 1);
    p.check_every = r.integer(prep, "preparation", "check_every", false, p.check_every, 1);
    p.stress_tolerance =
        r.positive(prep, "preparation", "stress_tolerance", false, p.stress_tolerance);
    p.unbalanced_force =
        r.positive(prep, "preparation", "unbalanced_force", false, p.unbalanced_force);
    p.kinetic_ratio = r.positive(prep, "preparation", "kinetic_ratio", false, p.kinetic_ratio);
    p.servo_gain = r.positive(prep, "preparation", "servo_gain", false, p.servo_gain);
    p.max_wall_speed_m_s =
        r.positive(prep, "preparation", "max_wall_speed_m_s", false, p.max_wall_speed_m_s);
    p.deposition =
        prep && prep->contains("deposition") ? (*prep)["deposition"].value_or(false) : false;
    p.max_steps = r.integer(prep, "preparation", "max_steps", false, 0, 0);
    p.max_cell_rate_1_s =
        r.positive(prep, "preparation", "max_rate_1_s", false, p.max_cell_rate_1_s);
    if (s.test == "biaxial_periodic") {
      if (p.deposition) r.fail("preparation.deposition", "not in a periodic cell");
      if (p.servo_gain > 1)
        r.fail("preparation.servo_gain", "a cell's servo gain is a fraction in (0, 1]",
               value_str(p.servo_gain));
    } else if (prep && prep->contains("max_rate_1_s")) {
      r.fail("preparation.max_rate_1_s",
             "is for a periodic cell (scene.test = \"biaxial_periodic\")");
    }
    if (p.pressure_Pa == 0 && !p.deposition)
      r.fail("preparation.pressure_Pa", "missing (or set deposition = true)");
  } else if (prep) {
    r.fail("[preparation]", "needs scene.test");
  }
}

}  // namespace

void replace_spheres_by_clumps(Scene& s) {
  if (!s.clump_replace || s.particles.empty() || !s.clumps.empty()) return;
  const auto& cr = *s.clump_replace;
  std::mt19937_64 rng(cr.seed);
  auto rep =
      replace_by_clumps(s.particles, cr.shape, s.config.material.density, cr.model, rng, 0, 0);
  // Members take the spheres' place (ids 0…), clumps are numbered after them.
  s.particles = rep.members;
  std::int64_t next = static_cast<std::int64_t>(s.particles.size());
  for (auto& c : rep.clumps) {
    c.id = next++;
    c.template_name = cr.template_name;
    for (const auto i : c.members) s.particles[i].clump_id = c.id;
  }
  s.clumps = std::move(rep.clumps);
  if (s.dt_auto_safety > 0) {
    std::vector<double> radii;
    for (const auto& p : s.particles) radii.push_back(p.radius);
    s.dt_pwave = material_timestep(radii, s.config.material);
    s.config.dt = s.dt_auto_safety * s.dt_pwave;
  }
}

namespace {

/// [[clump_template]] (name, members = [[x, y, z, r], …] in metres in the template frame) and
/// [clumps] (packing = CSV of template,x,y,z,qw,qx,qy,qz[,scale]: the template rotated by the
/// unit quaternion, scaled, placed at (x, y, z); mass = "member_sum" (YADE's default) or
/// "union"). Members are appended to the particles, ids after the largest.
void read_clumps(const Reader& r, const toml::table& root, const std::filesystem::path& path,
                 Scene& s) {
  std::map<std::string, std::vector<ClumpMember>> templates;
  if (const auto* ts = root["clump_template"].as_array()) {
    for (std::size_t i = 0; i < ts->size(); ++i) {
      const auto* t = (*ts)[i].as_table();
      const std::string sec = "clump_template[" + std::to_string(i) + "]";
      if (!t) r.fail(sec, "expected a table");
      r.only(t, sec, {"name", "members", "shape", "diameter_m", "member_radius_m"});
      const std::string name = r.string(t, sec, "name", true, "");
      std::vector<ClumpMember> members;
      if (t->contains("shape")) {  // the seeds' shapes (clump_shapes.hpp)
        if (t->contains("members")) r.fail(sec + ".members", "give either shape or members");
        const std::string shape = r.string(t, sec, "shape", true, "");
        if (shape == "asymmetric4") {
          members = asymmetric_clump4(r.positive(t, sec, "diameter_m", true, 0));
        } else if (shape == "dimer") {
          members = dimer_clump(r.positive(t, sec, "member_radius_m", true, 0));
        } else {
          r.fail(sec + ".shape", "expected \"asymmetric4\" or \"dimer\"", shape);
        }
        if (!templates.emplace(name, members).second)
          r.fail(sec + ".name", "template defined twice", name);
        continue;
      }
      const auto* ms = (*t)["members"].as_array();
      if (!ms || ms->empty()) r.fail(sec + ".members", "a clump template needs member spheres");
      for (std::size_t k = 0; k < ms->size(); ++k) {
        const std::string key = sec + ".members[" + std::to_string(k) + "]";
        const auto* m = (*ms)[k].as_array();
        if (!m || m->size() != 4) r.fail(key, "expected [x, y, z, r]");
        double v[4];
        for (std::size_t c = 0; c < 4; ++c) {
          const auto d = (*m)[c].value<double>();
          if (!d || !std::isfinite(*d)) r.fail(key, "not a finite number");
          v[c] = *d;
        }
        if (!(v[3] > 0)) r.fail(key, "member radius must be positive", value_str(v[3]));
        members.push_back({{v[0], v[1], v[2]}, v[3]});
      }
      if (!templates.emplace(name, members).second)
        r.fail(sec + ".name", "template defined twice", name);
    }
  }
  const auto* clumps = r.table("clumps", false);
  if (!clumps) {
    if (!templates.empty()) r.fail("[clumps]", "templates given but no [clumps] packing");
    return;
  }
  r.only(clumps, "clumps", {"packing", "mass", "replace", "seed"});
  const std::string mass = r.string(clumps, "clumps", "mass", false, "member_sum");
  if (mass != "member_sum" && mass != "union")
    r.fail("clumps.mass", "expected \"member_sum\" or \"union\"", mass);
  const ClumpMassModel model = mass == "union" ? ClumpMassModel::Union : ClumpMassModel::MemberSum;
  if (clumps->contains("replace")) {
    // Seed 003 §2.4: every sphere of the packing becomes a clump of its volume, randomly turned.
    if (clumps->contains("packing")) r.fail("clumps.replace", "give either packing or replace");
    const std::string name = r.string(clumps, "clumps", "replace", true, "");
    const auto it = templates.find(name);
    if (it == templates.end()) r.fail("clumps.replace", "unknown clump template", name);
    auto& rep = s.clump_replace.emplace();
    rep.template_name = name;
    rep.shape = it->second;
    rep.model = model;
    rep.seed = static_cast<std::uint64_t>(r.integer(clumps, "clumps", "seed", false, 1, 0));
    // A generated specimen is replaced once it is made (scene_programmes).
    if (s.specimen) return;
    if (s.particles.empty()) r.fail("clumps.replace", "the packing has no spheres to replace");
    replace_spheres_by_clumps(s);
    return;
  }
  if (clumps->contains("seed")) r.fail("clumps.seed", "only with replace");
  const auto file = path.parent_path() / r.string(clumps, "clumps", "packing", true, "");
  std::error_code missing;
  if (!std::filesystem::exists(file, missing))
    r.fail("clumps.packing", "no such file", file.string());
  const std::string f = file.string();
  const std::string body_text = text::read_text_file(file);
  const auto lines = text::split_lines(body_text);
  if (lines.empty()) throw InputError(f, "empty clump packing");
  const auto header = text::split_csv(lines[0]);
  const std::vector<std::string_view> names = {"template", "x", "y", "z", "qw", "qx", "qy", "qz"};
  const auto idx = text::column_indices(header, names);
  for (std::size_t k = 0; k < names.size(); ++k)
    if (idx[k] >= header.size()) throw InputError(f, "missing column", std::string(names[k]));
  std::int64_t next_id = 0;
  for (const auto& p : s.particles) next_id = std::max(next_id, p.id + 1);
  for (std::size_t ln = 1; ln < lines.size(); ++ln) {
    if (text::trim(lines[ln]).empty()) continue;
    const auto tok = text::split_csv(lines[ln]);
    if (tok.size() < header.size())
      throw InputError(f, "line " + std::to_string(ln + 1) + ": too few columns");
    const std::string name(text::trim(tok[idx[0]]));
    const auto it = templates.find(name);
    if (it == templates.end())
      throw InputError(f, "line " + std::to_string(ln + 1) + ": unknown clump template", name);
    auto num = [&](std::size_t k, const char* what) {
      const double v = text::to_double(tok[idx[k]], f, ln + 1, what);
      if (!std::isfinite(v))
        throw InputError(f, "line " + std::to_string(ln + 1) + ": " + what + " is not finite",
                         value_str(v));
      return v;
    };
    const Eigen::Vector3d x(num(1, "x"), num(2, "y"), num(3, "z"));
    Eigen::Quaterniond q(num(4, "qw"), num(5, "qx"), num(6, "qy"), num(7, "qz"));
    if (!(std::abs(q.norm() - 1) < 1e-6))
      throw InputError(f,
                       "line " + std::to_string(ln + 1) + ": orientation is not a unit quaternion",
                       value_str(q.norm()));
    q.normalize();
    std::vector<std::uint32_t> index;
    std::vector<Eigen::Vector3d> pos;
    std::vector<double> rad;
    for (const auto& m : it->second) {
      Particle p;
      p.id = next_id++;
      p.position = x + q * m.offset;
      p.radius = m.radius;
      index.push_back(static_cast<std::uint32_t>(s.particles.size()));
      pos.push_back(p.position);
      rad.push_back(p.radius);
      s.particles.push_back(p);
    }
    auto body = make_clump_body(index, pos, rad, s.config.material.density, model);
    body.id = -1;  // (numbered after the particles by the scene: below)
    body.template_name = name;
    s.clumps.push_back(std::move(body));
  }
  for (auto& c : s.clumps) c.id = next_id++;
  for (const auto& c : s.clumps)
    for (const auto i : c.members) s.particles[i].clump_id = c.id;
}

// The materials after [material] ([[materials]], Hertz–Mindlin law only) and the material-pair
// table ([[material_pairs]]): the restitution of every pair that can meet, and a friction angle
// where it is not the smaller of the two materials' (YADE's default).
void read_materials(const Reader& r, const toml::table& root, bool hertz, Scene& s) {
  const auto* mat = r.table("material", true);
  s.material_names = {r.string(mat, "material", "name", false, "default")};
  s.material_radius_range = {{-1.0, -1.0}};
  const auto* ms = root["materials"].as_array();
  const auto* ps = root["material_pairs"].as_array();
  if (!ms) {
    if (ps) r.fail("[[material_pairs]]", "needs [[materials]]");
    return;
  }
  if (!hertz) r.fail("[[materials]]", "several materials need material.law = \"hertz_mindlin\"");
  for (std::size_t i = 0; i < ms->size(); ++i) {
    const auto* t = (*ms)[i].as_table();
    const std::string sec = "materials[" + std::to_string(i) + "]";
    if (!t) r.fail(sec, "expected a table");
    r.only(t, sec,
           {"name", "young_Pa", "poisson", "restitution", "friction_deg", "density_kg_m3",
            "radius_range_m"});
    Material m;
    const std::string name = r.string(t, sec, "name", true, "");
    if (std::find(s.material_names.begin(), s.material_names.end(), name) != s.material_names.end())
      r.fail(sec + ".name", "used twice", name);
    m.young_ec = r.positive(t, sec, "young_Pa", true, 0);
    m.poisson = r.number(t, sec, "poisson", true, 0);
    if (!(m.poisson > -1 && m.poisson <= 0.5))
      r.fail(sec + ".poisson", "outside (-1, 0.5]", value_str(m.poisson));
    m.restitution = r.number(t, sec, "restitution", false, NAN);
    if (!std::isnan(m.restitution) && !(m.restitution > 0 && m.restitution <= 1))
      r.fail(sec + ".restitution", "outside (0, 1]", value_str(m.restitution));
    m.friction_deg = r.number(t, sec, "friction_deg", true, 0);
    if (m.friction_deg < 0 || m.friction_deg >= 90)
      r.fail(sec + ".friction_deg", "outside [0, 90)", value_str(m.friction_deg));
    m.density = r.positive(t, sec, "density_kg_m3", true, 0);
    std::array<double, 2> range{-1.0, -1.0};
    if (t->contains("radius_range_m")) {
      const auto* a = (*t)["radius_range_m"].as_array();
      const auto lo = a && a->size() == 2 ? (*a)[0].value<double>() : std::nullopt;
      const auto hi = a && a->size() == 2 ? (*a)[1].value<double>() : std::nullopt;
      if (!lo || !hi || !(*lo > 0) || !(*hi >= *lo))
        r.fail(sec + ".radius_range_m", "expected [lo, hi] with 0 < lo <= hi");
      range = {*lo, *hi};
    }
    s.material_names.push_back(name);
    s.material_radius_range.push_back(range);
    s.config.more_materials.push_back(m);
  }
  const std::size_t n = s.material_names.size();
  auto at = [&](int i) -> const Material& {
    return i == 0 ? s.config.material : s.config.more_materials[static_cast<std::size_t>(i - 1)];
  };
  std::vector<double> en(n * n, NAN), phi(n * n, -1.0);
  for (std::size_t i = 0; i < n; ++i) en[i * n + i] = at(static_cast<int>(i)).restitution;
  for (std::size_t k = 0; ps && k < ps->size(); ++k) {
    const auto* t = (*ps)[k].as_table();
    const std::string sec = "material_pairs[" + std::to_string(k) + "]";
    if (!t) r.fail(sec, "expected a table");
    r.only(t, sec, {"materials", "restitution", "friction_deg"});
    const auto* a = (*t)["materials"].as_array();
    std::array<std::size_t, 2> ij{};
    for (std::size_t q = 0; q < 2; ++q) {
      const auto name = a && a->size() == 2 ? (*a)[q].value<std::string>() : std::nullopt;
      if (!name) r.fail(sec + ".materials", "expected two material names");
      const auto it = std::find(s.material_names.begin(), s.material_names.end(), *name);
      if (it == s.material_names.end()) r.fail(sec + ".materials", "unknown material", *name);
      ij[q] = static_cast<std::size_t>(it - s.material_names.begin());
    }
    const double e = r.number(t, sec, "restitution", true, 0);
    if (!(e > 0 && e <= 1)) r.fail(sec + ".restitution", "outside (0, 1]", value_str(e));
    const double f = r.number(t, sec, "friction_deg", false, -1);
    if (t->contains("friction_deg") && (f < 0 || f >= 90))
      r.fail(sec + ".friction_deg", "outside [0, 90)", value_str(f));
    en[ij[0] * n + ij[1]] = en[ij[1] * n + ij[0]] = e;
    phi[ij[0] * n + ij[1]] = phi[ij[1] * n + ij[0]] = f;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i; j < n; ++j)
      if (std::isnan(en[i * n + j]))
        r.fail("[[material_pairs]]", "no restitution for a pair of materials",
               s.material_names[i] + "/" + s.material_names[j]);
  s.config.pair_restitution = en;
  s.config.pair_friction_deg = phi;
}

/// The material a wall or mesh names (`material = "steel"`; default the first).
/// When a wall or a mesh is switched off: `off_at_s` (a time) and `off_after_fill` (when the
/// [fill] has settled), e.g. a lid under an outlet.
struct SwitchOff {
  double at_s = HUGE_VAL;
  bool after_fill = false;
};
SwitchOff read_switch_off(const Reader& r, const toml::table* t, const std::string& sec) {
  SwitchOff o;
  o.at_s = r.number(t, sec, "off_at_s", false, HUGE_VAL);
  if (!(o.at_s >= 0)) r.fail(sec + ".off_at_s", "must be >= 0", value_str(o.at_s));
  o.after_fill = r.boolean(t, sec, "off_after_fill", false);
  return o;
}

int material_index(const Reader& r, const Scene& s, const toml::table* t, const std::string& sec) {
  if (!t->contains("material")) return 0;
  const std::string name = r.string(t, sec, "material", true, "");
  const auto it = std::find(s.material_names.begin(), s.material_names.end(), name);
  if (it == s.material_names.end()) r.fail(sec + ".material", "unknown material", name);
  return static_cast<int>(it - s.material_names.begin());
}

/// [[particles]]: single particles added to the packing (e.g. the DEM8 impactor): position,
/// radius, velocity, material; ids after the packing's.
void read_extra_particles(const Reader& r, const toml::table& root, Scene& s) {
  const auto* ps = root["particles"].as_array();
  if (!ps) return;
  std::int64_t next = 0;
  for (const auto& p : s.particles) next = std::max(next, p.id + 1);
  for (std::size_t i = 0; i < ps->size(); ++i) {
    const auto* t = (*ps)[i].as_table();
    const std::string sec = "particles[" + std::to_string(i) + "]";
    if (!t) r.fail(sec, "expected a table");
    r.only(t, sec, {"position_m", "radius_m", "velocity_m_s", "material"});
    Particle q;
    q.id = next++;
    q.position = r.vec3(t, sec, "position_m", true, {});
    q.radius = r.positive(t, sec, "radius_m", true, 0);
    q.velocity = r.vec3(t, sec, "velocity_m_s", false, Eigen::Vector3d::Zero());
    q.material_id = material_index(r, s, t, sec);
    s.particles.push_back(q);
  }
}

/// A particle of material 0 (the default: none named, none in the packing) takes the first
/// material whose radius range holds its radius.
void assign_materials_by_radius(const Reader& r, Scene& s) {
  const std::size_t n = s.material_names.size();
  for (auto& p : s.particles) {
    for (std::size_t i = 1; p.material_id == 0 && i < n; ++i) {
      const auto& rr = s.material_radius_range[i];
      if (rr[0] > 0 && p.radius >= rr[0] && p.radius <= rr[1]) {
        p.material_id = static_cast<std::int32_t>(i);
        break;
      }
    }
    if (p.material_id < 0 || static_cast<std::size_t>(p.material_id) >= n)
      r.fail("scene.packing", "particle " + std::to_string(p.id) + " has no such material",
             std::to_string(p.material_id));
  }
}

/// [fill]: layers of a grading inserted into a region (layered_filling.hpp). The particles are
/// appended to the scene's (ids after every particle and clump), waiting for insertion; the
/// first layer is placed here already, so that a region too small for it is an error now.
void read_fill(const Reader& r, Scene& s) {
  const auto* t = r.table("fill", false);
  if (!t) return;
  if (!s.test.empty() && s.test != "silo")
    r.fail("[fill]", "a laboratory test makes its own specimen; remove [fill]");
  r.only(t, "fill",
         {"region_lo_m", "region_hi_m", "layers", "count", "dmin_m", "dmax_m", "distribution",
          "seed", "kinetic_ratio", "min_steps", "max_steps", "hold_steps", "max_attempts",
          "friction_deg", "damping", "placement"});
  FillSpec f;
  f.region_lo_m = r.vec3(t, "fill", "region_lo_m", true, {});
  f.region_hi_m = r.vec3(t, "fill", "region_hi_m", true, {});
  if (!(f.region_lo_m.array() < f.region_hi_m.array()).all())
    r.fail("fill.region_hi_m", "must exceed region_lo_m on every axis");
  f.layers = static_cast<int>(r.integer(t, "fill", "layers", false, 6, 1));
  f.count = r.integer(t, "fill", "count", true, 0, f.layers);
  if (f.count > 20000000) r.fail("fill.count", "more than 20 million", std::to_string(f.count));
  f.sizes.dmin_m = r.positive(t, "fill", "dmin_m", true, 0);
  f.sizes.dmax_m = r.positive(t, "fill", "dmax_m", true, 0);
  if (f.sizes.dmax_m < f.sizes.dmin_m)
    r.fail("fill.dmax_m", "smaller than dmin_m", value_str(f.sizes.dmax_m));
  const std::string dist = r.string(t, "fill", "distribution", false, "uniform");
  if (dist == "linear")
    f.sizes.distribution = SizeDistribution::Linear;
  else if (dist != "uniform")
    r.fail("fill.distribution", "expected \"uniform\" or \"linear\"", dist);
  f.seed = static_cast<std::uint64_t>(r.integer(t, "fill", "seed", false, 1, 0));
  f.kinetic_ratio = r.positive(t, "fill", "kinetic_ratio", false, f.kinetic_ratio);
  f.min_steps = r.integer(t, "fill", "min_steps", false, f.min_steps, 1);
  f.max_steps = r.integer(t, "fill", "max_steps", false, f.max_steps, f.min_steps);
  f.hold_steps = r.integer(t, "fill", "hold_steps", false, f.hold_steps, 1);
  if (f.hold_steps > f.max_steps)
    r.fail("fill.hold_steps", "more than max_steps", std::to_string(f.hold_steps));
  f.max_attempts = static_cast<int>(r.integer(t, "fill", "max_attempts", false, 20000, 1));
  f.friction_deg = r.number(t, "fill", "friction_deg", false, -1);
  if (!(f.friction_deg < 90))
    r.fail("fill.friction_deg", "must be below 90", value_str(f.friction_deg));
  f.damping = r.number(t, "fill", "damping", false, -1);
  if (t->contains("damping") && !(f.damping >= 0 && f.damping < 1))
    r.fail("fill.damping", "outside [0, 1)", value_str(f.damping));
  const std::string placement = r.string(t, "fill", "placement", false, "random");
  if (placement != "random" && placement != "lattice")
    r.fail("fill.placement", "expected \"random\" or \"lattice\"", placement);
  f.lattice = placement == "lattice";
  if (!(s.config.gravity.norm() > 0)) r.fail("solver.gravity_m_s2", "[fill] needs gravity");
  std::int64_t next_id = 0;
  for (const auto& p : s.particles) next_id = std::max(next_id, p.id + 1);
  for (const auto& c : s.clumps) next_id = std::max(next_id, c.id + 1);
  FillParticles fp;
  try {
    fp = fill_particles(f, next_id);
  } catch (const std::invalid_argument& e) {
    r.fail("[fill]", e.what());
  }
  // The first layer must fit among what is there at the start.
  {
    const Simulation probe(s.config, s.particles, s.walls);
    std::vector<double> radii;
    for (const auto k : fp.layers[0]) radii.push_back(fp.particles[k].radius);
    const auto placed = place_in_region(probe, radii, f.region_lo_m, f.region_hi_m,
                                        f.seed + 0x9e3779b97f4a7c15ull, f.max_attempts, f.lattice);
    if (placed.size() < radii.size())
      r.fail("fill.region_hi_m",
             "the region takes " + std::to_string(placed.size()) + " of the " +
                 std::to_string(radii.size()) + " particles of a layer (enlarge it, use more " +
                 "layers or fewer particles)",
             std::to_string(f.count));
  }
  s.fill_first = static_cast<std::uint32_t>(s.particles.size());
  s.fill_layers = fp.layers;
  for (auto& p : fp.particles) s.particles.push_back(p);
  s.fill = f;
}

}  // namespace

namespace {
// Two spheres at one centre have no contact normal: the engine skips the pair and they pass
// through each other without a word. (Members of one clump may share a centre.)
void check_distinct_centres(const Reader& r, const std::vector<Particle>& particles) {
  // Members of one clump may share a centre.
  std::map<std::array<double, 3>, const Particle*> at;
  for (const auto& p : particles) {
    const auto [it, fresh] =
        at.emplace(std::array<double, 3>{p.position.x(), p.position.y(), p.position.z()}, &p);
    const Particle& q = *it->second;
    if (fresh || (p.clump_id >= 0 && p.clump_id == q.clump_id)) continue;
    r.fail("particles",
           "particles " + std::to_string(q.id) + " and " + std::to_string(p.id) +
               " have the same centre",
           value_str(p.position.x()) + ", " + value_str(p.position.y()) + ", " +
               value_str(p.position.z()));
  }
}

// Outputs stay inside the output directory, and none replaces another: each is a plain file
// name (no directory part, no "..", not empty), all distinct, and none is the checkpoint index.
// Checked before anything runs (a clash used to show only after the whole run; an absolute
// trajectory path replaced a file anywhere on disk).
void check_output_names(const Reader& r, const Scene& s) {
  auto plain = [&](const std::string& key, const std::string& v) {
    if (v.empty()) r.fail(key, "must not be empty");
    if (v.find('/') != std::string::npos || v.find('\\') != std::string::npos || v == "." ||
        v == ".." || v.find('\0') != std::string::npos)
      r.fail(key, "must be a file name inside the output directory (no directory part)", v);
  };
  plain("scene.name", s.name);
  const std::vector<std::pair<std::string, std::string>> outs = {
      {"output.trajectory", s.output.trajectory},
      {"output.history", s.output.history},
      {"output.curve", s.output.curve},
      {"output.specimen", s.output.specimen},
      {"output.preparation", s.output.preparation},
      {"(checkpoint index)", "checkpoint.txt"}};
  for (std::size_t i = 0; i < outs.size(); ++i) {
    if (i + 1 < outs.size()) plain(outs[i].first, outs[i].second);
    for (std::size_t j = 0; j < i; ++j)
      if (outs[i].second == outs[j].second)
        r.fail(outs[i].first, "names the same file as " + outs[j].first, outs[i].second);
  }
}

}  // namespace

namespace {
// The shortest text that reads back as `d` (0.1, not 0.10000000000000001): a run directory's name.
std::string shortest_text(double d) {
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, d);
    if (std::strtod(buf, nullptr) == d) break;
  }
  return buf;
}
}  // namespace

bool scene_has_sweep(const std::filesystem::path& path) {
  try {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return false;
    return toml::parse_file(path.string()).contains("sweep");
  } catch (const std::exception&) {
    return false;
  }
}

namespace {

/// "a.b.c" -> {"a", "b", "c"} (a sweep's or an override's key).
std::vector<std::string> dotted_parts(const std::string& key) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(key);
  while (std::getline(in, part, '.')) parts.push_back(part);
  return parts;
}

/// Sets `key` (SECTION.KEY, SECTION.INDEX.KEY for arrays of tables) of `root` to the TOML value
/// `value`; missing sections are created.
template <class Reader>
void apply_override(const Reader& r, toml::table& root, const std::string& key,
                    const std::string& value) {
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    r.fail(key, "not a TOML value", value);
  }
  if (parsed.size() != 1) r.fail(key, "not a TOML value", value);
  const std::vector<std::string> parts = dotted_parts(key);
  if (parts.size() < 2 || parts[0] == "sweep") r.fail(key, "expected SECTION.KEY to set", key);
  toml::node* node = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    if (auto* t = node->as_table()) {
      if (!t->contains(parts[i])) t->insert(parts[i], toml::table{});
      node = t->get(parts[i]);
    } else if (auto* a = node->as_array()) {
      char* end = nullptr;
      const long k = std::strtol(parts[i].c_str(), &end, 10);
      if (end == parts[i].c_str() || *end != '\0' || k < 0 ||
          static_cast<std::size_t>(k) >= a->size())
        r.fail(key, "no such element", parts[i]);
      node = a->get(static_cast<std::size_t>(k));
    } else {
      r.fail(key, "not a section", parts[i]);
    }
  }
  auto* t = node->as_table();
  if (!t) r.fail(key, "not a section", parts[parts.size() - 2]);
  parsed.get("v")->visit([&](auto&& x) { t->insert_or_assign(parts.back(), x); });
}

}  // namespace

int machine_threads() {
  return std::clamp(omp_get_num_procs(), 1, kMaxThreads);
}

int auto_threads(std::size_t particles) {
  return particles < kAutoThreadsFrom ? 1 : machine_threads();
}

Scene load_scene(const std::filesystem::path& path, int sweep_point,
                 const SceneOverrides& overrides) {
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
  // [sweep]: key = "section.key", values = [...]: one run per value (cmd_simulate); point i
  // loads the scene with the key set to values[i] (point 0 when none is asked for).
  if (const auto* sw = r.table("sweep", false)) {
    r.only(sw, "sweep", {"key", "values"});
    const std::string key = r.string(sw, "sweep", "key", true, "");
    const auto* values = (*sw)["values"].as_array();
    if (!values || values->empty()) r.fail("sweep.values", "expected a non-empty array");
    const std::vector<std::string> parts = dotted_parts(key);
    if (parts.size() < 2 || parts[0] == "sweep")
      r.fail("sweep.key", "expected SECTION.KEY of another section", key);
    toml::table* t = &root;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      t = (*t)[parts[i]].as_table();
      if (!t) r.fail("sweep.key", "no such section", key);
    }
    auto& info = s.sweep.emplace();
    info.key = key;
    for (std::size_t i = 0; i < values->size(); ++i) {
      const auto& v = *values->get(i);
      if (const auto d = v.value<double>(); d && v.is_number())
        info.values.push_back(shortest_text(*d));
      else if (const auto str = v.value<std::string>())
        info.values.push_back(*str);
      else
        r.fail("sweep.values", "expected numbers or strings", std::to_string(i));
      const std::string& text = info.values.back();
      if (text.empty() || text.find('/') != std::string::npos || text == "." || text == "..")
        r.fail("sweep.values", "a value names a run directory: no '/' and not empty", text);
    }
    if (sweep_point >= static_cast<int>(values->size()))
      r.fail("sweep.values", "no such point", std::to_string(sweep_point));
    info.point = std::max(0, sweep_point);
    values->get(static_cast<std::size_t>(info.point))->visit([&](auto&& v) {
      t->insert_or_assign(parts.back(), v);
    });
    root.erase("sweep");
  }
  for (const auto& [key, value] : overrides) apply_override(r, root, key, value);
  for (const auto& [k, v] : root) {
    static const char* sections[] = {"scene",
                                     "material",
                                     "materials",
                                     "material_pairs",
                                     "particles",
                                     "solver",
                                     "output",
                                     "walls",
                                     "specimen",
                                     "preparation",
                                     "triaxial",
                                     "plane_strain",
                                     "direct_shear",
                                     "interface_shear",
                                     "mesh",
                                     "outlet",
                                     "clump_template",
                                     "clumps",
                                     "fill",
                                     "cell",
                                     "biaxial_periodic",
                                     "silo",
                                     "stress_rotation",
                                     "sweep"};
    if (std::find(std::begin(sections), std::end(sections), k.str()) == std::end(sections))
      r.fail("[" + std::string(k.str()) + "]", "unknown section");
  }
  const auto* scene = r.table("scene", true);
  r.only(scene, "scene", {"name", "packing", "packing_rows", "test", "wall_friction_deg"});
  s.name = r.string(scene, "scene", "name", true, "");
  s.test = r.string(scene, "scene", "test", false, "");
  if (!s.test.empty() && s.test != "triaxial" && s.test != "plane_strain" &&
      s.test != "direct_shear" && s.test != "interface_shear" && s.test != "biaxial_periodic" &&
      s.test != "silo" && s.test != "stress_rotation")
    r.fail("scene.test",
           "expected \"triaxial\", \"plane_strain\", \"direct_shear\", \"interface_shear\", "
           "\"biaxial_periodic\", \"silo\" or \"stress_rotation\"",
           s.test);
  const auto* specimen = r.table("specimen", false);
  const bool has_packing = scene->contains("packing");
  // A plain scene may start empty when clumps or a filling bring its particles.
  const bool brought = root.contains("fill") || root.contains("clumps");
  if (has_packing || (!specimen && !brought)) {
    const std::string packing = r.string(scene, "scene", "packing", true, "");
    const auto packing_path = path.parent_path() / packing;
    std::error_code missing;
    if (!std::filesystem::exists(packing_path, missing))
      r.fail("scene.packing", "no such file", packing_path.string());
    ImportOptions io;
    if (scene->contains("packing_rows"))
      io.max_particles =
          static_cast<std::size_t>(r.integer(scene, "scene", "packing_rows", true, 0, 1));
    const Trajectory t = read_snapshots(packing_path, io);
    if (t.frames.empty() || t.frames.back().particles.empty())
      throw InputError(packing_path.string(), "packing holds no particles");
    s.particles = t.frames.back().particles;
    s.parameters.emplace_back("scene.packing", packing);
  }
  if (specimen && has_packing) r.fail("[specimen]", "give either scene.packing or [specimen]");
  if (specimen && s.test.empty()) r.fail("[specimen]", "needs scene.test");
  if (s.test == "biaxial_periodic" && !specimen)
    r.fail("[specimen]", "missing (the periodic biaxial test generates its disks)");
  s.parameters.emplace_back("scene.name", s.name);
  s.wall_friction_deg = r.number(scene, "scene", "wall_friction_deg", false, 0.0);

  const auto* mat = r.table("material", true);
  const std::string law = r.string(mat, "material", "law", false, "cohesive_frictional");
  const bool hertz = law == "hertz_mindlin";
  if (!hertz && law != "cohesive_frictional")
    r.fail("material.law", "expected \"cohesive_frictional\" or \"hertz_mindlin\"", law);
  const bool several = root.contains("materials");
  if (hertz)  // (YADE's FrictMat with MindlinPhys: no stiffness ratio, no contact moments)
    r.only(mat, "material",
           {"law", "name", "young_Pa", "poisson", "restitution", "friction_deg", "density_kg_m3",
            "wall_radius"});
  else
    r.only(mat, "material",
           {"law", "young_Pa", "normal_stiffness_N_m", "stiffness_ratio", "friction_deg",
            "density_kg_m3", "rolling_stiffness", "rolling_limit", "rolling_limit_radius",
            "twisting_stiffness", "twisting_limit"});
  auto& m = s.config.material;
  s.config.law = hertz ? ContactLaw::HertzMindlin : ContactLaw::CohesiveFrictional;
  // Seed 003 §2.4's constant stiffness: Kn given in N/m instead of the modulus Ec.
  if (mat->contains("normal_stiffness_N_m"))
    m.normal_stiffness_N_m = r.positive(mat, "material", "normal_stiffness_N_m", true, 0);
  const bool constant_kn = m.normal_stiffness_N_m > 0;
  if (constant_kn && mat->contains("young_Pa"))
    r.fail("material.normal_stiffness_N_m", "give either young_Pa or normal_stiffness_N_m");
  if (!constant_kn) m.young_ec = r.positive(mat, "material", "young_Pa", true, 0);
  if (hertz) {
    m.poisson = r.number(mat, "material", "poisson", true, 0);
    if (!(m.poisson > -1 && m.poisson <= 0.5))
      r.fail("material.poisson", "outside (-1, 0.5]", value_str(m.poisson));
    m.restitution = r.number(mat, "material", "restitution", !several, NAN);
    if (!std::isnan(m.restitution) && !(m.restitution > 0 && m.restitution <= 1))
      r.fail("material.restitution", "outside (0, 1]", value_str(m.restitution));
    const std::string wr = r.string(mat, "material", "wall_radius", false, "flat");
    if (wr != "flat" && wr != "yade")
      r.fail("material.wall_radius", "expected \"flat\" or \"yade\"", wr);
    s.config.hertz_flat_walls = wr == "flat";
  } else {
    m.stiffness_ratio = r.number(mat, "material", "stiffness_ratio", true, 0);
  }
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
  read_materials(r, root, hertz, s);
  read_extra_particles(r, root, s);

  const auto* sol = r.table("solver", true);
  r.only(sol, "solver",
         {"dt_s", "dt_safety", "damping", "gravity_m_s2", "steps", "threads", "skin_m",
          "max_overlap_ratio", "max_energy_residual", "order"});
  if (specimen) {
    auto& sp = s.specimen.emplace();
    const bool periodic2d = s.test == "biaxial_periodic";
    if (periodic2d)
      r.only(specimen, "specimen",
             {"count", "two_d", "thickness_m", "dmin_m", "dmax_m", "distribution", "d50_m",
              "uniformity", "grading", "void_ratio", "seed", "cloud_solid_fraction"});
    else
      r.only(specimen, "specimen",
             {"size_m", "dmin_m", "dmax_m", "distribution", "d50_m", "uniformity", "void_ratio",
              "seed", "cloud_solid_fraction"});
    if (periodic2d) {
      sp.count = r.integer(specimen, "specimen", "count", true, 0, 3);
      if (sp.count > 10000000)
        r.fail("specimen.count", "more than 10 million disks", std::to_string(sp.count));
      const std::string two_d = r.string(specimen, "specimen", "two_d", false, "disks");
      if (two_d != "disks" && two_d != "spheres_in_plane")
        r.fail("specimen.two_d", "expected \"disks\" or \"spheres_in_plane\"", two_d);
      sp.disks = two_d == "disks";
      sp.sizes.mass_exponent = sp.disks ? 2 : 3;
    } else {
      sp.size_m = r.vec3(specimen, "specimen", "size_m", true, {});
      if ((sp.size_m.array() <= 0).any()) r.fail("specimen.size_m", "must be positive");
    }
    sp.sizes.dmin_m = r.positive(specimen, "specimen", "dmin_m", true, 0);
    sp.sizes.dmax_m = r.positive(specimen, "specimen", "dmax_m", true, 0);
    if (sp.sizes.dmax_m < sp.sizes.dmin_m)
      r.fail("specimen.dmax_m", "smaller than dmin_m", value_str(sp.sizes.dmax_m));
    const std::string dist = r.string(specimen, "specimen", "distribution", false, "uniform");
    if (dist == "uniform")
      sp.sizes.distribution = SizeDistribution::Uniform;
    else if (dist == "linear")
      sp.sizes.distribution = SizeDistribution::Linear;
    else if (dist == "graded")
      sp.sizes.distribution = SizeDistribution::Graded;
    else if (dist == "piecewise")
      sp.sizes.distribution = SizeDistribution::Piecewise;
    else
      r.fail("specimen.distribution",
             "expected \"uniform\", \"linear\", \"graded\" or \"piecewise\"", dist);
    if (dist == "piecewise") {
      // grading = [[d_m, mass fraction finer], …] from [dmin_m, 0] to [dmax_m, 1]; d50_m (the
      // weight-median, for the biaxial test's scales) is read off the curve.
      const auto* a = specimen->contains("grading") ? (*specimen)["grading"].as_array() : nullptr;
      if (!a) r.fail("specimen.grading", "missing: [[d_m, fraction finer], …]");
      for (std::size_t i = 0; i < a->size(); ++i) {
        const auto* row = (*a)[i].as_array();
        const auto d = row && row->size() == 2 ? (*row)[0].value<double>() : std::nullopt;
        const auto f = row && row->size() == 2 ? (*row)[1].value<double>() : std::nullopt;
        if (!d || !f)
          r.fail("specimen.grading", "expected [d_m, fraction] pairs", std::to_string(i));
        sp.sizes.grading.emplace_back(*d, *f);
      }
      try {
        check_piecewise(sp.sizes);
      } catch (const std::invalid_argument& e) {
        r.fail("specimen.grading", e.what());
      }
      sp.sizes.d50_m = mass_quantile(sp.sizes, 0.5);
    } else if (specimen->contains("grading")) {
      r.fail("specimen.grading", "only for distribution = \"piecewise\"");
    }
    if (dist == "graded") {
      sp.sizes.d50_m = r.positive(specimen, "specimen", "d50_m", true, 0);
      sp.sizes.uniformity = r.positive(specimen, "specimen", "uniformity", true, 0);
      try {
        fit_graded(sp.sizes);
      } catch (const std::invalid_argument& e) {
        r.fail("specimen.uniformity", e.what(), value_str(sp.sizes.uniformity));
      }
    } else {
      for (const char* k : {"d50_m", "uniformity"})
        if (specimen->contains(k))
          r.fail(std::string("specimen.") + k, "only for distribution = \"graded\"");
    }
    sp.void_ratio = r.positive(specimen, "specimen", "void_ratio", false, sp.void_ratio);
    sp.seed = static_cast<std::uint64_t>(r.integer(specimen, "specimen", "seed", false, 1, 0));
    sp.cloud_solid_fraction = r.positive(specimen, "specimen", "cloud_solid_fraction", false,
                                         periodic2d ? 0.45 : sp.cloud_solid_fraction);
    const double cloud_limit = periodic2d ? 0.6 : 0.45;  // random sequential addition jams
    if (sp.cloud_solid_fraction >= cloud_limit)
      r.fail("specimen.cloud_solid_fraction",
             std::string("too dense for random sequential addition (< ") +
                 (periodic2d ? "0.6 in 2D)" : "0.45)"),
             value_str(sp.cloud_solid_fraction));
    if (periodic2d) {
      sp.thickness_m = r.positive(specimen, "specimen", "thickness_m", false, 2 * sp.sizes.dmax_m);
    }
  }
  double& auto_dt_safety = s.dt_auto_safety;  // "auto": dt is set once clumps and fillings are in
  if (sol->contains("dt_s") && (*sol)["dt_s"].is_string()) {
    if (r.string(sol, "solver", "dt_s", true, "") != "auto")
      r.fail("solver.dt_s", "expected a number or \"auto\"");
    auto_dt_safety = r.positive(sol, "solver", "dt_safety", false, 0.3);
    s.config.dt = 1;  // (a placeholder until then)
  } else {
    s.config.dt = r.positive(sol, "solver", "dt_s", true, 0);
  }
  s.config.damping = r.number(sol, "solver", "damping", false, 0);
  if (s.config.damping < 0 || s.config.damping >= 1)
    r.fail("solver.damping", "outside [0, 1)", value_str(s.config.damping));
  s.config.gravity = r.vec3(sol, "solver", "gravity_m_s2", false, Eigen::Vector3d::Zero());
  s.steps = r.integer(sol, "solver", "steps", s.test.empty(), 0, 0);
  // "auto" (and the default): chosen by the run from the number of particles (auto_threads).
  std::int64_t threads = 0;
  if (sol->contains("threads") && (*sol)["threads"].is_string()) {
    if (r.string(sol, "solver", "threads", true, "") != "auto")
      r.fail("solver.threads", "expected a number or \"auto\"",
             r.string(sol, "solver", "threads", true, ""));
  } else {
    threads = r.integer(sol, "solver", "threads", false, 0, 1);
  }
  if (threads > kMaxThreads)
    r.fail("solver.threads", "must be at most " + std::to_string(kMaxThreads),
           std::to_string(threads));
  s.config.threads = static_cast<int>(threads);
  s.config.skin = r.number(sol, "solver", "skin_m", false, 0);
  s.config.max_overlap_ratio = r.positive(sol, "solver", "max_overlap_ratio", false, 0.1);
  s.config.max_energy_residual = r.positive(sol, "solver", "max_energy_residual", false, 0.2);
  // "file" (the default, YADE's order: the results to the bit of YADE's) or "spatial".
  const std::string order = r.string(sol, "solver", "order", false, "file");
  if (order != "file" && order != "spatial")
    r.fail("solver.order", "expected \"file\" or \"spatial\"", order);
  s.spatial_order = order == "spatial";
  if (s.spatial_order && !s.test.empty())
    r.fail("solver.order",
           "\"spatial\" is for plain scenes (the laboratory tests keep the file's order)", s.test);

  const auto* out = r.table("output", false);
  r.only(out, "output",
         {"trajectory", "every", "contacts", "history", "history_every", "checkpoint_every",
          "curve", "curve_every", "specimen", "preparation", "facet_forces", "track_ids"});
  s.output.trajectory = r.string(out, "output", "trajectory", false, s.output.trajectory);
  s.output.every = r.integer(out, "output", "every", false, s.output.every, 1);
  s.output.contacts = out && out->contains("contacts") ? (*out)["contacts"].value_or(true) : true;
  s.output.history = r.string(out, "output", "history", false, s.output.history);
  s.output.history_every =
      r.integer(out, "output", "history_every", false, s.output.history_every, 1);
  s.output.checkpoint_every =
      r.integer(out, "output", "checkpoint_every", false, s.output.checkpoint_every, 1);
  s.output.curve = r.string(out, "output", "curve", false, s.output.curve);
  s.output.curve_every = r.integer(out, "output", "curve_every", false, s.output.curve_every, 1);
  s.output.specimen = r.string(out, "output", "specimen", false, s.output.specimen);
  s.output.preparation = r.string(out, "output", "preparation", false, s.output.preparation);
  check_output_names(r, s);
  if (out && out->contains("track_ids")) {
    const auto* a = (*out)["track_ids"].as_array();
    if (!a) r.fail("output.track_ids", "expected an array of particle ids");
    for (std::size_t i = 0; i < a->size(); ++i) {
      const auto id = (*a)[i].value<std::int64_t>();
      if (!id) r.fail("output.track_ids", "expected an array of particle ids");
      s.output.track_ids.push_back(*id);
    }
  }
  s.output.facet_forces = r.boolean(out, "output", "facet_forces", false);
  read_lab_sections(r, root, s);

  if (s.test == "interface_shear" && root.contains("outlet"))
    r.fail("[outlet]",
           "the interface shear test removes what falls off its surface; remove [outlet]");
  if (s.test == "silo" && root.contains("outlet"))
    r.fail("[outlet]", "the silo removes what leaves through its outlet; remove [outlet]");
  if (!s.test.empty() && root.contains("walls"))
    r.fail("[[walls]]", "a laboratory test builds its own walls; remove [[walls]]");
  if (const auto* walls = root["walls"].as_array()) {
    for (std::size_t i = 0; i < walls->size(); ++i) {
      const auto* w = (*walls)[i].as_table();
      const std::string sec = "walls[" + std::to_string(i) + "]";
      if (!w) r.fail(sec, "expected a table");
      r.only(w, sec,
             {"name", "shape", "center_m", "half_extents_m", "point_m", "normal",
              "angular_velocity_rad_s", "velocity_m_s", "servo", "friction_deg", "material",
              "off_at_s", "off_after_fill"});
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
      spec.friction_deg = r.number(w, sec, "friction_deg", false, -1);
      spec.material = material_index(r, s, w, sec);
      if (const auto* servo = (*w)["servo"].as_table()) {
        const std::string ss = sec + ".servo";
        r.only(servo, ss, {"stress_Pa", "area_m2", "gain_m_s_per_Pa", "max_velocity_m_s", "axis"});
        spec.servo_stress_Pa = r.number(servo, ss, "stress_Pa", true, 0);
        spec.servo_area_m2 = r.positive(servo, ss, "area_m2", true, 0);
        spec.servo_gain = r.positive(servo, ss, "gain_m_s_per_Pa", true, 0);
        spec.servo_max_velocity = r.positive(servo, ss, "max_velocity_m_s", true, 0);
        if (spec.shape == WallShape::Box) spec.normal = r.vec3(servo, ss, "axis", true, {});
      }
      const SwitchOff off = read_switch_off(r, w, sec);
      spec.off_at_s = off.at_s;
      if (off.after_fill) s.open_after_fill.push_back(s.walls.size());
      s.walls.push_back(spec);
    }
  }
  if (!s.test.empty() && root.contains("mesh"))
    r.fail("[[mesh]]", "a laboratory test builds its own walls; remove [[mesh]]");
  if (const auto* meshes = root["mesh"].as_array()) {
    for (std::size_t i = 0; i < meshes->size(); ++i) {
      const auto* m = (*meshes)[i].as_table();
      const std::string sec = "mesh[" + std::to_string(i) + "]";
      if (!m) r.fail(sec, "expected a table");
      r.only(m, sec,
             {"file", "scale", "contact", "velocity_m_s", "friction_deg", "name",
              "angular_velocity_rad_s", "rotation_center_m", "servo", "off_at_s", "off_after_fill",
              "material"});
      const std::string file_name = r.string(m, sec, "file", true, "");
      const auto mesh_path = path.parent_path() / file_name;
      std::error_code missing;
      if (!std::filesystem::exists(mesh_path, missing))
        r.fail(sec + ".file", "no such file", mesh_path.string());
      const double scale = r.positive(m, sec, "scale", false, 1.0);
      const std::string contact_name = r.string(m, sec, "contact", false, "merged");
      const std::optional<MeshContact> contact = mesh_contact_named(contact_name);
      if (!contact) r.fail(sec + ".contact", "expected \"merged\" or \"yade\"", contact_name);
      const std::string name = r.string(m, sec, "name", false, "");
      const TriangleMesh tm = read_mesh(mesh_path, scale);  // (InputError names the mesh file)
      MeshTriangles tri;
      for (std::size_t t = 0; t < tm.triangles.size(); ++t) {
        const auto& v = tm.triangles[t];
        tri.triangles.push_back({tm.vertices[static_cast<std::size_t>(v[0])],
                                 tm.vertices[static_cast<std::size_t>(v[1])],
                                 tm.vertices[static_cast<std::size_t>(v[2])]});
        const std::string& g = tm.group_names[static_cast<std::size_t>(tm.group[t])];
        tri.group.push_back(name.empty() ? g : name + "/" + g);
      }
      // The mesh moves as one rigid body: velocity, rotation about a centre (default the centre
      // of its bounding box), a servo on the force summed over its triangles, switched off at a
      // time (an outlet opening).
      const Eigen::Vector3d omega =
          r.vec3(m, sec, "angular_velocity_rad_s", false, Eigen::Vector3d::Zero());
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
      for (const auto& t : tri.triangles)
        for (const auto& v : t) {
          lo = lo.cwiseMin(v);
          hi = hi.cwiseMax(v);
        }
      const Eigen::Vector3d centre = r.vec3(m, sec, "rotation_center_m", false, 0.5 * (lo + hi));
      const SwitchOff off = read_switch_off(r, m, sec);
      WallSpec servo;
      if (const auto* sv = (*m)["servo"].as_table()) {
        const std::string ss = sec + ".servo";
        r.only(sv, ss, {"stress_Pa", "area_m2", "gain_m_s_per_Pa", "max_velocity_m_s", "axis"});
        servo.servo_stress_Pa = r.number(sv, ss, "stress_Pa", true, 0);
        servo.servo_area_m2 = r.positive(sv, ss, "area_m2", true, 0);
        servo.servo_gain = r.positive(sv, ss, "gain_m_s_per_Pa", true, 0);
        servo.servo_max_velocity = r.positive(sv, ss, "max_velocity_m_s", true, 0);
        servo.normal = r.vec3(sv, ss, "axis", true, {});
        if (!(servo.normal.norm() > 0)) r.fail(ss + ".axis", "must not be zero");
      }
      const int body = static_cast<int>(i);
      const int mesh_material = material_index(r, s, m, sec);
      try {
        for (auto& w : mesh_walls(tri, *contact,
                                  r.vec3(m, sec, "velocity_m_s", false, Eigen::Vector3d::Zero()),
                                  r.number(m, sec, "friction_deg", false, -1))) {
          w.angular_velocity = omega;
          w.rotation_center = centre;
          w.body = body;
          w.mesh = name.empty() ? mesh_path.stem().string() : name;
          w.off_at_s = off.at_s;
          w.material = mesh_material;
          w.servo_stress_Pa = servo.servo_stress_Pa;
          w.servo_area_m2 = servo.servo_area_m2;
          w.servo_gain = servo.servo_gain;
          w.servo_max_velocity = servo.servo_max_velocity;
          w.normal = servo.normal;
          if (off.after_fill) s.open_after_fill.push_back(s.walls.size());
          s.walls.push_back(std::move(w));
        }
      } catch (const std::invalid_argument& e) {
        throw InputError(mesh_path.string(), e.what());
      }
    }
  }
  read_clumps(r, root, path, s);
  if (const auto* cell = r.table("cell", false)) {
    // Periodic cell (docs/scenes.md "[cell]"; YADE's O.cell.hSize and O.cell.velGrad).
    r.only(cell, "cell",
           {"size_m", "hsize_m", "velocity_gradient_1_s", "two_d", "control", "target",
            "servo_gain", "servo_fraction", "max_rate_1_s"});
    auto& c = s.cell.emplace();
    if (cell->contains("size_m") == cell->contains("hsize_m"))
      r.fail("cell", "give one of size_m and hsize_m");
    if (cell->contains("size_m")) {
      const Eigen::Vector3d size = r.vec3(cell, "cell", "size_m", true, {});
      if (!(size.array() > 0).all()) r.fail("cell.size_m", "must be positive");
      c.hsize = size.asDiagonal();
    } else {
      c.hsize = r.matrix3(cell, "cell", "hsize_m", true, {});
    }
    if (!(c.hsize.determinant() > 0))
      r.fail(cell->contains("size_m") ? "cell.size_m" : "cell.hsize_m",
             "singular or inverted cell (det H <= 0)", value_str(c.hsize.determinant()));
    c.vel_grad = r.matrix3(cell, "cell", "velocity_gradient_1_s", false, Eigen::Matrix3d::Zero());
    const std::string two_d = r.string(cell, "cell", "two_d", false, "");
    if (two_d == "spheres_in_plane" || two_d == "disks")
      c.planar = true;
    else if (!two_d.empty())
      r.fail("cell.two_d", "expected \"spheres_in_plane\" or \"disks\"", two_d);
    c.disks = two_d == "disks";
    if (cell->contains("control")) {
      // Each diagonal axis: "stress" (target in Pa, compression negative) or "rate" (1/s).
      auto& sv = c.servo.emplace();
      const auto* ctl = (*cell)["control"].as_array();
      if (!ctl || ctl->size() != 3) r.fail("cell.control", "expected 3 of \"stress\" and \"rate\"");
      for (std::size_t i = 0; i < 3; ++i) {
        const auto v = (*ctl)[i].value<std::string>();
        if (!v || (*v != "stress" && *v != "rate"))
          r.fail("cell.control", "expected 3 of \"stress\" and \"rate\"",
                 v ? *v : "entry " + std::to_string(i));
        sv.stress[i] = *v == "stress";
      }
      sv.target = r.vec3(cell, "cell", "target", true, {});
      const bool any = sv.stress[0] || sv.stress[1] || sv.stress[2];
      if (cell->contains("servo_gain") && cell->contains("servo_fraction"))
        r.fail("cell.servo_fraction", "give one of servo_gain and servo_fraction");
      if (any && cell->contains("servo_fraction")) {
        sv.stiffness_fraction = r.positive(cell, "cell", "servo_fraction", true, 0);
        if (sv.stiffness_fraction > 1)
          r.fail("cell.servo_fraction", "must be at most 1", value_str(sv.stiffness_fraction));
      } else {
        sv.gain = any ? r.positive(cell, "cell", "servo_gain", true, 0) : 0.0;
      }
      sv.max_rate = any ? r.positive(cell, "cell", "max_rate_1_s", true, 0) : 0.0;
      for (int i = 0; i < 3; ++i)
        if (c.vel_grad(i, i) != 0)
          r.fail("cell.velocity_gradient_1_s",
                 "its diagonal is the servo's (cell.control): give 0 there",
                 value_str(c.vel_grad(i, i)));
    } else {
      for (const char* k : {"target", "servo_gain", "servo_fraction", "max_rate_1_s"})
        if (cell->contains(k)) r.fail(std::string("cell.") + k, "needs cell.control");
    }
    if (root.contains("walls") || root.contains("mesh"))
      r.fail("[cell]", "walls and meshes in a periodic cell are not supported");
    if (root.contains("clumps")) r.fail("[cell]", "clumps in a periodic cell are not supported");
    if (!s.test.empty())
      r.fail("[cell]", s.test == "biaxial_periodic"
                           ? "the periodic biaxial test makes its own cell; remove [cell]"
                           : "a periodic cell runs a plain scene (no scene.test)");
  }
  if (const auto* outlet = r.table("outlet", false)) {
    r.only(outlet, "outlet", {"keep_lo_m", "keep_hi_m"});
    const Eigen::Vector3d lo = r.vec3(outlet, "outlet", "keep_lo_m", true, {});
    const Eigen::Vector3d hi = r.vec3(outlet, "outlet", "keep_hi_m", true, {});
    if (!(lo.array() < hi.array()).all())
      r.fail("outlet.keep_hi_m", "must exceed keep_lo_m on every axis");
    s.outlet = std::make_pair(lo, hi);
  }
  read_fill(r, s);
  {
    std::vector<double> all;
    for (const auto& p : s.particles) all.push_back(p.radius);
    if (s.specimen) all.push_back(0.5 * s.specimen->sizes.dmin_m);
    s.dt_pwave = material_timestep(all, s.config.material);
    if (auto_dt_safety > 0) s.config.dt = auto_dt_safety * s.dt_pwave;
    assign_materials_by_radius(r, s);
    for (const auto id : s.output.track_ids)
      if (std::none_of(s.particles.begin(), s.particles.end(),
                       [&](const Particle& p) { return p.id == id; }))
        r.fail("output.track_ids", "no particle with this id", std::to_string(id));
    const auto& m = s.config.material;
    if (s.config.law == ContactLaw::HertzMindlin && (!s.clumps.empty() || s.clump_replace))
      r.fail("material.law", "the Hertz-Mindlin law does not take clumps yet", "hertz_mindlin");
    if (s.config.law == ContactLaw::HertzMindlin && !all.empty()) {
      // Each material's Rayleigh step from its own smallest sphere (YADE's RayleighWaveTimeStep
      // takes each body's own material); a generated specimen is of the scene's material.
      std::vector<double> rmin(1 + s.config.more_materials.size(), HUGE_VAL);
      for (const auto& p : s.particles) {
        auto& x = rmin[static_cast<std::size_t>(std::max(p.material_id, 0))];
        x = std::min(x, p.radius);
      }
      if (s.specimen) rmin[0] = std::min(rmin[0], 0.5 * s.specimen->sizes.dmin_m);
      double dt_r = HUGE_VAL;
      for (std::size_t i = 0; i < rmin.size(); ++i) {
        if (rmin[i] == HUGE_VAL) continue;
        const Material& pm = i == 0 ? m : s.config.more_materials[i - 1];
        dt_r = std::min(dt_r, rayleigh_timestep({rmin[i]}, pm.density, pm.young_ec, pm.poisson));
      }
      if (s.config.dt > dt_r)
        r.fail("solver.dt_s", "above the Hertz critical (Rayleigh) step " + value_str(dt_r) + " s",
               value_str(s.config.dt));
    }
  }
  if (!s.open_after_fill.empty() && !s.fill) r.fail("off_after_fill", "there is no [fill] section");
  // (The particles of a [fill] are placed later, layer by layer.)
  check_distinct_centres(
      r, {s.particles.begin(), s.particles.begin() + (s.fill ? s.fill_first : s.particles.size())});
  std::ostringstream flat;
  flat << root;
  s.parameters.emplace_back("scene.toml", flat.str());
  {
    std::string names;  // the material of id k is the k-th (analyze materials reads them)
    for (const auto& n : s.material_names) names += (names.empty() ? "" : ",") + n;
    s.parameters.emplace_back("material_names", names);
  }
  return s;
}

namespace {
void flatten(const toml::table& t, const std::string& prefix,
             std::map<std::string, std::string>& out) {
  for (const auto& [k, v] : t) {
    const std::string key =
        prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) {
      flatten(*sub, key, out);
    } else {
      std::ostringstream os;
      v.visit([&](auto&& x) { os << x; });
      out[key] = os.str();
    }
  }
}
}  // namespace

std::map<std::string, std::string> scene_values(const std::string& toml_text) {
  std::map<std::string, std::string> out;
  flatten(toml::parse(toml_text), "", out);
  return out;
}

std::vector<std::string> scene_differences(const std::string& a, const std::string& b) {
  std::map<std::string, std::string> fa, fb;
  flatten(toml::parse(a), "", fa);
  flatten(toml::parse(b), "", fb);
  std::vector<std::string> keys;
  for (const auto& [k, v] : fa)
    if (!fb.count(k) || fb.at(k) != v) keys.push_back(k);
  for (const auto& [k, v] : fb)
    if (!fa.count(k)) keys.push_back(k);
  std::sort(keys.begin(), keys.end());
  return keys;
}

}  // namespace gs::solver
