// Kanatani contact fabric (seed 003 eq 18–21) and clump orientation fabric D^p (seed 003 §4.3
// with eq 20–21).
#include "fabric.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace gs::analysis {
namespace {

/// Deviatoric anisotropy of a normalised second moment T (trace 1): 15/2 (T - I/3) in 3D,
/// 4 (T - I/2) in 2D (seed 003 eq 21 and its 2D analogue).
Eigen::Matrix3d anisotropy(const Eigen::Matrix3d& t, int dim) {
  if (dim == 2) {
    Eigen::Matrix3d d = Eigen::Matrix3d::Zero();
    d.topLeftCorner<2, 2>() = 4.0 * (t.topLeftCorner<2, 2>() - 0.5 * Eigen::Matrix2d::Identity());
    return d;
  }
  return 7.5 * (t - Eigen::Matrix3d::Identity() / 3.0);
}

}  // namespace

Fabric contact_fabric(const std::vector<Eigen::Vector3d>& normals, std::size_t particles, int dim) {
  if (particles == 0) throw std::invalid_argument("fabric: no particle selected");
  if (normals.empty()) throw std::invalid_argument("fabric: no contact selected");
  Fabric f;
  f.dim = dim;
  f.particles = particles;
  f.contacts = normals.size();
  for (const auto& n0 : normals) {
    Eigen::Vector3d n = n0;
    if (dim == 2) n.z() = 0.0;
    const double len = n.norm();
    if (!(len > 0.0)) continue;
    n /= len;
    f.M.noalias() += 2.0 * n * n.transpose();  // both contact points C^AB and C^BA
  }
  f.M /= static_cast<double>(particles);
  f.omega = f.M.trace();
  if (!(f.omega > 0.0)) throw std::invalid_argument("fabric: no contact normal in the plane");
  f.D = anisotropy(f.M / f.omega, dim);
  f.D_norm = f.D.norm();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(f.D);
  for (int k = 0; k < 3; ++k) {
    f.D_principal[k] = es.eigenvalues()[2 - k];
    f.D_directions.col(k) = es.eigenvectors().col(2 - k);
  }
  return f;
}

const char* orientation_source_name(OrientationSource s) {
  switch (s) {
    case OrientationSource::Bodies:
      return "clump bodies";
    case OrientationSource::Members:
      return "clump members";
    case OrientationSource::None:
      break;
  }
  return "none";
}

namespace {

/// Phi = <m m^T> over the axes, D^p = anisotropy(Phi) (seed 003 §4.3 with eq 20–21).
void finish_orientation(OrientationFabric& o, int dim) {
  o.bodies = o.clump.size();
  if (o.bodies == 0) return;
  o.Phi.setZero();
  for (const auto& m : o.axis) o.Phi.noalias() += m * m.transpose();
  o.Phi /= static_cast<double>(o.bodies);
  o.D = anisotropy(o.Phi, dim);
  o.D_norm = o.D.norm();
}

}  // namespace

std::optional<Eigen::Vector3d> clump_long_axis(const Clump& c) {
  const Eigen::Vector3d& I = c.principal_inertia;
  int k = 0;
  for (int j = 1; j < 3; ++j)
    if (I[j] < I[k]) k = j;
  const double next = std::min(I[(k + 1) % 3], I[(k + 2) % 3]);
  if (!(next - I[k] > 1e-9 * next)) return std::nullopt;
  return Eigen::Vector3d(c.orientation.normalized().toRotationMatrix().col(k));
}

OrientationFabric body_orientation_fabric(const std::vector<Clump>& clumps, int dim) {
  OrientationFabric o;
  o.source = OrientationSource::Bodies;
  for (const auto& c : clumps) {
    auto m = clump_long_axis(c);
    if (!m) continue;
    if (dim == 2) {
      m->z() = 0.0;
      const double len = m->norm();
      if (!(len > 1e-12)) continue;  // a long axis normal to the plane: none in the plane
      *m /= len;
    }
    o.clump.push_back(c.id);
    o.axis.push_back(*m);
    o.centroid.push_back(c.position);
  }
  finish_orientation(o, dim);
  return o;
}

OrientationFabric orientation_fabric(const Frame& frame) {
  if (!frame.clumps.empty()) return body_orientation_fabric(frame.clumps, frame.two_d ? 2 : 3);
  return member_orientation_fabric(frame);
}

OrientationFabric member_orientation_fabric(const Frame& frame) {
  OrientationFabric o;
  std::map<std::int64_t, std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < frame.particles.size(); ++i)
    if (frame.particles[i].clump_id >= 0) members[frame.particles[i].clump_id].push_back(i);
  const int dim = frame.two_d ? 2 : 3;
  for (const auto& [id, idx] : members) {
    if (idx.size() < 2) continue;
    double vol = 0.0;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto i : idx) {
      const auto& p = frame.particles[i];
      const double v = std::pow(p.radius, dim);
      vol += v;
      c += v * p.position;
    }
    c /= vol;
    Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
    for (const auto i : idx) {
      const auto& p = frame.particles[i];
      const Eigen::Vector3d d = p.position - c;
      s.noalias() += std::pow(p.radius, dim) * d * d.transpose();
    }
    if (dim == 2) s.row(2).setZero(), s.col(2).setZero();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(s);
    const Eigen::Vector3d m = es.eigenvectors().col(2);
    o.clump.push_back(id);
    o.axis.push_back(m);
    o.centroid.push_back(c);
  }
  if (!members.empty()) o.source = OrientationSource::Members;
  finish_orientation(o, dim);
  return o;
}

}  // namespace gs::analysis
