#include "interface_shear.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cuboid_walls.hpp"
#include "errors.hpp"
#include "mesh_walls.hpp"
#include "surface_generators.hpp"

namespace gs::solver {

namespace {

double rad(double deg) {
  return deg * M_PI / 180.0;
}

// The surface's patch as mesh walls, appended to w: merged (one contact per tooth face or
// corrugation strip, a plane wall's stiffness) or YADE's facets (docs/physics.md).
void append_mesh(const TriangleMesh& tm, double friction_deg, MeshContact mode,
                 std::vector<WallSpec>& w) {
  MeshTriangles tri;
  for (const auto& f : tm.triangles) {
    tri.triangles.push_back({tm.vertices[f[0]], tm.vertices[f[1]], tm.vertices[f[2]]});
    tri.group.push_back("surface");
  }
  for (auto& x : mesh_walls(tri, mode, Eigen::Vector3d::Zero(), friction_deg)) {
    x.mesh = "surface";
    x.body = 0;
    w.push_back(std::move(x));
  }
}

}  // namespace

std::vector<WallSpec> interface_surface_walls(const InterfaceSurfaceSpec& s,
                                              InterfaceShearGeometry& g, double dmax_m,
                                              InterfaceShearWalls& index) {
  const std::string sec = "interface_shear.";
  require_value(g.length_m > 0, "specimen.size_m", g.length_m, "length must be positive");
  require_value(g.width_m > 0, "specimen.size_m", g.width_m, "width must be positive");
  require_value(g.height_m > 0, "specimen.size_m", g.height_m, "height must be positive");
  require_value(dmax_m > 0, "specimen.dmax_m", dmax_m, "must be positive");
  require_value(g.travel_m > 0, sec + "max_displacement_m", g.travel_m, "must be positive");
  const std::optional<MeshContact> contact = mesh_contact_named(s.contact);
  if (!contact)
    throw std::invalid_argument(sec + "surface_contact: expected \"merged\" or \"yade\" (" +
                                s.contact + ")");
  require_value(g.wall_thickness_m > 0, "wall thickness", g.wall_thickness_m, "must be positive");
  const double L = g.length_m, W = g.width_m, t = g.wall_thickness_m;
  // The surface runs from before the frame's start to beyond its end of travel, whole periods;
  // what leaks out of the frame and is pushed off the surface's ends is removed (scene_programmes
  // sets the outlet), so that nothing jams between the frame and a wall.
  const double margin = t + 4 * dmax_m;
  std::vector<WallSpec> w;
  index.surface_begin = 0;
  if (s.kind == "saw_tooth") {
    require_value(s.d50_m > 0, sec + "d50_m", s.d50_m, "must be positive");
    require_value(s.roughness > 0, sec + "roughness", s.roughness,
                  "must be positive (flat: surface = \"flat\")");
    const double hg = s.roughness * s.d50_m;
    require_value(hg >= 1e-3 * s.d50_m, sec + "roughness", s.roughness,
                  "gives teeth below 1e-3·d50");
    require_value(s.tooth_slope_deg > 0 && s.tooth_slope_deg < 90, sec + "tooth_slope_deg",
                  s.tooth_slope_deg, "outside (0, 90)");
    const double base = 2 * hg / std::tan(rad(s.tooth_slope_deg));
    const double sg = s.tooth_spacing_ratio * hg;
    require_value(sg >= base * (1 - 1e-9), sec + "tooth_spacing_ratio", s.tooth_spacing_ratio,
                  "teeth wider than their spacing");
    const double before = std::ceil(margin / sg), after = std::ceil((L + g.travel_m + margin) / sg);
    require_value(before + after <= 2e5, sec + "roughness", s.roughness,
                  "more than 200 000 teeth along the surface");
    SawToothSpec st;
    st.origin = Eigen::Vector3d(-before * sg, 0, 0);
    st.length_m = (before + after) * sg;
    st.width_m = W;
    st.height_m = hg;
    st.spacing_m = sg;
    st.slope_deg = s.tooth_slope_deg;
    st.back_slope_deg = s.tooth_slope_deg;
    st.group = "surface";
    append_mesh(saw_tooth_wall(st), s.friction_deg, *contact, w);
    g.crest_z_m = hg;
    g.trough_z_m = 0;
    g.mean_z_m = 0.5 * hg * base / sg;  // the teeth's area per pitch over the pitch
    g.surface_x0_m = st.origin.x();
    g.surface_x1_m = st.origin.x() + st.length_m;
  } else if (s.kind == "sinusoid" && s.depth_ratio != 0) {
    require_value(s.wavelength_m > 0, sec + "wavelength_m", s.wavelength_m, "must be positive");
    require_value(s.depth_ratio > 0 && s.depth_ratio < 1, sec + "depth_ratio", s.depth_ratio,
                  "outside [0, 1)");
    require_value(s.segments_per_wavelength >= 4, sec + "segments_per_wavelength",
                  s.segments_per_wavelength, "must be at least 4");
    const double l = s.wavelength_m, d = s.depth_ratio * l;
    const double before = std::ceil(margin / l), after = std::ceil((L + g.travel_m + margin) / l);
    SinusoidSpec ss;
    ss.origin = Eigen::Vector3d(-before * l, 0, 0);
    ss.length_m = (before + after) * l;
    ss.width_m = W;
    ss.depth_m = d;
    ss.wavelength_m = l;
    ss.segments_per_wavelength = s.segments_per_wavelength;
    ss.group = "surface";
    append_mesh(sinusoidal_wall(ss), s.friction_deg, *contact, w);
    g.crest_z_m = 0.5 * d;
    g.trough_z_m = -0.5 * d;
    g.mean_z_m = 0;
    g.surface_x0_m = ss.origin.x();
    g.surface_x1_m = ss.origin.x() + ss.length_m;
  } else if (s.kind == "flat" || s.kind == "sinusoid") {  // (a sinusoid of depth 0 is flat)
    g.surface_x0_m = -margin;
    g.surface_x1_m = L + g.travel_m + margin;
    w.push_back(
        box_wall("surface", {g.surface_x0_m, 0, -t}, {g.surface_x1_m, W, 0}, s.friction_deg));
    w.back().group = "surface";
    g.crest_z_m = g.mean_z_m = g.trough_z_m = 0;
  } else {
    throw std::invalid_argument(
        sec + "surface: expected \"saw_tooth\", \"sinusoid\" or \"flat\" (" + s.kind + ")");
  }
  index.surface_end = w.size();
  g.surface_triangles = 0;
  for (std::size_t k = index.surface_begin; k < index.surface_end; ++k)
    g.surface_triangles += w[k].facets.size();
  return w;
}

void append_interface_box_walls(InterfaceShearGeometry& g, double dmax_m, std::vector<WallSpec>& w,
                                InterfaceShearWalls& index) {
  if (g.gap_m < 0) g.gap_m = dmax_m;
  const double L = g.length_m, W = g.width_m, t = g.wall_thickness_m;
  require_value(g.platen_z_m > g.crest_z_m, "platen", g.platen_z_m, "below the surface's crests");
  require_value(g.frame_top_m > g.platen_z_m, "frame top", g.frame_top_m, "below the platen");
  const double x0 = g.surface_x0_m, x1 = g.surface_x1_m, zb = g.trough_z_m - t;
  const double zf = g.crest_z_m + g.gap_m;  // the frame's lower edge
  const double ff = g.frame_friction_deg;
  index.frame[0] = w.size();
  w.push_back(box_wall("frame x-", {-t, -t, zf}, {0, W + t, g.frame_top_m}, ff));
  index.frame[1] = w.size();
  w.push_back(box_wall("frame x+", {L, -t, zf}, {L + t, W + t, g.frame_top_m}, ff));
  index.closer[0] = w.size();
  w.push_back(box_wall("closer x-", {-t, -t, g.trough_z_m}, {0, W + t, zf + 0.5 * t}, ff));
  index.closer[1] = w.size();
  w.push_back(box_wall("closer x+", {L, -t, g.trough_z_m}, {L + t, W + t, zf + 0.5 * t}, ff));
  index.side[0] = w.size();
  w.push_back(box_wall("side y-", {x0 - t, -t, zb}, {x1 + t, 0, g.frame_top_m}, ff));
  index.side[1] = w.size();
  w.push_back(box_wall("side y+", {x0 - t, W, zb}, {x1 + t, W + t, g.frame_top_m}, ff));
  index.platen = w.size();
  w.push_back(
      box_wall("platen", {0, 0, g.platen_z_m}, {L, W, g.platen_z_m + t}, g.platen_friction_deg));
}

std::vector<WallSpec> interface_shear_walls(const InterfaceSurfaceSpec& s,
                                            InterfaceShearGeometry& g, double dmax_m,
                                            InterfaceShearWalls& index) {
  auto w = interface_surface_walls(s, g, dmax_m, index);
  append_interface_box_walls(g, dmax_m, w, index);
  return w;
}

SpecimenGauge interface_shear_gauge(const InterfaceShearGeometry& g, const InterfaceShearWalls& w) {
  SpecimenGauge gauge =
      platen_gauge(g.length_m, g.width_m, g.wall_thickness_m, w.platen, g.crest_z_m);
  gauge.clump_solid_factor = g.clump_solid_factor;
  return gauge;
}

InterfaceShear::InterfaceShear(InterfaceShearSpec spec, InterfaceShearGeometry g,
                               InterfaceShearWalls w)
    : MeasuredProgramme({spec.max_displacement_m, spec.frame_every_m}), spec_(spec), g_(g), w_(w) {
  const std::string sec = "interface_shear.";
  require_value(spec_.normal_stress_Pa > 0, sec + "normal_stress_Pa", spec_.normal_stress_Pa,
                "must be positive");
  require_value(spec_.shear_velocity_m_s > 0, sec + "shear_velocity_m_s", spec_.shear_velocity_m_s,
                "must be positive");
  require_value(spec_.max_displacement_m > 0, sec + "max_displacement_m", spec_.max_displacement_m,
                "must be positive");
  require_value(spec_.residual_fraction > 0 && spec_.residual_fraction < 1,
                sec + "residual_fraction", spec_.residual_fraction, "outside (0, 1)");
  require_value(spec_.peak_fraction > 0 && spec_.peak_fraction <= 0.5, sec + "peak_fraction",
                spec_.peak_fraction, "outside (0, 0.5]");
  require_value(spec_.internal_friction_deg > 0 && spec_.internal_friction_deg < 90,
                sec + "internal_friction_deg", spec_.internal_friction_deg, "outside (0, 90)");
  if (!(spec_.frame_every_m > 0)) spec_.frame_every_m = spec_.max_displacement_m / 10;
  target_ = {spec_.max_displacement_m, spec_.frame_every_m};
}

double InterfaceShear::specimen_height(const Simulation& sim) const {
  return sim.walls()[w_.platen].pos.z() - 0.5 * g_.wall_thickness_m - g_.mean_z_m;
}

void InterfaceShear::start(Simulation& sim) {
  sim.share_all_states();  // (under a domain: e0 from every particle's present state)
  reset_rotations(sim);
  for (const auto c : w_.closer) sim.set_wall_active(c, false);
  for (std::size_t k = 0; k < sim.walls().size(); ++k)
    if (!sim.walls()[k].spec.velocity.isZero()) sim.set_wall_velocity(k, Eigen::Vector3d::Zero());
  x0_ = sim.walls()[w_.frame[0]].pos.x();
  frame_z0_ = sim.walls()[w_.frame[0]].pos.z();
  h0_ = specimen_height(sim);
  e0_ = void_ratio(sim);
}

double InterfaceShear::platen_force(const Simulation& sim) const {
  return sim.walls()[w_.platen].force.z();
}

void InterfaceShear::control(Simulation& sim) {
  const Eigen::Vector3d v(spec_.shear_velocity_m_s, 0, 0);
  // A free frame moves up at the speed that removes the fraction servo_gain of its vertical
  // load per step (over its contacts' summed stiffness), as the platen's servo; untouched, it
  // stays.
  double frame_vz = 0;
  if (spec_.frame_free) {
    const double fz = frame_vertical_force(sim);
    double k = 0;
    for (const auto w : w_.frame) k += sim.wall_stiffness(w).first;
    if (k > 0)
      frame_vz = std::clamp(spec_.servo_gain * fz / (k * sim.config().dt),
                            -spec_.max_platen_speed_m_s, spec_.max_platen_speed_m_s);
  }
  for (const auto k : w_.frame) sim.set_wall_velocity(k, v + Eigen::Vector3d(0, 0, frame_vz));
  const double area = g_.length_m * g_.width_m;
  const double vz = servo_speed(sim, w_.platen, platen_force(sim) / area, spec_.normal_stress_Pa,
                                area, spec_.servo_gain, spec_.max_platen_speed_m_s);
  sim.set_wall_velocity(w_.platen, v + Eigen::Vector3d(0, 0, -vz));
}

double InterfaceShear::displacement(const Simulation& sim) const {
  return sim.walls()[w_.frame[0]].pos.x() - x0_;
}

double InterfaceShear::frame_vertical_force(const Simulation& sim) const {
  double fz = 0;
  for (const auto k : w_.frame) fz += sim.walls()[k].force.z();
  return fz;
}

double InterfaceShear::frame_shear_force(const Simulation& sim) const {
  double fx = sim.walls()[w_.platen].force.x();
  for (const auto k : w_.frame) fx += sim.walls()[k].force.x();
  return -fx;
}

Eigen::Vector3d InterfaceShear::surface_force(const Simulation& sim) const {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (std::size_t k = w_.surface_begin; k < w_.surface_end; ++k) f += sim.walls()[k].force;
  return f;
}

double InterfaceShear::void_ratio(const Simulation& sim) const {
  const double u = displacement(sim);
  const double top = sim.walls()[w_.platen].pos.z() - 0.5 * g_.wall_thickness_m;
  return box_void_ratio(sim.particles(), {u, 0, g_.crest_z_m}, {u + g_.length_m, g_.width_m, top},
                        g_.clump_solid_factor);
}

// The mean of μ over the sub-bins max(0, j − kWindowBins + 1) … j, j the last closed sub-bin, or
// the one in progress with `with_current` (a run shorter than a window: from u = 0); `last`: j.
double InterfaceShear::window_mean(bool with_current, std::int64_t& last) const {
  last = with_current ? bin_ : bin_ - 1;
  double sum = with_current ? bin_sum_ : 0.0, n = with_current ? bin_n_ : 0.0;
  const std::int64_t first = std::max<std::int64_t>(0, last - kWindowBins + 1);
  for (std::int64_t j = with_current ? last - 1 : last; j >= first; --j) {
    sum += ring_sum_[static_cast<std::size_t>(j % kWindowBins)];
    n += ring_n_[static_cast<std::size_t>(j % kWindowBins)];
  }
  return n > 0 ? sum / n : -1e300;
}

// The centre of the window that ends with sub-bin `last` (from u = 0 while shorter).
double InterfaceShear::window_centre(std::int64_t last) const {
  const std::int64_t first = std::max<std::int64_t>(0, last - kWindowBins + 1);
  return 0.5 * static_cast<double>(first + last + 1) * sub_bin_width();
}

void InterfaceShear::close_sub_bin() const {
  ring_sum_[static_cast<std::size_t>(bin_ % kWindowBins)] = bin_sum_;
  ring_n_[static_cast<std::size_t>(bin_ % kWindowBins)] = bin_n_;
  ++bin_;
  bin_sum_ = bin_n_ = 0;
  std::int64_t last = 0;
  const double m = window_mean(false, last);
  if (last + 1 >= kWindowBins && m > peak_) {  // (whole windows only; see results())
    peak_ = m;
    peak_u_ = window_centre(last);
  }
}

void InterfaceShear::record(double u, double mu, double eps_v) const {
  const std::int64_t bin =
      std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(u / sub_bin_width())));
  if (bin_ < 0) bin_ = bin;            // (the first row: the sub-bins before it stay empty)
  while (bin_ < bin) close_sub_bin();  // (and any the frame passed without a row, empty)
  bin_sum_ += mu;
  bin_n_ += 1;
  if (u >= (1 - spec_.residual_fraction) * spec_.max_displacement_m) {
    res_sum_ += mu;
    eps_res_sum_ += eps_v;
    res_n_ += 1;
  }
  last_eps_ = eps_v;
}

