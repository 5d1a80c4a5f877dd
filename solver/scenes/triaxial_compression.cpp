#include "triaxial_compression.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "cuboid_walls.hpp"
#include "specimen_preparation.hpp"

namespace gs::solver {

double mobilised_friction_deg(double sigma1, double sigma3) {
  const double s = (sigma1 - sigma3) / (sigma1 + sigma3);
  return std::asin(std::clamp(s, -1.0, 1.0)) * 180.0 / M_PI;
}

TriaxialCompression::TriaxialCompression(TriaxialSpec spec)
    : MeasuredProgramme({spec.max_strain, spec.frame_every_strain}),
      spec_(spec),
      inertial_warning_{spec.inertial_warning} {
  if (!(spec_.confining_Pa > 0)) throw std::invalid_argument("confining pressure must be positive");
  if (!(spec_.strain_rate_1_s > 0)) throw std::invalid_argument("strain rate must be positive");
  if (!(spec_.max_strain > 0 && spec_.max_strain < 1))
    throw std::invalid_argument("max strain must be in (0, 1)");
}

void TriaxialCompression::start(Simulation& sim) {
  reset_rotations(sim);
  const Eigen::Vector3d lo = cuboid_lo(sim), hi = cuboid_hi(sim);
  size0_ = hi - lo;
  h0_ = size0_.z();
  v0_ = size0_.prod();
  d50_ = spec_.d50_m > 0 ? spec_.d50_m : mean_diameter(sim.particles());
  for (std::size_t f = 0; f < 6; ++f) sim.set_wall_velocity(f, Eigen::Vector3d::Zero());
}

void TriaxialCompression::control(Simulation& sim) {
  const double v = 0.5 * spec_.strain_rate_1_s * h0_;
  sim.set_wall_velocity(kZmin, v * cuboid_inward(kZmin));
  sim.set_wall_velocity(kZmax, v * cuboid_inward(kZmax));
  for (const std::size_t f : {kXmin, kXmax, kYmin, kYmax}) {
    const Eigen::Vector3d in = cuboid_inward(f);
    const double a = cuboid_face_area(sim, f);
    const double speed = servo_speed(sim, f, wall_stress(sim, f, in, a), spec_.confining_Pa, a,
                                     spec_.servo_gain, spec_.max_wall_speed_m_s);
    sim.set_wall_velocity(f, speed * in);
  }
}

double TriaxialCompression::axial_strain(const Simulation& sim) const {
  return (h0_ - (cuboid_hi(sim).z() - cuboid_lo(sim).z())) / h0_;
}

double TriaxialCompression::volumetric_strain(const Simulation& sim) const {
  return ((cuboid_hi(sim) - cuboid_lo(sim)).prod() - v0_) / v0_;
}

Eigen::Vector3d TriaxialCompression::wall_stresses(const Simulation& sim) const {
  auto mean = [&](std::size_t a, std::size_t b) {
    return 0.5 * (wall_stress(sim, a, cuboid_inward(a), cuboid_face_area(sim, a)) +
                  wall_stress(sim, b, cuboid_inward(b), cuboid_face_area(sim, b)));
  };
  return {mean(kZmin, kZmax), mean(kYmin, kYmax), mean(kXmin, kXmax)};
}

double TriaxialCompression::inertial_number(const Simulation& sim) const {
  const Eigen::Vector3d s = wall_stresses(sim);
  const double p = s.mean();
  if (!(p > 0)) return std::numeric_limits<double>::quiet_NaN();
  return spec_.strain_rate_1_s * d50_ / std::sqrt(p / sim.config().material.density);
}

std::string TriaxialCompression::curve_header() const {
  return "step,time_s,eps1_shortening,eps2_shortening,eps3_shortening,eps_v_dilation,"
         "sigma1_Pa,sigma2_Pa,sigma3_Pa,p_Pa,q_Pa,sin_phi,phi_deg,void_ratio,core_void_ratio,"
         "coordination,"
         "inertial_number,unbalanced_force";
}

std::string TriaxialCompression::curve_row(const Simulation& sim) const {
  const Eigen::Vector3d lo = cuboid_lo(sim), hi = cuboid_hi(sim);
  const Eigen::Vector3d s = wall_stresses(sim);
  const double e1 = axial_strain(sim);
  const Eigen::Vector3d size = hi - lo;
  const double p = s.mean();
  const double q = s[0] - 0.5 * (s[1] + s[2]);
  const double sin_phi = (s[0] - s[2]) / (s[0] + s[2]);
  const double phi = mobilised_friction_deg(s[0], s[2]);
  const double inertial = inertial_number(sim);
  if (phi > max_phi_deg_) max_phi_deg_ = phi;
  inertial_warning_.check(inertial, "triaxial", e1);
  const double e = box_void_ratio(sim.particles(), lo, hi, spec_.clump_solid_factor);
  const Eigen::Vector3d inset = Eigen::Vector3d::Constant(spec_.core_inset_m);
  const double e_core =
      box_void_ratio(sim.particles(), lo + inset, hi - inset, spec_.clump_solid_factor);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,"
                "%.6g,%.6g",
                static_cast<long long>(sim.step_count()), sim.time(), e1,
                (size0_.y() - size.y()) / size0_.y(), (size0_.x() - size.x()) / size0_.x(),
                volumetric_strain(sim), s[0], s[1], s[2], p, q, sin_phi, phi, e, e_core,
                coordination_number(sim), inertial, sim.unbalanced_force());
  return buf;
}

std::string TriaxialCompression::summary(const Simulation& sim) const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "triaxial: eps1 %.4f, eps_v %.4f (dilation positive), peak mobilised friction "
                "angle %.2f deg",
                axial_strain(sim), volumetric_strain(sim), max_phi_deg_);
  return buf;
}

std::string TriaxialCompression::save_state() const {
  ProgrammeState st;
  st.set("h0", h0_);
  st.set("v0", v0_);
  st.set("d50", d50_);
  st.set("sx", size0_.x());
  st.set("sy", size0_.y());
  st.set("sz", size0_.z());
  st.set("max_phi", max_phi_deg_);
  st.set("warned", static_cast<std::int64_t>(inertial_warning_.warned));
  return st.text();
}

void TriaxialCompression::load_state(const std::string& state) {
  const ProgrammeState st(state);
  h0_ = st.number("h0");
  v0_ = st.number("v0");
  d50_ = st.number("d50");
  size0_ = {st.number("sx"), st.number("sy"), st.number("sz")};
  max_phi_deg_ = st.number("max_phi");
  inertial_warning_.warned = st.integer("warned") != 0;
}

}  // namespace gs::solver
