#include "loading_programme.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace gs::solver {

ProgrammeState::ProgrammeState(const std::string& text) {
  std::istringstream in(text);
  std::string key, value;
  while (in >> key >> value) values_[key] = value;
}

void ProgrammeState::set(const std::string& key, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  values_[key] = buf;
}

void ProgrammeState::set(const std::string& key, std::int64_t v) {
  values_[key] = std::to_string(v);
}

double ProgrammeState::number(const std::string& key) const {
  const auto it = values_.find(key);
  if (it == values_.end()) throw std::invalid_argument("programme state lacks " + key);
  return std::strtod(it->second.c_str(), nullptr);
}

std::int64_t ProgrammeState::integer(const std::string& key) const {
  const auto it = values_.find(key);
  if (it == values_.end()) throw std::invalid_argument("programme state lacks " + key);
  return std::stoll(it->second);
}

std::string ProgrammeState::text() const {
  std::string s;
  for (const auto& [k, v] : values_) s += k + " " + v + "\n";
  return s;
}

double wall_stress(const Simulation& sim, std::size_t w, const Eigen::Vector3d& inward,
                   double area_m2) {
  return -sim.walls()[w].force.dot(inward) / area_m2;
}

double servo_speed(const Simulation& sim, std::size_t w, double stress_Pa, double target_Pa,
                   double area_m2, double gain, double max_speed) {
  const auto [k, count] = sim.wall_stiffness(w);
  const double error = target_Pa - stress_Pa;
  if (count == 0 || !(k > 0)) return error > 0 ? max_speed : -max_speed;
  const double dt = sim.config().dt;
  return std::clamp(gain * error * area_m2 / k / dt, -max_speed, max_speed);
}

void reset_rotations(Simulation& sim) {
  auto& rot = sim.particles().rot;
  std::fill(rot.begin(), rot.end(), Eigen::Vector3d::Zero());
}

double mean_diameter(const ParticleState& p) {
  double d = 0;
  for (const double r : p.radius) d += 2 * r;
  return p.size() == 0 ? 0.0 : d / static_cast<double>(p.size());
}

double MeasureTarget::progress(double v) const {
  return std::clamp(v / max, 0.0, 1.0);
}

std::int64_t MeasureTarget::frame_index(double v) const {
  return static_cast<std::int64_t>(std::floor(v / every));
}

void InertialWarning::check(double inertial, const std::string& test, double strain) {
  if (warned || !(inertial > threshold)) return;
  warned = true;
  std::cerr << "warning: " << test << ": inertial number " << inertial << " exceeds " << threshold
            << " at strain " << strain << " (not quasi-static; lower the loading rate)\n";
}

double coordination_number(const Simulation& sim) {
  const std::size_t n = sim.particles().size();
  return n == 0 ? 0.0
                : 2.0 * static_cast<double>(sim.sphere_contact_count()) / static_cast<double>(n);
}

double cell_void_ratio(const Simulation& sim) {
  const auto& p = sim.particles();
  const Eigen::Matrix3d& h = sim.cell().hsize;
  const bool plane = sim.planar();
  double solid = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.removed[i] != 0) continue;
    const double r = p.radius[i];
    solid += plane ? M_PI * r * r : 4.0 / 3.0 * M_PI * r * r * r;
  }
  const double v = plane ? h.topLeftCorner<2, 2>().determinant() : h.determinant();
  return solid > 0 ? v / solid - 1 : std::numeric_limits<double>::quiet_NaN();
}

double elastic_energy(Simulation& sim) {
  const auto& e = sim.energy();
  return e.elastic_normal + e.elastic_shear + e.elastic_rolling;
}

}  // namespace gs::solver
