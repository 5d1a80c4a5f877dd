// Love–Weber stress (seed 004 eq 4.1) and the boundary form (seed 003 eq 14); conventions in the
// header.
#include "love_weber_stress.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace gs::analysis {

ContactBranches contact_branches(const Frame& frame) {
  ContactBranches out;
  std::unordered_map<std::int64_t, std::int32_t> index;
  index.reserve(frame.particles.size());
  for (std::size_t i = 0; i < frame.particles.size(); ++i)
    index.emplace(frame.particles[i].id, static_cast<std::int32_t>(i));
  const bool periodic = frame.domain.periodic;
  const Eigen::Matrix3d cell = frame.domain.cell;
  const Eigen::Matrix3d inv = periodic ? Eigen::Matrix3d(cell.inverse()) : Eigen::Matrix3d::Zero();
  out.branches.reserve(frame.contacts.size());
  for (std::size_t k = 0; k < frame.contacts.size(); ++k) {
    const Contact& c = frame.contacts[k];
    const auto i1 = index.find(c.id1), i2 = index.find(c.id2);
    const bool has1 = i1 != index.end(), has2 = i2 != index.end();
    const Eigen::Vector3d f = c.normal_force + c.shear_force;  // by id1 on id2
    ContactBranch b;
    b.contact = static_cast<std::int32_t>(k);
    if (has1 && has2) {
      if (i1->second == i2->second) {
        ++out.skipped;
        continue;
      }
      b.p1 = i1->second;
      b.p2 = i2->second;
      b.start = frame.particles[static_cast<std::size_t>(b.p1)].position;
      b.branch = frame.particles[static_cast<std::size_t>(b.p2)].position - b.start;
      if (periodic) {  // minimum image across the cell
        Eigen::Vector3d s = inv * b.branch;
        if (frame.two_d) s.z() = 0.0;
        b.branch -= cell * s.array().round().matrix();
      }
      b.force = f;
      ++out.particle_contacts;
    } else if (has1 || has2) {
      b.p1 = has1 ? i1->second : i2->second;
      b.start = frame.particles[static_cast<std::size_t>(b.p1)].position;
      b.branch = c.point - b.start;
      b.force = has1 ? f : Eigen::Vector3d(-f);  // by the particle on the wall
      ++out.wall_contacts;
    } else {
      ++out.skipped;
      continue;
    }
    out.branches.push_back(b);
  }
  return out;
}

double segment_box_fraction(const Eigen::Vector3d& start, const Eigen::Vector3d& l,
                            const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t0 = 0.0, t1 = 1.0;
  for (int d = 0; d < 3; ++d) {
    if (l[d] == 0.0) {
      if (start[d] < lo[d] || start[d] >= hi[d]) return 0.0;
      continue;
    }
    double a = (lo[d] - start[d]) / l[d], b = (hi[d] - start[d]) / l[d];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t1 <= t0) return 0.0;
  }
  return t1 - t0;
}

Eigen::Matrix3d love_weber_stress(const std::vector<ContactBranch>& branches,
                                  const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (const auto& b : branches) {
    const double w = segment_box_fraction(b.start, b.branch, lo, hi);
    if (w > 0.0) s.noalias() += w * b.branch * b.force.transpose();
  }
  return s / (hi - lo).prod();
}

Eigen::Matrix3d periodic_cell_stress(const Frame& frame, const ContactBranches& b) {
  if (!frame.domain.periodic) throw std::invalid_argument("the frame has no periodic cell");
  const Eigen::Matrix3d& c = frame.domain.cell;
  const double v = std::abs(frame.two_d ? c.topLeftCorner<2, 2>().determinant() : c.determinant());
  if (!(v > 0.0) || !std::isfinite(v)) throw std::invalid_argument("degenerate periodic cell");
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (const auto& br : b.branches) s.noalias() += br.branch * br.force.transpose();
  return s / v;
}

Eigen::Matrix3d boundary_stress(const Frame& frame, const ContactBranches& b, double volume) {
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (const auto& br : b.branches) {
    if (br.p2 >= 0) continue;
    const Eigen::Vector3d& x = frame.contacts[static_cast<std::size_t>(br.contact)].point;
    s.noalias() += x * br.force.transpose();  // -x (F of the wall on the specimen = -f)
  }
  return s / volume;
}

}  // namespace gs::analysis
