#include "plane_strain_compression.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "cuboid_walls.hpp"
#include "specimen_preparation.hpp"
#include "triaxial_compression.hpp"

namespace gs::solver {

namespace {
constexpr std::size_t kClamp = 6;  // first clamp wall: x− bottom, x+ bottom, x− top, x+ top
}

std::vector<WallSpec> membrane_clamps() {
  std::vector<WallSpec> w(4);
  const char* names[4] = {"clamp x- bottom", "clamp x+ bottom", "clamp x- top", "clamp x+ top"};
  for (int k = 0; k < 4; ++k) {
    w[static_cast<std::size_t>(k)].name = names[k];
    w[static_cast<std::size_t>(k)].shape = WallShape::Box;
    w[static_cast<std::size_t>(k)].half_extents = Eigen::Vector3d::Constant(1e-3);
    w[static_cast<std::size_t>(k)].friction_deg = 0;
    w[static_cast<std::size_t>(k)].active = false;
  }
  return w;
}

PlaneStrainCompression::PlaneStrainCompression(PlaneStrainSpec spec)
    : MeasuredProgramme({spec.max_strain, spec.frame_every_strain}),
      spec_(spec),
      inertial_warning_{spec.inertial_warning} {
  if (!(spec_.confining_Pa > 0)) throw std::invalid_argument("confining pressure must be positive");
  if (!(spec_.strain_rate_1_s > 0)) throw std::invalid_argument("strain rate must be positive");
  if (!(spec_.max_strain > 0 && spec_.max_strain < 1))
    throw std::invalid_argument("max strain must be in (0, 1)");
  if (spec_.refresh_steps < 1) throw std::invalid_argument("refresh_steps must be >= 1");
}

MembraneLoads PlaneStrainCompression::membrane(const Simulation& sim) const {
  const Eigen::Vector3d lo = cuboid_lo(sim), hi = cuboid_hi(sim);
  MembraneSpec m;
  m.pressure_Pa = spec_.confining_Pa;
  m.bin_m = spec_.membrane_bin_m > 0 ? spec_.membrane_bin_m : 0.5 * d50_;
  m.normal_stencil_m = spec_.membrane_stencil_m > 0 ? spec_.membrane_stencil_m : d50_;
  // (under a domain decomposition every process finds the membranes from every particle's
  // present position, as one process does)
  return membrane_loads(sim.present_positions(), sim.particles().radius, lo.y(), hi.y(),
                        lo.z() + clamp_, hi.z() - clamp_, m);
}

void PlaneStrainCompression::refresh(Simulation& sim) {
  const MembraneLoads m = membrane(sim);
  auto& ext = sim.particles().external_force;
  std::fill(ext.begin(), ext.end(), Eigen::Vector3d::Zero());
  for (std::size_t k = 0; k < m.particle.size(); ++k) ext[m.particle[k]] = m.force[k];
}

void PlaneStrainCompression::start(Simulation& sim) {
  reset_rotations(sim);
  d50_ = spec_.d50_m > 0 ? spec_.d50_m : mean_diameter(sim.particles());
  for (std::size_t f = 0; f < 6; ++f) sim.set_wall_velocity(f, Eigen::Vector3d::Zero());
  // Clamps where the x walls meet the caps; then the x walls give way to the membranes.
  const Eigen::Vector3d lo = cuboid_lo(sim), hi = cuboid_hi(sim);
  clamp_ = spec_.clamp_height_m > 0 ? spec_.clamp_height_m : d50_;
  b0_ = hi.x() - lo.x();
  const double t = d50_;  // clamp thickness (outside the specimen)
  const Eigen::Vector3d half(0.5 * t, 0.5 * (hi.y() - lo.y()) + t, 0.5 * clamp_);
  for (int k = 0; k < 4; ++k) {
    WallState& w = sim.mutable_walls().at(kClamp + static_cast<std::size_t>(k));
    const double x = (k % 2 == 0) ? lo.x() - 0.5 * t : hi.x() + 0.5 * t;
    const double z = (k < 2) ? lo.z() + 0.5 * clamp_ : hi.z() - 0.5 * clamp_;
    w.spec.half_extents = half;
    w.pos = Eigen::Vector3d(x, 0.5 * (lo.y() + hi.y()), z);
    sim.set_wall_active(kClamp + static_cast<std::size_t>(k), true);
  }
  sim.set_wall_active(kXmin, false);
  sim.set_wall_active(kXmax, false);
  h0_ = hi.z() - lo.z();
  v0_ = volume(sim);
  top_x0_ = sim.walls()[kClamp + 2].pos.x();
  start_step_ = sim.step_count();
}

double PlaneStrainCompression::volume(const Simulation& sim) const {
  const double depth = cuboid_hi(sim).y() - cuboid_lo(sim).y();
  return membrane(sim).volume_m3 + 2 * clamp_ * b0_ * depth;
}

double PlaneStrainCompression::top_shift(const Simulation& sim) const {
  return sim.walls()[kClamp + 2].pos.x() - top_x0_;
}

void PlaneStrainCompression::control(Simulation& sim) {
  const double axial_speed = spec_.strain_rate_1_s * h0_;
  const Eigen::Vector3d v = axial_speed * cuboid_inward(kZmax);
  sim.set_wall_velocity(kZmax, v);  // frictionless: its own lateral motion changes nothing
  Eigen::Vector3d vc = v;           // the top clamps move with the top cap, and on the sledge
  if (spec_.top_sledge) {
    // Lateral force of the grains on the sledge (cap frictionless: the clamps take it all).
    double fx = 0, k = 0;
    for (const std::size_t w : {kClamp + 2, kClamp + 3}) {
      fx += sim.walls()[w].force.x();
      k += sim.wall_stiffness(w).first;
    }
    if (k > 0)
      vc.x() = std::clamp(spec_.sledge_gain * fx / k / sim.config().dt, -axial_speed, axial_speed);
  }
  sim.set_wall_velocity(kClamp + 2, vc);
  sim.set_wall_velocity(kClamp + 3, vc);
  if ((sim.step_count() - start_step_) % spec_.refresh_steps == 0) refresh(sim);
}

double PlaneStrainCompression::axial_strain(const Simulation& sim) const {
  return (h0_ - (cuboid_hi(sim).z() - cuboid_lo(sim).z())) / h0_;
}

std::string PlaneStrainCompression::curve_header() const {
  return "step,time_s,eps1_shortening,eps_v_dilation,sigma1_Pa,sigma2_Pa,sigma3_Pa,p_Pa,q_Pa,"
         "sin_phi,phi_deg,void_ratio,core_void_ratio,width_m,coordination,inertial_number,"
         "unbalanced_force,"
         "membrane_particles,top_shift_m";
}

std::string PlaneStrainCompression::curve_row(const Simulation& sim) const {
  const MembraneLoads m = membrane(sim);
  const Eigen::Vector3d lo = cuboid_lo(sim), hi = cuboid_hi(sim);
  const double depth = hi.y() - lo.y(), h = hi.z() - lo.z();
  const double width = m.mean_width_m;
  const double vol = m.volume_m3 + 2 * clamp_ * b0_ * depth;
  auto stress = [&](std::size_t f, double area) {
    return wall_stress(sim, f, cuboid_inward(f), area);
  };
  const double s1 = 0.5 * (stress(kZmin, width * depth) + stress(kZmax, width * depth));
  const double s2 = 0.5 * (stress(kYmin, width * h) + stress(kYmax, width * h));
  const double s3 = spec_.confining_Pa;
  const double p = (s1 + s2 + s3) / 3;
  // q = sqrt(((σ1−σ2)² + (σ2−σ3)² + (σ3−σ1)²)/2) (von Mises, seed 003 eq 17).
  const double q =
      std::sqrt(0.5 * ((s1 - s2) * (s1 - s2) + (s2 - s3) * (s2 - s3) + (s3 - s1) * (s3 - s1)));
  const double phi = mobilised_friction_deg(s1, s3);
  if (phi > max_phi_deg_) max_phi_deg_ = phi;
  const double inertial =
      p > 0 ? spec_.strain_rate_1_s * d50_ / std::sqrt(p / sim.config().material.density)
            : std::numeric_limits<double>::quiet_NaN();
  inertial_warning_.check(inertial, "plane_strain", axial_strain(sim));
  // Core: between the mean membrane positions and the caps / plane-strain walls, inset.
  double xm = 0, xp = 0;
  std::size_t hits = 0;
  for (std::size_t b = 0; b < m.x_minus.size(); ++b) {
    if (!std::isfinite(m.x_minus[b])) continue;
    xm += m.x_minus[b];
    xp += m.x_plus[b];
    ++hits;
  }
  const double in = spec_.core_inset_m;
  const Eigen::Vector3d clo(xm / std::max<std::size_t>(1, hits) + in, lo.y() + in, lo.z() + in);
  const Eigen::Vector3d chi(xp / std::max<std::size_t>(1, hits) - in, hi.y() - in, hi.z() - in);
  const double e_core = box_void_ratio(sim.particles(), clo, chi, spec_.clump_solid_factor);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,"
                "%.6g,%zu,%.9g",
                static_cast<long long>(sim.step_count()), sim.time(), axial_strain(sim),
                (vol - v0_) / v0_, s1, s2, s3, p, q, (s1 - s3) / (s1 + s3), phi,
                vol / solid_volume(sim) - 1, e_core, width, coordination_number(sim), inertial,
                sim.unbalanced_force(), m.particle.size(), top_shift(sim));
  return buf;
}

std::string PlaneStrainCompression::summary(const Simulation& sim) const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "plane strain: eps1 %.4f, peak mobilised friction angle %.2f deg",
                axial_strain(sim), max_phi_deg_);
  return buf;
}

std::string PlaneStrainCompression::save_state() const {
  ProgrammeState st;
  st.set("h0", h0_);
  st.set("v0", v0_);
  st.set("d50", d50_);
  st.set("start_step", start_step_);
  st.set("clamp", clamp_);
  st.set("b0", b0_);
  st.set("top_x0", top_x0_);
  st.set("max_phi", max_phi_deg_);
  st.set("warned", static_cast<std::int64_t>(inertial_warning_.warned));
  return st.text();
}

void PlaneStrainCompression::load_state(const std::string& state) {
  const ProgrammeState st(state);
  h0_ = st.number("h0");
  v0_ = st.number("v0");
  d50_ = st.number("d50");
  start_step_ = st.integer("start_step");
  clamp_ = st.number("clamp");
  b0_ = st.number("b0");
  top_x0_ = st.number("top_x0");
  max_phi_deg_ = st.number("max_phi");
  inertial_warning_.warned = st.integer("warned") != 0;
}

}  // namespace gs::solver
