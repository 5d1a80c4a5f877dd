// The motion of particles between two frames of a trajectory (matched by particle id), or their
// velocities in one frame: the input of every deformation analysis (strain, void cells, HHD).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "snapshot.hpp"

namespace gs {

struct FrameMotion {
  Frame frame;                        // reference frame (particles in file order)
  std::vector<std::int32_t> index;    // particles of `frame` that take part
  std::vector<Eigen::Vector3d> x, u;  // their positions and displacements (m) / velocities (m/s)
  std::string kind;                   // "displacement" or "velocity"
};

/// Frame `i` of any snapshot file granoscope reads (HDF5 read lazily, other formats whole).
/// Throws InputError "FILE: frame out of range 0..N-1 (i)" and the readers' errors.
Frame read_frame(const std::string& path, long i);
/// Number of frames of any snapshot file.
std::size_t frame_count(const std::string& path);

/// Without `to`: the velocities of frame `from`. With it: the displacement from `from` to `to`
/// of every particle present in both (matched by id; periodic cells take the minimum image
/// with respect to the target frame's cell, the one wrapped positions were wrapped into).
FrameMotion motion_between(const Frame& from, const Frame& to, const std::string& source);
/// The motion of frame `from`: the velocities of its particles, or with `to` the displacement
/// to it (motion_between); positions and motions checked for lengths the geometry can handle.
FrameMotion frame_motion(const Frame& from, const Frame* to, const std::string& source);
FrameMotion read_frame_motion(const std::string& path, long from, std::optional<long> to);

}  // namespace gs
