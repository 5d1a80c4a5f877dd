#include "frame_motion.hpp"

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

FrameMotion read_frame_motion(const std::string& path, long from, std::optional<long> to) {
  const std::size_t n = frame_count(path);
  check_index(path, from, n, "reference frame");
  if (to) check_index(path, *to, n, "target frame");
  Frame ref = read_frame(path, from);
  if (to) return motion_between(ref, read_frame(path, *to), path);
  FrameMotion m;
  m.kind = "velocity";
  for (std::size_t i = 0; i < ref.particles.size(); ++i) {
    m.index.push_back(static_cast<std::int32_t>(i));
    m.x.push_back(ref.particles[i].position);
    m.u.push_back(ref.particles[i].velocity);
  }
  m.frame = std::move(ref);
  return m;
}

}  // namespace gs
