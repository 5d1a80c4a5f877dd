// Six rigid planes bounding a cuboid specimen (triaxial and plane-strain scenes): their specs,
// the current box between them, and the gauge the servo and the curves use.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "specimen_preparation.hpp"

namespace gs::solver {

/// Order of the six planes in the wall list.
enum CuboidFace : std::size_t { kXmin = 0, kXmax, kYmin, kYmax, kZmin, kZmax };

/// An axis-aligned box wall [lo, hi] and a plane wall through `point` with unit normal `normal`
/// (into the domain), with a friction angle (deg; negative: the material's).
WallSpec box_wall(const std::string& name, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                  double friction_deg);
WallSpec plane_wall(const std::string& name, const Eigen::Vector3d& point,
                    const Eigen::Vector3d& normal, double friction_deg);

/// Planes through the faces of [lo, hi], normals pointing inwards, named x-, x+, y-, y+, z-, z+,
/// with the given wall friction (deg; negative: the material's).
std::vector<WallSpec> cuboid_planes(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                    double friction_deg);

/// The box between the six planes (walls 0..5 of the simulation).
Eigen::Vector3d cuboid_lo(const Simulation& sim);
Eigen::Vector3d cuboid_hi(const Simulation& sim);
/// Inward unit normal of face f.
Eigen::Vector3d cuboid_inward(std::size_t f);
/// Area of face f of the current box.
double cuboid_face_area(const Simulation& sim, std::size_t f);

/// Gauge of a specimen under a servo-controlled box platen (direct and interface shear): the
/// platen (its underside pressing −z over length × width) is the only servo wall; the box is
/// [0, length] × [0, width] from `floor_z` up to the platen's underside.
SpecimenGauge platen_gauge(double length_m, double width_m, double platen_thickness_m,
                           std::size_t platen, double floor_z_m);

/// A scene key's check: throws std::invalid_argument "KEY: WHAT (VALUE)" unless `ok`.
void require_value(bool ok, const std::string& key, double value, const std::string& what);

/// Σ 4/3·π·r³ over all particles.
double solid_volume(const Simulation& sim);

/// Gauge of the cuboid: servo on every face, volume of the box.
SpecimenGauge cuboid_gauge();

}  // namespace gs::solver
