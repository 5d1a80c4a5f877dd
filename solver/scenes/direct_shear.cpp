#include "direct_shear.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "cuboid_walls.hpp"

namespace gs::solver {

std::vector<WallSpec> shear_box_walls(const ShearBoxGeometry& g, ShearBoxWalls& index) {
  const double L = g.length_m, W = g.width_m, t = g.wall_thickness_m;
  if (!(L > 0 && W > 0 && g.height_m > 0 && t > 0 && g.gap_m >= 0))
    throw std::invalid_argument("shear box dimensions must be positive");
  if (!(g.frame_top_m > g.height_m)) throw std::invalid_argument("frame top below the specimen");
  const double zl = 0.5 * (g.height_m - g.gap_m), zu = 0.5 * (g.height_m + g.gap_m);
  std::vector<WallSpec> w;
  // Four sides of a frame between heights a and b; the x sides cover the y sides' ends.
  auto sides = [&](const std::string& prefix, double a, double b, double friction, auto& out) {
    const std::size_t first = w.size();
    w.push_back(box_wall(prefix + "x-", {-t, -t, a}, {0, W + t, b}, friction));
    w.push_back(box_wall(prefix + "x+", {L, -t, a}, {L + t, W + t, b}, friction));
    w.push_back(box_wall(prefix + "y-", {0, -t, a}, {L, 0, b}, friction));
    w.push_back(box_wall(prefix + "y+", {0, W, a}, {L, W + t, b}, friction));
    for (std::size_t k = 0; k < 4; ++k) out[k + (out.size() - 4)] = first + k;
  };
  index.lower[0] = w.size();
  w.push_back(box_wall("lower bottom", {-t, -t, -t}, {L + t, W + t, 0}, g.platen_friction_deg));
  sides("lower ", -t, zl, g.side_friction_deg, index.lower);
  sides("upper ", zu, g.frame_top_m, g.side_friction_deg, index.upper);
  sides("closer ", zl - 0.5 * t, zu + 0.5 * t, g.side_friction_deg, index.closer);
  index.platen = w.size();
  w.push_back(
      box_wall("platen", {0, 0, g.platen_z_m}, {L, W, g.platen_z_m + t}, g.platen_friction_deg));
  return w;
}

SpecimenGauge shear_box_gauge(const ShearBoxGeometry& g, const ShearBoxWalls& w) {
  return platen_gauge(g.length_m, g.width_m, g.wall_thickness_m, w.platen, 0.0);
}

DirectShear::DirectShear(DirectShearSpec spec, ShearBoxGeometry geometry, ShearBoxWalls walls)
    : MeasuredProgramme({spec.max_displacement_m, spec.frame_every_m}),
      spec_(spec),
      g_(geometry),
      w_(walls) {
  if (!(spec_.normal_stress_Pa > 0)) throw std::invalid_argument("normal stress must be positive");
  if (!(spec_.shear_velocity_m_s > 0))
    throw std::invalid_argument("shear velocity must be positive");
  if (!(spec_.max_displacement_m > 0))
    throw std::invalid_argument("max displacement must be positive");
  if (!(spec_.frame_every_m > 0)) spec_.frame_every_m = spec_.max_displacement_m / 10;
  target_ = {spec_.max_displacement_m, spec_.frame_every_m};
}

double DirectShear::specimen_height(const Simulation& sim) const {
  return sim.walls()[w_.platen].pos.z() - 0.5 * g_.wall_thickness_m;
}

void DirectShear::start(Simulation& sim) {
  reset_rotations(sim);
  for (const auto c : w_.closer) sim.set_wall_active(c, false);
  for (std::size_t w = 0; w < sim.walls().size(); ++w)
    sim.set_wall_velocity(w, Eigen::Vector3d::Zero());
  x0_ = sim.walls()[w_.upper[0]].pos.x();
  h0_ = specimen_height(sim);
}

double DirectShear::normal_stress(const Simulation& sim) const {
  return sim.walls()[w_.platen].force.z() / (g_.length_m * g_.width_m);
}

void DirectShear::control(Simulation& sim) {
  const Eigen::Vector3d v(spec_.shear_velocity_m_s, 0, 0);
  for (const auto k : w_.upper) sim.set_wall_velocity(k, v);
  const double area = g_.length_m * g_.width_m;
  const double vz = servo_speed(sim, w_.platen, normal_stress(sim), spec_.normal_stress_Pa, area,
                                spec_.servo_gain, spec_.max_platen_speed_m_s);
  sim.set_wall_velocity(w_.platen, v + Eigen::Vector3d(0, 0, -vz));
}

double DirectShear::displacement(const Simulation& sim) const {
  return sim.walls()[w_.upper[0]].pos.x() - x0_;
}

double DirectShear::shear_stress(const Simulation& sim) const {
  double fx = sim.walls()[w_.platen].force.x();
  for (const auto k : w_.upper) fx += sim.walls()[k].force.x();
  return -fx / (g_.length_m * g_.width_m);
}

std::string DirectShear::curve_header() const {
  return "step,time_s,u_m,tau_Pa,sigma_n_Pa,tau_over_sigma_n,dh_m,eps_v_dilation,void_ratio,"
         "coordination,particles_outside";
}

std::string DirectShear::curve_row(const Simulation& sim) const {
  const double u = displacement(sim), tau = shear_stress(sim), sn = normal_stress(sim);
  const double h = specimen_height(sim);
  // Particles whose centre left the box (through the gap) are not counted in the void ratio.
  const auto& p = sim.particles();
  double vs = 0;
  std::size_t outside = 0;
  const double L = g_.length_m, W = g_.width_m;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector3d& x = p.pos[i];
    const double shift = x.z() > 0.5 * g_.height_m ? u : 0.0;
    if (x.x() < shift || x.x() > L + shift || x.y() < 0 || x.y() > W || x.z() < 0 || x.z() > h) {
      ++outside;
      continue;
    }
    const double share = !p.clump.empty() && p.clump[i] >= 0 ? spec_.clump_solid_factor : 1.0;
    vs += share * 4.0 / 3.0 * M_PI * std::pow(p.radius[i], 3);
  }
  const double ratio = tau / sn;
  if (ratio > peak_ratio_) peak_ratio_ = ratio;
  char buf[512];
  std::snprintf(buf, sizeof buf, "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%zu",
                static_cast<long long>(sim.step_count()), sim.time(), u, tau, sn, ratio, h - h0_,
                (h - h0_) / h0_, L * W * h / vs - 1, coordination_number(sim), outside);
  return buf;
}

std::string DirectShear::summary(const Simulation& sim) const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "direct shear: u %.4g m, peak tau/sigma_n %.4f (friction angle %.2f deg), "
                "dh %.4g m",
                displacement(sim), peak_ratio_, std::atan(peak_ratio_) * 180 / M_PI,
                specimen_height(sim) - h0_);
  return buf;
}

std::string DirectShear::save_state() const {
  ProgrammeState st;
  st.set("x0", x0_);
  st.set("h0", h0_);
  st.set("peak", peak_ratio_);
  return st.text();
}

void DirectShear::load_state(const std::string& state) {
  const ProgrammeState st(state);
  x0_ = st.number("x0");
  h0_ = st.number("h0");
  peak_ratio_ = st.number("peak");
}

}  // namespace gs::solver
