#include "silo_flow.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cuboid_walls.hpp"
#include "errors.hpp"
#include "mesh_walls.hpp"
#include "sphere_box_volume.hpp"
#include "surface_generators.hpp"

namespace gs::solver {

namespace {

double rad(double deg) {
  return deg * M_PI / 180.0;
}

}  // namespace

std::vector<WallSpec> silo_walls(const SiloSpec& s, double d50_m, double dmax_m, SiloWalls& index) {
  require_value(s.width_m > 0, "silo.width_m", s.width_m, "must be positive");
  require_value(s.height_m > 0, "silo.height_m", s.height_m, "must be positive");
  require_value(s.depth_m > 0, "silo.depth_m", s.depth_m, "must be positive");
  require_value(d50_m > 0, "silo.d50_m", d50_m, "must be positive");
  require_value(dmax_m > 0, "fill.dmax_m", dmax_m, "must be positive");
  require_value(s.roughness >= 0, "silo.roughness", s.roughness, "must not be negative");
  const double hg = s.roughness * d50_m;
  require_value(s.roughness == 0 || hg >= 1e-3 * d50_m, "silo.roughness", s.roughness,
                "gives teeth below 1e-3·d50");
  require_value(s.tooth_slope_deg > 0 && s.tooth_slope_deg < 90, "silo.tooth_slope_deg",
                s.tooth_slope_deg, "outside (0, 90)");
  const double base = 2 * hg / std::tan(rad(s.tooth_slope_deg));  // both faces at α_g
  const double sg = s.tooth_spacing_ratio * hg;
  require_value(s.roughness == 0 || sg >= base * (1 - 1e-9), "silo.tooth_spacing_ratio",
                s.tooth_spacing_ratio, "teeth wider than their spacing");
  require_value(2 * hg < 0.5 * s.width_m, "silo.roughness", s.roughness,
                "teeth take more than half the width");
  const bool quasi = s.mode == "quasi_static";
  require_value(quasi || s.mode == "gravitational", "silo.mode", 0,
                "expected \"quasi_static\" or \"gravitational\"");
  const double t = std::max(2 * dmax_m, 0.02 * s.width_m);  // plate thickness
  // The side walls reach below the bottom by its travel (and a grain), so that nothing leaks
  // under them while the bottom moves down.
  index.floor_z_m = quasi ? -(s.bottom_travel_m + 2 * dmax_m) : 0.0;
  index.tooth_height_m = hg;
  index.dmax_m = dmax_m;
  index.tooth_spacing_m = sg;
  std::vector<WallSpec> w;
  const double W = s.width_m, D = s.depth_m, z0 = index.floor_z_m, L = s.height_m - z0;
  auto side = [&](bool left) {
    const std::string name = left ? "left" : "right";
    const std::size_t first = w.size();
    if (hg == 0) {
      w.push_back(
          plane_wall(name, {left ? 0.0 : W, 0, 0}, {left ? 1.0 : -1.0, 0, 0}, s.wall_friction_deg));
      w.back().group = name;
    } else {
      SawToothSpec st;
      st.along = Eigen::Vector3d::UnitZ();
      st.normal = Eigen::Vector3d(left ? 1.0 : -1.0, 0, 0);
      // e_v = e_n × e_u: −y on the left wall, +y on the right one.
      st.origin = left ? Eigen::Vector3d(0, D, z0) : Eigen::Vector3d(W, 0, z0);
      st.length_m = L;
      st.width_m = D;
      st.height_m = hg;
      st.spacing_m = sg;
      st.slope_deg = s.tooth_slope_deg;
      st.back_slope_deg = s.tooth_slope_deg;
      st.group = name;
      const TriangleMesh tm = saw_tooth_wall(st);
      MeshTriangles tri;
      for (const auto& f : tm.triangles) {
        tri.triangles.push_back({tm.vertices[f[0]], tm.vertices[f[1]], tm.vertices[f[2]]});
        tri.group.push_back(name);
      }
      for (auto& x :
           mesh_walls(tri, MeshContact::Merged, Eigen::Vector3d::Zero(), s.wall_friction_deg)) {
        x.mesh = name;
        x.body = left ? 0 : 1;
        x.rotation_center = Eigen::Vector3d(left ? 0.0 : W, 0.5 * D, 0.5 * (z0 + s.height_m));
        w.push_back(std::move(x));
      }
    }
    (left ? index.left_begin : index.right_begin) = first;
    (left ? index.left_end : index.right_end) = w.size();
  };
  side(true);
  side(false);
  const double bf = s.bottom_friction_deg;
  index.bottom.clear();
  index.outlet = SIZE_MAX;
  const Eigen::Vector3d lo(-t, -t, -t), hi(W + t, D + t, 0);
  if (quasi) {
    require_value(s.bottom_velocity_m_s > 0, "silo.bottom_velocity_m_s", s.bottom_velocity_m_s,
                  "must be positive");
    require_value(s.bottom_travel_m > 0, "silo.bottom_travel_m", s.bottom_travel_m,
                  "must be positive");
    index.bottom.push_back(w.size());
    w.push_back(box_wall("bottom", lo, hi, bf));
  } else {
    const double b = s.outlet_width_m;
    double x1 = 0, x2 = 0;  // the opening
    if (s.outlet == "centre") {
      x1 = 0.5 * (W - b);
      x2 = 0.5 * (W + b);
    } else if (s.outlet == "right") {
      x1 = W - b;
      x2 = W;
    } else {
      throw std::invalid_argument("silo.outlet: expected \"centre\" or \"right\" (" + s.outlet +
                                  ")");
    }
    require_value(b > 0 && x1 >= 0, "silo.outlet_width_m", b, "outside the bottom");
    require_value(b > dmax_m, "silo.outlet_width_m", b, "not wider than the largest grain");
    require_value(s.settle_s >= 0, "silo.settle_s", s.settle_s, "must not be negative");
    if (x1 > 0) {
      index.bottom.push_back(w.size());
      w.push_back(box_wall("bottom_left", lo, {x1, hi.y(), 0}, bf));
    }
    if (x2 < W) {
      index.bottom.push_back(w.size());
      w.push_back(box_wall("bottom_right", {x2, lo.y(), lo.z()}, hi, bf));
    }
    index.outlet = w.size();
    w.push_back(box_wall("outlet", {x1 > 0 ? x1 : lo.x(), lo.y(), lo.z()},
                         {x2 < W ? x2 : hi.x(), hi.y(), 0}, bf));
  }
  index.front = w.size();
  w.push_back(plane_wall("front", {0, 0, 0}, Eigen::Vector3d::UnitY(), s.front_back_friction_deg));
  index.back = w.size();
  w.push_back(plane_wall("back", {0, D, 0}, -Eigen::Vector3d::UnitY(), s.front_back_friction_deg));
  return w;
}

SiloForces silo_forces(const Simulation& sim, const SiloWalls& w) {
  SiloForces f;
  const auto& walls = sim.walls();
  const auto& p = sim.particles();
  const double g = sim.config().gravity.norm();
  // The bottom's surface: the top of its plate (it moves in the quasi-static mode).
  const WallState& b0 = walls.at(w.bottom.empty() ? w.outlet : w.bottom.front());
  const double z_bottom = b0.pos.z() + b0.spec.half_extents.z();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.removed[i] == 0 && p.pos[i].z() > z_bottom) f.weight += p.mass[i] * g;
  for (const std::size_t k : w.bottom) f.bottom -= walls[k].force.z();
  if (w.outlet != SIZE_MAX && walls[w.outlet].active) f.bottom -= walls[w.outlet].force.z();
  for (std::size_t k = w.left_begin; k < w.left_end; ++k) {
    f.t_left -= walls[k].force.z();
    f.n_left -= walls[k].force.x();
  }
  for (std::size_t k = w.right_begin; k < w.right_end; ++k) {
    f.t_right -= walls[k].force.z();
    f.n_right += walls[k].force.x();
  }
  return f;
}

