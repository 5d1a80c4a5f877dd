// The YADE oedometer reference case (../shared/reference/yade/oedometer, README there) as a
// solver setup, shared by the reference test and the benchmark.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "packing_csv.hpp"
#include "reference_case.hpp"
#include "simulation.hpp"
#include "text_parse.hpp"

namespace gs::test {

/// The shared reference (../shared/reference/yade/oedometer, all 20 states) when the checkout
/// has it beside it, else the copy of its packing, wall forces and first two states in
/// tests/data/yade_oedometer (enough for the test's assertions).
inline std::filesystem::path yade_reference_dir() {
  return reference_case_dir("oedometer");
}

/// Parameters of case.json (material, damping, gravity, dt, walls).
inline solver::SimulationConfig oedometer_config(int threads = 1) {
  solver::SimulationConfig c;
  c.material.young_ec = 3.0e7;
  c.material.stiffness_ratio = 0.3;
  c.material.friction_deg = 18.0;
  c.material.density = 2550.0;
  c.material.rolling_beta = 0.7;
  c.material.rolling_eta = 0.4;
  c.material.rolling_radius = solver::RollingRadius::Min;
  c.damping = 0.08;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.dt = 1.0e-6;
  c.threads = threads;
  return c;
}

inline std::vector<solver::WallSpec> oedometer_walls() {
  const auto box = box_wall;
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  return {box("bottom", {0.0125, 0.0125, -0.002}, {0.025, 0.025, 0.002}, z),
          box("x-", {-0.002, 0.0125, 0.05}, {0.002, 0.025, 0.1}, z),
          box("x+", {0.027, 0.0125, 0.05}, {0.002, 0.025, 0.1}, z),
          box("y-", {0.0125, -0.002, 0.05}, {0.025, 0.002, 0.1}, z),
          box("y+", {0.0125, 0.027, 0.05}, {0.025, 0.002, 0.1}, z),
          box("top", {0.0125, 0.0125, 0.0317046381579962}, {0.025, 0.025, 0.002}, {0, 0, -0.05})};
}

/// Rows of a YADE state file: id -> (x, y, z, vx, vy, vz, wx, wy, wz).
inline std::map<long, std::vector<double>> read_yade_state(const std::filesystem::path& p) {
  const std::string text = text::read_text_file(p);
  std::map<long, std::vector<double>> rows;
  const auto lines = text::split_lines(text);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (text::trim(lines[i]).empty()) continue;
    const auto f = text::split_csv(lines[i]);
    std::vector<double> v;
    for (std::size_t k = 1; k < f.size(); ++k)
      v.push_back(text::to_double(f[k], p.string(), i + 1, "state"));
    rows[static_cast<long>(text::to_int(f[0], p.string(), i + 1, "id"))] = v;
  }
  return rows;
}

}  // namespace gs::test