std::string InterfaceShear::curve_header() const {
  return "step,time_s,u_m,u_over_L,T_N,P_N,tau_Pa,sigma_n_Pa,mu_eff,phi_s_deg,surface_T_N,"
         "surface_P_N,surface_mu,dh_m,eps_v,void_ratio,coordination,particles_outside,"
         "inertial_number,frame_dz_m,frame_P_N";
}

std::string InterfaceShear::curve_row(const Simulation& sim) const {
  const double u = displacement(sim), T = frame_shear_force(sim), P = platen_force(sim);
  const double A = g_.length_m * g_.width_m;
  const Eigen::Vector3d fs = surface_force(sim);
  // The particles exert −F on the walls' sum: the surface is pushed along +x and down.
  const double sT = fs.x(), sP = -fs.z();
  const double h = specimen_height(sim), eps = (h - h0_) / h0_;
  const double mu = P > 0 ? T / P : 0.0;
  std::size_t outside = 0;
  const auto& p = sim.particles();
  const double top = h + g_.mean_z_m;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p.removed.empty() && p.removed[i]) continue;
    const Eigen::Vector3d& x = p.pos[i];
    if (x.x() < u || x.x() > u + g_.length_m || x.z() > top) ++outside;
  }
  if (P > 0) record(u, mu, eps);
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,"
                "%.9g,%.6g,%zu,%.6g,%.9g,%.9g",
                static_cast<long long>(sim.step_count()), sim.time(), u, u / g_.length_m, T, P,
                T / A, P / A, mu, std::atan(mu) * 180 / M_PI, sT, sP, sP > 0 ? sT / sP : 0.0,
                h - h0_, eps, void_ratio(sim), coordination_number(sim), outside,
                sim.inertial_number(),
                spec_.frame_free ? sim.walls()[w_.frame[0]].pos.z() - frame_z0_ : 0.0,
                frame_vertical_force(sim));
  return buf;
}