SiloFlow::SiloFlow(SiloSpec spec, SiloWalls walls) : spec_(std::move(spec)), w_(std::move(walls)) {
  require_value(spec_.flow_damping >= 0 && spec_.flow_damping < 1, "silo.flow_damping",
                spec_.flow_damping, "outside [0, 1)");
  if (quasi_static()) {
    require_value(spec_.frame_every_m >= 0, "silo.frame_every_m", spec_.frame_every_m,
                  "must not be negative");
  } else {
    require_value(spec_.max_discharge_s > 0, "silo.max_discharge_s", spec_.max_discharge_s,
                  "must be positive");
    require_value(spec_.end_fraction > 0 && spec_.end_fraction <= 1, "silo.end_fraction",
                  spec_.end_fraction, "outside (0, 1]");
    require_value(spec_.stop_after_s >= 0, "silo.stop_after_s", spec_.stop_after_s,
                  "must not be negative");
    require_value(spec_.frame_every_s >= 0, "silo.frame_every_s", spec_.frame_every_s,
                  "must not be negative");
  }
}

void SiloFlow::start(Simulation& sim) {
  // (under a domain: every process reads every particle's state here, as one process does)
  sim.share_all_states();
  sim.set_damping(spec_.flow_damping);
  reset_rotations(sim);
  t0_ = sim.time();
  const WallState& b = sim.walls().at(w_.bottom.empty() ? w_.outlet : w_.bottom.front());
  z0_ = b.pos.z();
  mass0_ = silo_forces(sim, w_).weight / sim.config().gravity.norm();
  removed0_ = sim.removed_mass();
  opened_ = false;
  // The gauge box for the void ratio: below the fill's surface, clear of walls and bottom.
  const auto& p = sim.particles();
  std::vector<double> tops;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.removed[i] == 0) tops.push_back(p.pos[i].z() + p.radius[i]);
  std::sort(tops.begin(), tops.end());
  const std::size_t n_top = std::min(tops.size(), std::max<std::size_t>(1, tops.size() / 20));
  double surface = 0;
  for (std::size_t k = tops.size() - n_top; k < tops.size(); ++k)
    surface += tops[k] / static_cast<double>(n_top);
  const double c = w_.tooth_height_m + w_.dmax_m;
  gauge_lo_ = Eigen::Vector3d(c, 0, z0_ + b.spec.half_extents.z() + w_.dmax_m);
  gauge_hi_ = Eigen::Vector3d(spec_.width_m - c, spec_.depth_m, surface - w_.dmax_m);
  e0_ = void_ratio(sim);
}

