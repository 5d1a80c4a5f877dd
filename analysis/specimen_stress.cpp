#include "specimen_stress.hpp"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

#include "errors.hpp"
#include "frame_motion.hpp"
#include "love_weber_stress.hpp"

namespace gs::analysis {

SpecimenStress specimen_stress(
    const std::string& file, const Frame& f,
    const std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& region) {
  SpecimenStress s;
  s.dim = f.two_d ? 2 : 3;
  const auto b = contact_branches(f);
  auto box = region;
  if (!box && f.domain.periodic) {  // the whole cell: every (minimum-image) branch in full
    try {
      s.sigma = periodic_cell_stress(f, b);
    } catch (const std::invalid_argument& e) {
      throw InputError(file, e.what());
    }
    const Eigen::Matrix3d& c = f.domain.cell;
    s.volume = std::abs(f.two_d ? c.topLeftCorner<2, 2>().determinant() : c.determinant());
  } else {
    if (!box) box = particle_bounds(f);
    if (f.two_d) box->first.z() = -0.5, box->second.z() = 0.5;  // per unit depth: N/m
    s.volume = (box->second - box->first).prod();
    s.sigma = love_weber_stress(b.branches, box->first, box->second);
  }
  if (b.wall_contacts > 0) s.boundary_eq14 = boundary_stress(f, b, s.volume);
  return s;
}

Eigen::Matrix3d fit_deformation_gradient(const std::string& file, const Frame& from,
                                         const Frame& to) {
  const FrameMotion m = motion_between(from, to, file);
  const int dim = from.two_d ? 2 : 3;
  Eigen::Vector3d xm = Eigen::Vector3d::Zero(), um = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < m.x.size(); ++k) xm += m.x[k], um += m.u[k];
  xm /= static_cast<double>(m.x.size());
  um /= static_cast<double>(m.x.size());
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero(), b = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < m.x.size(); ++k) {
    const Eigen::Vector3d dx = m.x[k] - xm, du = m.u[k] - um;
    a.noalias() += dx * dx.transpose();
    b.noalias() += du * dx.transpose();
  }
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  const auto block = a.topLeftCorner(dim, dim);
  Eigen::FullPivLU<Eigen::MatrixXd> lu(block);
  if (m.x.size() < static_cast<std::size_t>(dim + 1) || lu.rank() < dim)
    throw InputError(file, "deformation gradient: matched particles are degenerate (coplanar)");
  F.topLeftCorner(dim, dim) += b.topLeftCorner(dim, dim) * lu.inverse();
  return F;
}

}  // namespace gs::analysis
