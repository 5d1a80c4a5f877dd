#include "snapshot.hpp"

#include <algorithm>
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
  const auto& ps = frame.particles;
  return sphere_bounds(
      ps.size(), [&](std::size_t i) -> const Eigen::Vector3d& { return ps[i].position; },
      [&](std::size_t i) { return ps[i].radius; }, [](std::size_t) { return false; });
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

void check_header(const Frame& f, const std::string& source) {
  check_finite(source, "time", f.time);
  check_finite(source, "dt", f.dt);
  if (f.dt < 0) throw InputError(source, "negative dt", value_str(f.dt));
  check_finite(source, "domain lo", f.domain.lo);
  check_finite(source, "domain hi", f.domain.hi);
  check_finite(source, "periodic cell", f.domain.cell);
  check_finite(source, "cell velocity gradient", f.domain.velocity_gradient);
}

/// One particle's fields (not its id's uniqueness). The names of the fields are only built
/// for a particle that fails.
void check_particle(const Particle& p, const std::string& source) {
  if (p.position.allFinite() && std::isfinite(p.radius) && p.radius > 0 && p.velocity.allFinite() &&
      p.angular_velocity.allFinite() && p.orientation.coeffs().allFinite() &&
      p.rotation.allFinite() && std::isfinite(p.mass) && p.mass >= 0)
    return;
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
}

void check_contact(const Contact& c, const std::string& source) {
  if (c.point.allFinite() && c.normal.allFinite() && c.normal_force.allFinite() &&
      c.shear_force.allFinite() && c.bending_moment.allFinite() && c.twisting_moment.allFinite() &&
      std::isfinite(c.overlap) && std::abs(c.normal.norm() - 1.0) <= 1e-6)
    return;
  const std::string cid = "contact " + std::to_string(c.id1) + "-" + std::to_string(c.id2) + " ";
  check_finite(source, cid + "point", c.point);
  check_finite(source, cid + "normal", c.normal);
  check_finite(source, cid + "normal force", c.normal_force);
  check_finite(source, cid + "shear force", c.shear_force);
  check_finite(source, cid + "bending moment", c.bending_moment);
  check_finite(source, cid + "twisting moment", c.twisting_moment);
  check_finite(source, cid + "overlap", c.overlap);
  throw InputError(source, cid + "normal is not a unit vector, |n|", value_str(c.normal.norm()));
}

void check_walls(const Frame& f, const std::string& source) {
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
}

/// Clump bodies (seed 003 §2.4): finite, unit orientation, positive mass, non-negative principal
/// inertia, unique ids. Returns each body's member count, zero so far.
std::unordered_map<std::int64_t, std::size_t> check_clump_bodies(const std::vector<Clump>& clumps,
                                                                 const std::string& source) {
  std::unordered_map<std::int64_t, std::size_t> members;
  members.reserve(clumps.size());
  for (const auto& c : clumps) {
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
  return members;
}

/// When a frame has bodies, every member (clump_id >= 0) names one of them and each of them has
/// a member. (Frames without bodies may still carry clump_id, e.g. imported YADE data: those ids
/// are not checked.)
void count_members(const std::vector<Particle>& particles,
                   std::unordered_map<std::int64_t, std::size_t>& members,
                   const std::string& source) {
  for (const auto& p : particles) {
    if (p.clump_id < 0) continue;
    const auto it = members.find(p.clump_id);
    if (it == members.end())
      throw InputError(source, "particle " + std::to_string(p.id) + " names a missing clump",
                       value_str(p.clump_id));
    ++it->second;
  }
}

void check_members(const std::vector<Clump>& clumps,
                   const std::unordered_map<std::int64_t, std::size_t>& members,
                   const std::string& source) {
  for (const auto& c : clumps)
    if (members.at(c.id) == 0)
      throw InputError(source, "clump has no member particle", value_str(c.id));
}

void check_facet_loads(const Frame& f, const std::string& source) {
  if (f.facet_loads.empty()) return;
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

}  // namespace

void validate_frame(const Frame& f, const std::string& source) {
  check_header(f, source);
  std::unordered_set<std::int64_t> ids;
  ids.reserve(f.particles.size());
  for (const auto& p : f.particles) {
    check_particle(p, source);
    if (!ids.insert(p.id).second)
      throw InputError(source, "duplicate particle id", value_str(p.id));
  }
  for (const auto& c : f.contacts) check_contact(c, source);
  check_walls(f, source);
  if (!f.clumps.empty()) {
    auto members = check_clump_bodies(f.clumps, source);
    count_members(f.particles, members, source);
    check_members(f.clumps, members, source);
  }
  check_facet_loads(f, source);
}

FrameCheck::FrameCheck(const Frame& head, std::string source) : source_(std::move(source)) {
  check_header(head, source_);
  check_walls(head, source_);
  if (!head.clumps.empty()) members_ = check_clump_bodies(head.clumps, source_);
  check_facet_loads(head, source_);
}

void FrameCheck::add(const Frame& piece) {
  ids_.reserve(ids_.size() + piece.particles.size());
  for (const auto& p : piece.particles) {
    check_particle(p, source_);
    ids_.push_back(p.id);
  }
  for (const auto& c : piece.contacts) check_contact(c, source_);
  if (!members_.empty()) count_members(piece.particles, members_, source_);
}

void FrameCheck::finish(const Frame& head) {
  std::sort(ids_.begin(), ids_.end());
  const auto twin = std::adjacent_find(ids_.begin(), ids_.end());
  if (twin != ids_.end()) throw InputError(source_, "duplicate particle id", value_str(*twin));
  std::vector<std::int64_t>().swap(ids_);
  check_members(head.clumps, members_, source_);
}

}  // namespace gs