double SiloFlow::void_ratio(const Simulation& sim) const {
  if (!(gauge_hi_.array() > gauge_lo_.array()).all()) return NAN;
  const auto& p = sim.particles();
  double solid = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.removed[i] == 0) solid += sphere_box_volume(p.pos[i], p.radius[i], gauge_lo_, gauge_hi_);
  const double v = (gauge_hi_ - gauge_lo_).prod();
  return solid > 0 ? v / solid - 1 : NAN;
}

double SiloFlow::travel(const Simulation& sim) const {
  return z0_ - sim.walls()[w_.bottom.front()].pos.z();
}

void SiloFlow::control(Simulation& sim) {
  if (quasi_static()) {
    const Eigen::Vector3d v(0, 0, -spec_.bottom_velocity_m_s);
    for (const std::size_t k : w_.bottom) sim.set_wall_velocity(k, v);
    return;
  }
  if (!opened_ && sim.time() - t0_ >= spec_.settle_s) {
    sim.set_wall_active(w_.outlet, false);
    opened_ = true;
  }
  if (!opened_) return;
  // (NaN: the opening step, or a checkpoint written before these keys)
  const double out = discharged_mass(sim);
  if (std::isnan(last_out_t_) || out > last_out_mass_) {
    last_out_t_ = sim.time();
    last_out_mass_ = out;
  }
}

bool SiloFlow::stalled(const Simulation& sim) const {
  return opened_ && spec_.stop_after_s > 0 && sim.time() - last_out_t_ >= spec_.stop_after_s;
}

bool SiloFlow::finished(const Simulation& sim) const {
  if (quasi_static()) return travel(sim) >= spec_.bottom_travel_m;
  if (!opened_) return false;
  return discharged_mass(sim) >= spec_.end_fraction * mass0_ || stalled(sim) ||
         sim.time() - t0_ >= spec_.settle_s + spec_.max_discharge_s;
}

double SiloFlow::progress(const Simulation& sim) const {
  if (quasi_static()) return std::clamp(travel(sim) / spec_.bottom_travel_m, 0.0, 1.0);
  const double by_time = (sim.time() - t0_) / (spec_.settle_s + spec_.max_discharge_s);
  const double by_mass = mass0_ > 0 ? discharged_mass(sim) / (spec_.end_fraction * mass0_) : 0.0;
  return std::clamp(std::max(by_time, by_mass), 0.0, 1.0);
}

std::string SiloFlow::curve_header() const {
  return "time_s,flow_time_s,u_m,G_N,P_N,T_left_N,T_right_N,N_left_N,N_right_N,P_G,T_left_G,"
         "T_right_G,N_left_G,N_right_G,balance_G,phi_w_left_deg,phi_w_right_deg,"
         "discharged_kg,discharged_fraction,inertial_number,void_ratio";
}

