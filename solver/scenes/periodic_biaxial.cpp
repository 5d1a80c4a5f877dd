#include "periodic_biaxial.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace gs::solver {

PeriodicBiaxial::PeriodicBiaxial(PeriodicBiaxialSpec spec)
    : spec_(std::move(spec)), inertial_warning_{spec_.inertial_warning} {
  if (!(spec_.lateral_stress_Pa > 0))
    throw std::invalid_argument("lateral stress must be positive");
  if (!(spec_.strain_rate_1_s > 0)) throw std::invalid_argument("strain rate must be positive");
  if (!(spec_.max_strain > 0 && spec_.max_strain < 1))
    throw std::invalid_argument("max strain must be in (0, 1)");
  if (!(spec_.servo_fraction > 0 && spec_.servo_fraction <= 1))
    throw std::invalid_argument("servo fraction must be in (0, 1]");
  std::sort(spec_.frame_strains.begin(), spec_.frame_strains.end());
}

void PeriodicBiaxial::start(Simulation& sim) {
  if (!sim.periodic() || !sim.planar())
    throw std::invalid_argument("the periodic biaxial test needs a planar periodic cell");
  reset_rotations(sim);
  const Eigen::Matrix3d& h = sim.cell().hsize;
  w0_ = h(0, 0);
  h0_ = h(1, 1);
  a0_ = h.topLeftCorner<2, 2>().determinant();
  d50_ = spec_.d50_m > 0 ? spec_.d50_m : mean_diameter(sim.particles());
  CellServo sv;
  sv.stress = {true, false, false};
  // L22 = ḣ/h = −ε̇: a constant true strain rate (h = h0·e^(−ε̇t); the engineering ε22 of the
  // curve lags ε̇t by under 1.5 % of itself up to ε22 = 3 %; docs/scenes.md).
  sv.target = {-spec_.lateral_stress_Pa, -spec_.strain_rate_1_s, 0.0};
  sv.stiffness_fraction = spec_.servo_fraction;
  sv.max_rate = spec_.max_rate_1_s > 0 ? spec_.max_rate_1_s : 10 * spec_.strain_rate_1_s;
  sim.set_cell_servo(sv);
}

double PeriodicBiaxial::axial_strain(const Simulation& sim) const {
  return (h0_ - sim.cell().hsize(1, 1)) / h0_;
}

double PeriodicBiaxial::lateral_strain(const Simulation& sim) const {
  return (w0_ - sim.cell().hsize(0, 0)) / w0_;
}

bool PeriodicBiaxial::finished(const Simulation& sim) const {
  return axial_strain(sim) >= spec_.max_strain;
}

double PeriodicBiaxial::progress(const Simulation& sim) const {
  return std::clamp(axial_strain(sim) / spec_.max_strain, 0.0, 1.0);
}

std::int64_t PeriodicBiaxial::frame_index(const Simulation& sim) const {
  const double e = axial_strain(sim);
  const auto listed = std::upper_bound(spec_.frame_strains.begin(), spec_.frame_strains.end(), e) -
                      spec_.frame_strains.begin();
  const auto regular = spec_.frame_every_strain > 0
                           ? static_cast<std::int64_t>(std::floor(e / spec_.frame_every_strain))
                           : 0;
  return static_cast<std::int64_t>(listed) + std::max<std::int64_t>(regular, 0);
}

Eigen::Vector3d PeriodicBiaxial::stresses(const Simulation& sim) const {
  const Eigen::Matrix3d s = sim.cell_stress();
  return {-s(0, 0), -s(1, 1), -0.5 * (s(0, 1) + s(1, 0))};
}

std::string PeriodicBiaxial::curve_header() const {
  return "step,time_s,eps22_shortening,eps11_shortening,eps_v_dilation,sigma11_Pa,sigma22_Pa,"
         "sigma12_Pa,p_Pa,q_Pa,sigma22_over_sigma11,sin_phi,phi_deg,void_ratio,coordination,"
         "inertial_number,unbalanced_force";
}

std::string PeriodicBiaxial::curve_row(const Simulation& sim) const {
  const Eigen::Vector3d s = stresses(sim);
  const double e22 = axial_strain(sim), e11 = lateral_strain(sim);
  const double area = sim.cell().hsize.topLeftCorner<2, 2>().determinant();
  const double p = 0.5 * (s[0] + s[1]), q = 0.5 * (s[1] - s[0]);
  const double ratio = s[1] / s[0];
  const double sin_phi = p > 0 ? q / p : std::numeric_limits<double>::quiet_NaN();
  const double phi = std::asin(std::clamp(sin_phi, -1.0, 1.0)) * 180.0 / M_PI;
  const double inertial =
      p > 0 ? spec_.strain_rate_1_s * d50_ / std::sqrt(p / sim.config().material.density)
            : std::numeric_limits<double>::quiet_NaN();
  if (ratio > peak_ratio_) {
    peak_ratio_ = ratio;
    peak_strain_ = e22;
  }
  inertial_warning_.check(inertial, "biaxial_periodic", e22);
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,"
                "%.6g",
                static_cast<long long>(sim.step_count()), sim.time(), e22, e11, (area - a0_) / a0_,
                s[0], s[1], s[2], p, q, ratio, sin_phi, phi, cell_void_ratio(sim),
                coordination_number(sim), inertial, sim.unbalanced_force());
  return buf;
}

std::string PeriodicBiaxial::summary(const Simulation& sim) const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "biaxial_periodic: eps22 %.4f, void ratio %.4f, peak sigma22/sigma11 %.3f at eps22 "
                "%.4f (from the curve rows)",
                axial_strain(sim), cell_void_ratio(sim), peak_ratio_, peak_strain_);
  return buf;
}

std::string PeriodicBiaxial::save_state() const {
  ProgrammeState st;
  st.set("h0", h0_);
  st.set("w0", w0_);
  st.set("a0", a0_);
  st.set("d50", d50_);
  st.set("peak_ratio", peak_ratio_);
  st.set("peak_strain", peak_strain_);
  st.set("warned", static_cast<std::int64_t>(inertial_warning_.warned));
  return st.text();
}

void PeriodicBiaxial::load_state(const std::string& state) {
  const ProgrammeState st(state);
  h0_ = st.number("h0");
  w0_ = st.number("w0");
  a0_ = st.number("a0");
  d50_ = st.number("d50");
  peak_ratio_ = st.number("peak_ratio");
  peak_strain_ = st.number("peak_strain");
  inertial_warning_.warned = st.integer("warned") != 0;
}

}  // namespace gs::solver
