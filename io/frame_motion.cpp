#include "frame_motion.hpp"

#include <algorithm>
#include <limits>

#include <filesystem>
#include <unordered_map>

#include "errors.hpp"
#include "hdf5_trajectory.hpp"
#include "trajectory_io.hpp"

namespace gs {
namespace {

void check_index(const std::string& path, long i, std::size_t n, const char* what) {
  if (i < 0 || i >= static_cast<long>(n)) {
    throw InputError(path, std::string(what) + " out of range 0.." + std::to_string(long(n) - 1),
                     std::to_string(i));
  }
}

}  // namespace

std::size_t frame_count(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path, "no such file");
  if (is_hdf5_file(path)) return TrajectoryReader(path).frame_count();
  return read_snapshots(path).frames.size();
}

Frame read_frame(const std::string& path, long i) {
  if (!std::filesystem::exists(path)) throw InputError(path, "no such file");
  if (is_hdf5_file(path)) {
    const TrajectoryReader reader(path);
    check_index(path, i, reader.frame_count(), "frame");
    return reader.frame(static_cast<std::size_t>(i));
  }
  Trajectory t = read_snapshots(path);
  check_index(path, i, t.frames.size(), "frame");
  return std::move(t.frames[static_cast<std::size_t>(i)]);
}

FrameMotion motion_between(const Frame& from, const Frame& to, const std::string& source) {
  FrameMotion m;
  m.frame = from;
  m.kind = "displacement";
  std::unordered_map<std::int64_t, std::size_t> by_id;
  for (std::size_t i = 0; i < to.particles.size(); ++i) by_id.emplace(to.particles[i].id, i);
  // A particle that left the cell was wrapped back by the cell of the target frame (which may
  // have deformed since `from`): its image shift is a whole multiple of that cell.
  const bool periodic = from.domain.periodic || to.domain.periodic;
  const Eigen::Matrix3d cell = to.domain.periodic ? to.domain.cell : from.domain.cell;
  const Eigen::Matrix3d inv = periodic ? Eigen::Matrix3d(cell.inverse()) : Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < from.particles.size(); ++i) {
    const auto it = by_id.find(from.particles[i].id);
    if (it == by_id.end()) continue;  // particle gone: not matched
    Eigen::Vector3d d = to.particles[it->second].position - from.particles[i].position;
    if (periodic) {  // wrapped across the cell: minimum image
      Eigen::Vector3d f = inv * d;
      if (from.two_d) f.z() = 0.0;
      d -= cell * f.array().round().matrix();
    }
    m.index.push_back(static_cast<std::int32_t>(i));
    m.x.push_back(from.particles[i].position);
    m.u.push_back(d);
  }
  if (m.index.empty()) throw InputError(source, "no particle id common to both frames");
  return m;
}

namespace {

// The geometry of the analyses (cell volumes ~ extent^3, Delaunay predicates, quality measures)
// over- or underflows outside these lengths, and cells then keep zero gradients without a word
// (coordinates scaled by 1e150 or 1e-300). Metres: a granular specimen lies well inside.
constexpr double kMinExtent = 1e-90, kMaxExtent = 1e90;

FrameMotion checked(FrameMotion m, const std::string& path) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  double umax = 0;
  for (std::size_t i = 0; i < m.x.size(); ++i) {
    lo = lo.cwiseMin(m.x[i]);
    hi = hi.cwiseMax(m.x[i]);
    umax = std::max(umax, m.u[i].cwiseAbs().maxCoeff());
  }
  if (m.x.size() < 2) return m;
  const double extent = (hi - lo).maxCoeff();  // (a norm would underflow at 1e-300)
  if (!(extent >= kMinExtent && extent <= kMaxExtent))
    throw InputError(path, "particle positions span a length the geometry cannot handle",
                     value_str(extent) + " m; 1e-90 to 1e90");
  if (!(umax <= kMaxExtent))
    throw InputError(path, std::string("particle ") + m.kind + " too large for the geometry",
                     value_str(umax));
  return m;
}

}  // namespace

FrameMotion frame_motion(const Frame& from, const Frame* to, const std::string& source) {
  if (to) return checked(motion_between(from, *to, source), source);
  FrameMotion m;
  m.kind = "velocity";
  for (std::size_t i = 0; i < from.particles.size(); ++i) {
    m.index.push_back(static_cast<std::int32_t>(i));
    m.x.push_back(from.particles[i].position);
    m.u.push_back(from.particles[i].velocity);
  }
  m.frame = from;
  return checked(std::move(m), source);
}

FrameMotion read_frame_motion(const std::string& path, long from, std::optional<long> to) {
  const std::size_t n = frame_count(path);
  check_index(path, from, n, "reference frame");
  if (to) check_index(path, *to, n, "target frame");
  const Frame ref = read_frame(path, from);
  if (to) {
    const Frame target = read_frame(path, *to);
    return frame_motion(ref, &target, path);
  }
  return frame_motion(ref, nullptr, path);
}

}  // namespace gs