std::string SiloFlow::curve_row(const Simulation& sim) const {
  const SiloForces f = silo_forces(sim, w_);
  const double G = f.weight;
  auto by_g = [&](double x) { return G > 0 ? x / G : NAN; };
  const double deg = 180.0 / M_PI;
  const double u = quasi_static() ? travel(sim) : 0.0;
  const double out = discharged_mass(sim);
  char b[768];
  std::snprintf(b, sizeof b,
                "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,"
                "%.9g,%.6g,%.6g,%.17g,%.9g,%.6g,%.6g",
                sim.time(), sim.time() - t0_, u, G, f.bottom, f.t_left, f.t_right, f.n_left,
                f.n_right, by_g(f.bottom), by_g(f.t_left), by_g(f.t_right), by_g(f.n_left),
                by_g(f.n_right), by_g(f.bottom + f.t_left + f.t_right),
                std::atan2(f.t_left, f.n_left) * deg, std::atan2(f.t_right, f.n_right) * deg, out,
                mass0_ > 0 ? out / mass0_ : 0.0, sim.inertial_number(), void_ratio(sim));
  return b;
}

std::int64_t SiloFlow::frame_index(const Simulation& sim) const {
  if (quasi_static())
    return spec_.frame_every_m > 0
               ? static_cast<std::int64_t>(std::floor(travel(sim) / spec_.frame_every_m))
               : 0;
  return spec_.frame_every_s > 0
             ? static_cast<std::int64_t>(std::floor((sim.time() - t0_) / spec_.frame_every_s))
             : 0;
}

std::string SiloFlow::summary(const Simulation& sim) const {
  const SiloForces f = silo_forces(sim, w_);
  char b[768];
  if (quasi_static()) {
    std::snprintf(
        b, sizeof b,
        "silo (quasi-static): e0 = %.3f; u = %.4g m; G = %.4g N, P/G = %.3f, T/G = %.3f / %.3f, "
        "N/G = %.3f / %.3f (left / right), (P + 2T)/G = %.3f",
        e0_, travel(sim), f.weight, f.bottom / f.weight, f.t_left / f.weight, f.t_right / f.weight,
        f.n_left / f.weight, f.n_right / f.weight, (f.bottom + f.t_left + f.t_right) / f.weight);
  } else {
    char why[160] = "";
    if (discharged_mass(sim) < spec_.end_fraction * mass0_ && stalled(sim))
      std::snprintf(why, sizeof why,
                    "; the flow stopped: nothing left in the last %.4g s (silo.stop_after_s)",
                    spec_.stop_after_s);
    std::snprintf(
        b, sizeof b,
        "silo (gravitational, outlet %s, b = %.4g m): e0 = %.3f; %.4g kg of %.4g kg discharged "
        "(%.1f %%) in %.4g s after the opening%s",
        spec_.outlet.c_str(), spec_.outlet_width_m, e0_, discharged_mass(sim), mass0_,
        mass0_ > 0 ? 100 * discharged_mass(sim) / mass0_ : 0.0, sim.time() - t0_ - spec_.settle_s,
        why);
  }
  return b;
}

std::string SiloFlow::save_state() const {
  ProgrammeState st;
  st.set("t0", t0_);
  st.set("z0", z0_);
  st.set("mass0", mass0_);
  st.set("removed0", removed0_);
  st.set("opened", static_cast<std::int64_t>(opened_));
  st.set("e0", e0_);
  st.set("last_out_t", last_out_t_);
  st.set("last_out_mass", last_out_mass_);
  for (int k = 0; k < 3; ++k) {
    st.set("gauge_lo" + std::to_string(k), gauge_lo_[k]);
    st.set("gauge_hi" + std::to_string(k), gauge_hi_[k]);
  }
  return st.text();
}

void SiloFlow::load_state(const std::string& state) {
  const ProgrammeState st(state);
  t0_ = st.number("t0");
  z0_ = st.number("z0");
  mass0_ = st.number("mass0");
  removed0_ = st.number("removed0");
  opened_ = st.integer("opened") != 0;
  e0_ = st.number("e0");
  // (a checkpoint written before these keys: the next step's control starts the clock again)
  last_out_t_ = st.has("last_out_t") ? st.number("last_out_t") : NAN;
  last_out_mass_ = st.has("last_out_mass") ? st.number("last_out_mass") : 0;
  for (int k = 0; k < 3; ++k) {
    gauge_lo_[k] = st.number("gauge_lo" + std::to_string(k));
    gauge_hi_[k] = st.number("gauge_hi" + std::to_string(k));
  }
}

}  // namespace gs::solver
