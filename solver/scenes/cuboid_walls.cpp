#include "cuboid_walls.hpp"

#include "errors.hpp"

#include <cmath>

namespace gs::solver {

WallSpec box_wall(const std::string& name, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                  double friction_deg) {
  WallSpec w;
  w.name = name;
  w.shape = WallShape::Box;
  w.center = 0.5 * (lo + hi);
  w.half_extents = 0.5 * (hi - lo);
  w.friction_deg = friction_deg;
  return w;
}

WallSpec plane_wall(const std::string& name, const Eigen::Vector3d& point,
                    const Eigen::Vector3d& normal, double friction_deg) {
  WallSpec w;
  w.name = name;
  w.shape = WallShape::Plane;
  w.center = point;
  w.normal = normal;
  w.friction_deg = friction_deg;
  return w;
}

std::vector<WallSpec> cuboid_planes(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                    double friction_deg) {
  static const char* names[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  std::vector<WallSpec> walls;
  for (std::size_t f = 0; f < 6; ++f) {
    const int axis = static_cast<int>(f / 2);
    Eigen::Vector3d point = 0.5 * (lo + hi);
    point[axis] = (f % 2 == 0) ? lo[axis] : hi[axis];
    walls.push_back(plane_wall(names[f], point, cuboid_inward(f), friction_deg));
  }
  return walls;
}

Eigen::Vector3d cuboid_inward(std::size_t f) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[static_cast<int>(f / 2)] = (f % 2 == 0) ? 1.0 : -1.0;
  return n;
}

Eigen::Vector3d cuboid_lo(const Simulation& sim) {
  const auto& w = sim.walls();
  return {w[kXmin].pos.x(), w[kYmin].pos.y(), w[kZmin].pos.z()};
}

Eigen::Vector3d cuboid_hi(const Simulation& sim) {
  const auto& w = sim.walls();
  return {w[kXmax].pos.x(), w[kYmax].pos.y(), w[kZmax].pos.z()};
}

double cuboid_face_area(const Simulation& sim, std::size_t f) {
  const Eigen::Vector3d size = cuboid_hi(sim) - cuboid_lo(sim);
  const int axis = static_cast<int>(f / 2);
  return size[(axis + 1) % 3] * size[(axis + 2) % 3];
}

double solid_volume(const Simulation& sim) {
  double v = 0;
  for (const double r : sim.particles().radius) v += 4.0 / 3.0 * M_PI * r * r * r;
  return v;
}

SpecimenGauge cuboid_gauge() {
  SpecimenGauge g;
  g.box = [](const Simulation& sim) { return std::make_pair(cuboid_lo(sim), cuboid_hi(sim)); };
  g.servo_walls = {kXmin, kXmax, kYmin, kYmax, kZmin, kZmax};
  g.inward = [](const Simulation&, std::size_t w) { return cuboid_inward(w); };
  g.area_m2 = [](const Simulation& sim, std::size_t w) { return cuboid_face_area(sim, w); };
  return g;
}

SpecimenGauge platen_gauge(double length_m, double width_m, double platen_thickness_m,
                           std::size_t platen, double floor_z_m) {
  SpecimenGauge gauge;
  gauge.servo_walls = {platen};
  const double area = length_m * width_m, t = platen_thickness_m;
  gauge.inward = [](const Simulation&, std::size_t) { return Eigen::Vector3d(0, 0, -1); };
  gauge.area_m2 = [area](const Simulation&, std::size_t) { return area; };
  const Eigen::Vector3d lo(0, 0, floor_z_m);
  const Eigen::Vector2d footprint(length_m, width_m);
  gauge.box = [lo, footprint, t, platen](const Simulation& sim) {
    return std::make_pair(
        lo, Eigen::Vector3d(footprint.x(), footprint.y(), sim.walls()[platen].pos.z() - 0.5 * t));
  };
  return gauge;
}

void require_value(bool ok, const std::string& key, double value, const std::string& what) {
  if (!ok) throw std::invalid_argument(key + ": " + what + " (" + value_str(value) + ")");
}

}  // namespace gs::solver