std::vector<std::pair<std::string, double>> InterfaceShear::results(const Simulation& sim) const {
  // The window that ends with the sub-bin in progress counts towards the peak too, and so, for a
  // run shorter than a window, the mean over its whole travel.
  double peak = peak_, peak_u = peak_u_;
  std::int64_t last = 0;
  const double m = bin_ >= 0 ? window_mean(true, last) : -1e300;
  if (m > peak) {
    peak = m;
    peak_u = window_centre(last);
  }
  const double res = res_n_ > 0 ? res_sum_ / res_n_ : NAN;
  const double eps_res = res_n_ > 0 ? eps_res_sum_ / res_n_ : NAN;
  std::vector<std::pair<std::string, double>> r = {{"mu_eff_max", peak},
                                                   {"phi_s_max_deg", std::atan(peak) * 180 / M_PI},
                                                   {"u_peak_m", peak_u},
                                                   {"mu_eff_res", res},
                                                   {"phi_s_res_deg", std::atan(res) * 180 / M_PI},
                                                   {"eps_v_res", eps_res},
                                                   {"eps_v_end", last_eps_},
                                                   {"void_ratio_start", e0_},
                                                   {"u_end_m", displacement(sim)}};
  if (spec_.flat_friction >= 0) {
    // Seed 004 Eq 4.7: a_w = (μeff − tan φi) / (μw − tan φi).
    const double ti = std::tan(rad(spec_.internal_friction_deg));
    r.emplace_back("a_w_max", (peak - ti) / (spec_.flat_friction - ti));
    r.emplace_back("a_w_res", (res - ti) / (spec_.flat_friction - ti));
  }
  return r;
}

