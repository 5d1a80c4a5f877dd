// Snapshot model shared by every module: value types, SI units, Eigen at interfaces.
// Data flows solver -> io (these types) -> analysis/dic; analysis never sees solver headers.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace gs {

/// One sphere (or clump member) at one instant. Lengths in m, velocities in m/s, rad/s.
struct Particle {
  std::int64_t id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double radius = 0.0;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();       // rad/s
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body -> lab
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  // cumulative rotation vector, rad
  double mass = 0.0;                                   // kg; 0 = unknown
  std::int64_t clump_id = -1;                          // -1: not in a clump
  std::int32_t material_id = 0;
};

/// One particle–particle or particle–wall contact, in YADE's convention: the normal points from
/// id1 towards id2 and the forces (N) are those exerted BY id1 ON id2 (id1 feels the opposite),
/// so a compressive contact has normal_force·normal > 0. For a wall contact one id is the wall
/// id (walls are numbered after the particles, as YADE numbers bodies).
struct Contact {
  std::int64_t id1 = 0;
  std::int64_t id2 = 0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, from id1 towards id2
  Eigen::Vector3d normal_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d shear_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d bending_moment = Eigen::Vector3d::Zero();   // N·m
  Eigen::Vector3d twisting_moment = Eigen::Vector3d::Zero();  // N·m
  double overlap = 0.0;                                       // m, > 0 when penetrating
};

enum class WallKind : std::int32_t {
  Plane = 0,  // a = point on the plane, b = unit normal (pointing into the granular domain)
  Box = 1,    // a = centre, b = half-extents (axis-aligned)
  Facet = 2,  // one triangle (or flat region) of a mesh wall: a = reference point (the incircle
              // centre of its first triangle), b = unit normal; the triangles are in the scene's
              // mesh file
};

struct Wall {
  std::int64_t id = 0;
  WallKind kind = WallKind::Plane;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   // N, total contact force on the wall
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();  // N·m about wall reference point a
};

/// Simulation domain: axis-aligned box [lo, hi]; optionally a periodic cell whose columns are
/// the cell vectors (origin lo).
struct Domain {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();
  bool periodic = false;
  Eigen::Matrix3d cell = Eigen::Matrix3d::Identity();
  /// Periodic cell: its velocity gradient L (1/s) at this instant, dC/dt = L·C (YADE's
  /// O.cell.velGrad); the particles' velocities include the mean flow L·x. Zero otherwise.
  Eigen::Matrix3d velocity_gradient = Eigen::Matrix3d::Zero();
};

/// A rigid clump body (seed 003 §2.4, seed 004 §4.3) at one instant: its members are the
/// particles with clump_id == id. Centre of mass, orientation of its principal frame (body ->
/// lab, principal axes = columns of its rotation matrix), velocities, mass and principal moments
/// of inertia (kg·m², in the order of the principal axes), and the scene's template name.
struct Clump {
  std::int64_t id = 0;
  std::string template_name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // rad/s
  double mass = 0.0;                                           // kg
  Eigen::Vector3d principal_inertia = Eigen::Vector3d::Zero();
};

/// The force on one triangle of a mesh wall (recorded on request, for wall-stress profiles):
/// the wall's id, the triangle's index within the wall, its incircle centre (m) and the force
/// the particles exert on it (N).
struct FacetLoad {
  std::int64_t wall_id = 0;
  std::int32_t facet = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
};

struct Frame {
  double time = 0.0;  // s
  std::int64_t step = 0;
  double dt = 0.0;  // s
  bool two_d = false;
  Domain domain;
  std::vector<Particle> particles;
  std::vector<Contact> contacts;
  std::vector<Wall> walls;
  std::vector<Clump> clumps;           // empty for a frame of free spheres
  std::vector<FacetLoad> facet_loads;  // empty unless per-facet forces were asked for
};

/// Run-level metadata: free-form key/value scene parameters plus provenance.
struct RunMetadata {
  std::string code_version;  // granoscope version that wrote the file
  std::string provenance;    // what produced the data (solver, importer + source file, ...)
  std::vector<std::pair<std::string, std::string>> parameters;
};

struct Trajectory {
  RunMetadata metadata;
  std::vector<Frame> frames;
};

/// Axis-aligned bounding box of the spheres (centres ± radius).
std::pair<Eigen::Vector3d, Eigen::Vector3d> particle_bounds(const Frame& frame);

/// The same box over spheres 0 … n−1 given by centre(i) and radius(i), leaving out those with
/// skip(i) (zero when none is left): for spheres not held as a Frame (the solver's frame head).
template <class Centre, class Radius, class Skip>
std::pair<Eigen::Vector3d, Eigen::Vector3d> sphere_bounds(std::size_t n, Centre centre,
                                                          Radius radius, Skip skip) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  bool any = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (skip(i)) continue;
    any = true;
    const Eigen::Vector3d& x = centre(i);
    const double r = radius(i);
    lo = lo.cwiseMin((x.array() - r).matrix());
    hi = hi.cwiseMax((x.array() + r).matrix());
  }
  if (!any) lo = hi = Eigen::Vector3d::Zero();
  return {lo, hi};
}

/// Throws InputError naming `source` and the first invalid field: non-finite numbers, radius
/// <= 0, negative mass, non-unit contact and plane-wall normals, duplicate particle ids; for clump
/// bodies a non-unit orientation, mass <= 0, negative principal inertia, duplicate ids, a member
/// naming a missing clump, or a clump without members.
void validate_frame(const Frame& frame, const std::string& source);

/// validate_frame for a frame given in pieces, never held whole: the head (all but its
/// particles and contacts) when constructed, each piece's particles and contacts with add(),
/// then finish(head) (particle ids unique over the pieces, every clump body with a member).
/// The same checks and messages; a duplicate id is reported as the smallest one.
class FrameCheck {
 public:
  FrameCheck(const Frame& head, std::string source);
  void add(const Frame& piece);
  void finish(const Frame& head);

 private:
  std::string source_;
  std::vector<std::int64_t> ids_;
  std::unordered_map<std::int64_t, std::size_t> members_;
};

/// The project version string, e.g. "granoscope 0.1.0".
std::string code_version();

}  // namespace gs
