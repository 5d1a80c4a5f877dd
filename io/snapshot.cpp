#include "snapshot.hpp"

#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

#include "errors.hpp"

#ifndef GRANOSCOPE_VERSION
#define GRANOSCOPE_VERSION "0.0.0"
#endif

namespace gs {

std::string code_version() {
  return std::string("granoscope ") + GRANOSCOPE_VERSION;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> particle_bounds(const Frame& frame) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : frame.particles) {
    lo = lo.cwiseMin((p.position.array() - p.radius).matrix());
    hi = hi.cwiseMax((p.position.array() + p.radius).matrix());
  }
  if (frame.particles.empty()) lo = hi = Eigen::Vector3d::Zero();
  return {lo, hi};
}

namespace {

void check_finite(const std::string& source, const std::string& field, double v) {
  if (!std::isfinite(v)) throw InputError(source, field + " is not finite", value_str(v));
}

template <class Derived>
void check_finite(const std::string& source, const std::string& field,
                  const Eigen::MatrixBase<Derived>& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v(i))) throw InputError(source, field + " is not finite", value_str(v(i)));
}

/// Clump bodies (seed 003 §2.4): finite, unit orientation, positive mass, non-negative principal
/// inertia, unique ids; and, when a frame has bodies, every member (clump_id >= 0) names one of
/// them and each of them has a member. (Frames without bodies may still carry clump_id, e.g.
/// imported YADE data: those ids are not checked.)
void validate_clumps(const Frame& f, const std::string& source) {
  if (f.clumps.empty()) return;
  std::unordered_map<std::int64_t, std::size_t> members;
  members.reserve(f.clumps.size());
  for (const auto& c : f.clumps) {
    const std::string cid = "clump " + std::to_string(c.id) + " ";
    check_finite(source, cid + "position", c.position);
    check_finite(source, cid + "orientation", c.orientation.coeffs());
    check_finite(source, cid + "velocity", c.velocity);
    check_finite(source, cid + "angular velocity", c.angular_velocity);
    check_finite(source, cid + "mass", c.mass);
    check_finite(source, cid + "principal inertia", c.principal_inertia);
    if (std::abs(c.orientation.norm() - 1.0) > 1e-6)
      throw InputError(source, cid + "orientation is not a unit quaternion, |q|",
                       value_str(c.orientation.norm()));
    if (!(c.mass > 0)) throw InputError(source, cid + "mass is not positive", value_str(c.mass));
    for (int k = 0; k < 3; ++k)
      if (c.principal_inertia[k] < 0)
        throw InputError(source, cid + "principal inertia is negative",
                         value_str(c.principal_inertia[k]));
    if (!members.emplace(c.id, 0).second)
      throw InputError(source, "duplicate clump id", value_str(c.id));
  }
  for (const auto& p : f.particles) {
    if (p.clump_id < 0) continue;
    const auto it = members.find(p.clump_id);
    if (it == members.end())
      throw InputError(source, "particle " + std::to_string(p.id) + " names a missing clump",
                       value_str(p.clump_id));
    ++it->second;
  }
  for (const auto& c : f.clumps)
    if (members.at(c.id) == 0)
      throw InputError(source, "clump has no member particle", value_str(c.id));
}

}  // namespace

void validate_frame(const Frame& f, const std::string& source) {
  check_finite(source, "time", f.time);
  check_finite(source, "dt", f.dt);
  if (f.dt < 0) throw InputError(source, "negative dt", value_str(f.dt));
  check_finite(source, "domain lo", f.domain.lo);
  check_finite(source, "domain hi", f.domain.hi);
  check_finite(source, "periodic cell", f.domain.cell);
  check_finite(source, "cell velocity gradient", f.domain.velocity_gradient);
  std::unordered_set<std::int64_t> ids;
  ids.reserve(f.particles.size());
  for (const auto& p : f.particles) {
    const std::string pid = "particle " + std::to_string(p.id) + " ";
    check_finite(source, pid + "position", p.position);
    check_finite(source, pid + "radius", p.radius);
    if (!(p.radius > 0))
      throw InputError(source, pid + "radius is not positive", value_str(p.radius));
    check_finite(source, pid + "velocity", p.velocity);
    check_finite(source, pid + "angular velocity", p.angular_velocity);
    check_finite(source, pid + "orientation", p.orientation.coeffs());
    check_finite(source, pid + "rotation", p.rotation);
    check_finite(source, pid + "mass", p.mass);
    if (p.mass < 0) throw InputError(source, pid + "mass is negative", value_str(p.mass));
    if (!ids.insert(p.id).second)
      throw InputError(source, "duplicate particle id", value_str(p.id));
  }
  for (const auto& c : f.contacts) {
    const std::string cid = "contact " + std::to_string(c.id1) + "-" + std::to_string(c.id2) + " ";
    check_finite(source, cid + "point", c.point);
    check_finite(source, cid + "normal", c.normal);
    check_finite(source, cid + "normal force", c.normal_force);
    check_finite(source, cid + "shear force", c.shear_force);
    check_finite(source, cid + "bending moment", c.bending_moment);
    check_finite(source, cid + "twisting moment", c.twisting_moment);
    check_finite(source, cid + "overlap", c.overlap);
    if (std::abs(c.normal.norm() - 1.0) > 1e-6)
      throw InputError(source, cid + "normal is not a unit vector, |n|",
                       value_str(c.normal.norm()));
  }
  for (const auto& w : f.walls) {
    const std::string wid = "wall " + std::to_string(w.id) + " ";
    check_finite(source, wid + "geometry", w.a);
    check_finite(source, wid + "geometry", w.b);
    check_finite(source, wid + "force", w.force);
    check_finite(source, wid + "torque", w.torque);
    if (w.kind != WallKind::Plane && w.kind != WallKind::Box && w.kind != WallKind::Facet)
      throw InputError(source, wid + "unknown kind", value_str(static_cast<int>(w.kind)));
    if ((w.kind == WallKind::Plane || w.kind == WallKind::Facet) &&
        std::abs(w.b.norm() - 1.0) > 1e-6)
      throw InputError(source, wid + "plane normal is not a unit vector, |n|",
                       value_str(w.b.norm()));
  }
  validate_clumps(f, source);
  if (!f.facet_loads.empty()) {
    std::unordered_set<std::int64_t> walls;
    for (const auto& w : f.walls) walls.insert(w.id);
    for (const auto& l : f.facet_loads) {
      check_finite(source, "facet load centroid", l.centroid);
      check_finite(source, "facet load force", l.force);
      if (!walls.count(l.wall_id))
        throw InputError(source, "facet load names a missing wall", value_str(l.wall_id));
      if (l.facet < 0) throw InputError(source, "negative facet index", value_str(l.facet));
    }
  }
}

}  // namespace gs