std::string InterfaceShear::summary(const Simulation& sim) const {
  const auto r = results(sim);
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "interface shear: u %.4g m, peak mu_eff %.4f (phi_s %.2f deg at u %.3g m), "
                "residual %.4f (%.2f deg), eps_v residual %.4g, e0 %.4f",
                displacement(sim), r[0].second, r[1].second, r[2].second, r[3].second, r[4].second,
                r[5].second, e0_);
  std::string s = buf;
  if (r.size() > 9) {
    std::snprintf(buf, sizeof buf, "; a_w (Eq 4.7, phi_i %.1f deg) %.4f peak, %.4f residual",
                  spec_.internal_friction_deg, r[9].second, r[10].second);
    s += buf;
  }
  return s;
}

std::string InterfaceShear::save_state() const {
  ProgrammeState st;
  st.set("x0", x0_);
  st.set("h0", h0_);
  st.set("frame_z0", frame_z0_);
  st.set("e0", e0_);
  st.set("bin", bin_);
  st.set("bin_sum", bin_sum_);
  st.set("bin_n", bin_n_);
  for (int k = 0; k < kWindowBins; ++k) {
    st.set("ring_sum_" + std::to_string(k), ring_sum_[static_cast<std::size_t>(k)]);
    st.set("ring_n_" + std::to_string(k), ring_n_[static_cast<std::size_t>(k)]);
  }
  st.set("peak", peak_);
  st.set("peak_u", peak_u_);
  st.set("res_sum", res_sum_);
  st.set("res_n", res_n_);
  st.set("eps_res_sum", eps_res_sum_);
  st.set("last_eps", last_eps_);
  return st.text();
}

void InterfaceShear::load_state(const std::string& state) {
  const ProgrammeState st(state);
  x0_ = st.number("x0");
  h0_ = st.number("h0");
  // (older checkpoints: a held frame, whose rise is 0 without it)
  frame_z0_ = st.has("frame_z0") ? st.number("frame_z0") : 0;
  e0_ = st.number("e0");
  bin_ = st.integer("bin");
  bin_sum_ = st.number("bin_sum");
  bin_n_ = st.number("bin_n");
  if (st.has("ring_n_0")) {
    for (int k = 0; k < kWindowBins; ++k) {
      ring_sum_[static_cast<std::size_t>(k)] = st.number("ring_sum_" + std::to_string(k));
      ring_n_[static_cast<std::size_t>(k)] = st.number("ring_n_" + std::to_string(k));
    }
  } else {  // (older checkpoints: fixed bins of the whole width; the windows start afresh)
    bin_ = -1;
    bin_sum_ = bin_n_ = 0;
  }
  peak_ = st.number("peak");
  peak_u_ = st.number("peak_u");
  res_sum_ = st.number("res_sum");
  res_n_ = st.number("res_n");
  eps_res_sum_ = st.number("eps_res_sum");
  last_eps_ = st.number("last_eps");
}

}  // namespace gs::solver
