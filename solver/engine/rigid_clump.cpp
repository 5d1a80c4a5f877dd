#include "rigid_clump.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "newton_integrator.hpp"

namespace gs::solver {

namespace {

void check_members(const std::vector<ClumpMember>& members, double density) {
  if (members.empty()) throw std::invalid_argument("a clump needs at least one member sphere");
  for (const auto& m : members)
    if (!(m.radius > 0) || !std::isfinite(m.radius) || !m.offset.allFinite())
      throw std::invalid_argument("clump member radius must be positive and finite (" +
                                  std::to_string(m.radius) + ")");
  if (!(density > 0)) throw std::invalid_argument("clump density must be positive");
}

/// Inertia tensor from the second moments Σ x xᵀ ρ dV about the centroid: I = tr(S)·𝟙 − S.
Eigen::Matrix3d inertia_from_second_moments(const Eigen::Matrix3d& s) {
  return s.trace() * Eigen::Matrix3d::Identity() - s;
}

/// Union of two spheres, exact: along the axis u from c1 the cross-section is the larger of
/// the two disks, sphere 1 below the plane where they intersect and sphere 2 above it; its
/// area and moments are polynomials of degree ≤ 4 in the axial coordinate, which 3-point
/// Gauss–Legendre integrates exactly on each piece.
MassProperties two_sphere_union(const ClumpMember& a, const ClumpMember& b, double density) {
  const Eigen::Vector3d d = b.offset - a.offset;
  const double dist = d.norm(), r1 = a.radius, r2 = b.radius;
  auto single = [&](const ClumpMember& m) { return member_sum_mass_properties({m}, density); };
  if (dist + std::min(r1, r2) <= std::max(r1, r2)) return single(r1 >= r2 ? a : b);
  if (dist >= r1 + r2) return member_sum_mass_properties({a, b}, density);
  const Eigen::Vector3d u = d / dist;
  const double s_star = (dist * dist + r1 * r1 - r2 * r2) / (2 * dist);
  // Pieces [lo, hi] with ρ²(s) = r² − (s − c)².
  struct Piece {
    double lo, hi, c, r;
  };
  const Piece pieces[2] = {{-r1, s_star, 0.0, r1}, {s_star, dist + r2, dist, r2}};
  static const double gx[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
  static const double gw[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  // ∫ A, ∫ A s, ∫ A s², ∫ ρ⁴ (A = πρ²).
  double m0 = 0, m1 = 0, m2 = 0, q4 = 0;
  for (const auto& p : pieces) {
    const double half = 0.5 * (p.hi - p.lo), mid = 0.5 * (p.hi + p.lo);
    for (int k = 0; k < 3; ++k) {
      const double s = mid + half * gx[k];
      const double rho2 = p.r * p.r - (s - p.c) * (s - p.c);
      const double w = gw[k] * half;
      m0 += w * M_PI * rho2;
      m1 += w * M_PI * rho2 * s;
      m2 += w * M_PI * rho2 * s * s;
      q4 += w * rho2 * rho2;
    }
  }
  MassProperties mp;
  mp.volume = m0;
  mp.mass = density * m0;
  const double sc = m1 / m0;
  mp.centroid = a.offset + sc * u;
  const double axial = density * M_PI * q4 / 2;  // Σ ρ⁴/2 per disk
  const double perp = density * (M_PI * q4 / 4 + (m2 - 2 * sc * m1 + sc * sc * m0));
  const Eigen::Matrix3d uu = u * u.transpose();
  mp.inertia = perp * (Eigen::Matrix3d::Identity() - uu) + axial * uu;
  return mp;
}

}  // namespace

MassProperties member_sum_mass_properties(const std::vector<ClumpMember>& members, double density) {
  check_members(members, density);
  MassProperties mp;
  std::vector<double> m(members.size());
  Eigen::Vector3d sx = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < members.size(); ++i) {
    const double v = (4.0 / 3.0) * M_PI * std::pow(members[i].radius, 3);
    m[i] = v * density;
    mp.volume += v;
    mp.mass += m[i];
    sx += m[i] * members[i].offset;
  }
  mp.centroid = sx / mp.mass;
  for (std::size_t i = 0; i < members.size(); ++i) {
    const Eigen::Vector3d dd = members[i].offset - mp.centroid;
    const double r = members[i].radius;
    mp.inertia += (2.0 / 5.0) * m[i] * r * r * Eigen::Matrix3d::Identity() +
                  m[i] * (dd.squaredNorm() * Eigen::Matrix3d::Identity() - dd * dd.transpose());
  }
  return mp;
}

MassProperties union_mass_properties(const std::vector<ClumpMember>& members, double density,
                                     int resolution) {
  check_members(members, density);
  if (members.size() == 1) return member_sum_mass_properties(members, density);
  if (members.size() == 2) return two_sphere_union(members[0], members[1], density);
  if (resolution < 2) throw std::invalid_argument("union quadrature resolution must be >= 2");
  Eigen::Vector3d lo = members[0].offset, hi = lo;
  for (const auto& m : members) {
    lo = lo.cwiseMin((m.offset.array() - m.radius).matrix());
    hi = hi.cwiseMax((m.offset.array() + m.radius).matrix());
  }
  const double hy = (hi.y() - lo.y()) / resolution, hz = (hi.z() - lo.z()) / resolution;
  const double da = hy * hz;
  // Moments about the box corner (smaller numbers than about the origin).
  double v = 0;
  Eigen::Vector3d s1 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
  std::vector<std::pair<double, double>> iv;
  iv.reserve(members.size());
  for (int iz = 0; iz < resolution; ++iz) {
    const double z = lo.z() + (iz + 0.5) * hz;
    for (int iy = 0; iy < resolution; ++iy) {
      const double y = lo.y() + (iy + 0.5) * hy;
      iv.clear();
      for (const auto& m : members) {
        const double h2 = m.radius * m.radius - (y - m.offset.y()) * (y - m.offset.y()) -
                          (z - m.offset.z()) * (z - m.offset.z());
        if (h2 > 0) {
          const double h = std::sqrt(h2);
          iv.emplace_back(m.offset.x() - h - lo.x(), m.offset.x() + h - lo.x());
        }
      }
      if (iv.empty()) continue;
      std::sort(iv.begin(), iv.end());
      double len = 0, x1 = 0, x2 = 0, a = iv[0].first, b = iv[0].second;
      auto flush = [&] {
        len += b - a;
        x1 += 0.5 * (b * b - a * a);
        x2 += (b * b * b - a * a * a) / 3;
      };
      for (std::size_t k = 1; k < iv.size(); ++k) {
        if (iv[k].first > b) {
          flush();
          a = iv[k].first;
          b = iv[k].second;
        } else {
          b = std::max(b, iv[k].second);
        }
      }
      flush();
      const double yy = y - lo.y(), zz = z - lo.z();
      v += len;
      s1 += Eigen::Vector3d(x1, yy * len, zz * len);
      s2(0, 0) += x2;
      s2(1, 1) += yy * yy * len;
      s2(2, 2) += zz * zz * len;
      s2(0, 1) += yy * x1;
      s2(0, 2) += zz * x1;
      s2(1, 2) += yy * zz * len;
    }
  }
  s2(1, 0) = s2(0, 1);
  s2(2, 0) = s2(0, 2);
  s2(2, 1) = s2(1, 2);
  v *= da;
  s1 *= da;
  s2 *= da;
  const Eigen::Vector3d c = s1 / v;
  MassProperties mp;
  mp.volume = v;
  mp.mass = density * v;
  mp.centroid = lo + c;
  mp.inertia = density * inertia_from_second_moments(s2 - v * c * c.transpose());
  return mp;
}

MassProperties clump_mass_properties(const std::vector<ClumpMember>& members, double density,
                                     ClumpMassModel model) {
  return model == ClumpMassModel::MemberSum ? member_sum_mass_properties(members, density)
                                            : union_mass_properties(members, density);
}

PrincipalAxes principal_axes(const Eigen::Matrix3d& inertia) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(inertia);
  Eigen::Matrix3d r = es.eigenvectors();
  if (r.determinant() < 0) r.col(2) = -r.col(2);
  PrincipalAxes pa;
  pa.moments = es.eigenvalues();
  pa.orientation = Eigen::Quaterniond(r);
  pa.orientation.normalize();
  return pa;
}

ClumpBody make_clump_body(const std::vector<std::uint32_t>& member_indices,
                          const std::vector<Eigen::Vector3d>& member_pos,
                          const std::vector<double>& member_radius, double density,
                          ClumpMassModel model, const Eigen::Quaterniond* orientation) {
  if (member_indices.size() != member_pos.size() || member_pos.size() != member_radius.size())
    throw std::invalid_argument("clump members: index, position and radius counts differ");
  std::vector<ClumpMember> members(member_pos.size());
  for (std::size_t i = 0; i < members.size(); ++i) members[i] = {member_pos[i], member_radius[i]};
  const MassProperties mp = clump_mass_properties(members, density, model);
  ClumpBody c;
  c.members = member_indices;
  c.mass = mp.mass;
  c.pos = mp.centroid;
  if (orientation) {
    c.ori = orientation->normalized();
    const Eigen::Matrix3d r = c.ori.toRotationMatrix();
    c.inertia = (r.transpose() * mp.inertia * r).diagonal();
  } else {
    const PrincipalAxes pa = principal_axes(mp.inertia);
    c.ori = pa.orientation;
    c.inertia = pa.moments;
  }
  if (!(c.inertia.minCoeff() > 0)) throw std::invalid_argument("clump inertia must be positive");
  const Eigen::Quaterniond inv = c.ori.conjugate();
  for (const auto& x : member_pos) {
    c.local_pos.push_back(inv * (x - c.pos));
    c.local_ori.push_back(inv);
  }
  return c;
}

double integrate_clump(ClumpBody& c, const ClumpLoad& load, const Eigen::Vector3d& gravity,
                       double damping, double dt) {
  double damp = 0;
  integrate_clump_bodies(&c, &load, 1, gravity, damping, dt, &damp);
  return damp;
}

double clump_kinetic_energy(const ClumpBody& c) {
  const Eigen::Matrix3d r = c.ori.toRotationMatrix();
  const Eigen::Matrix3d i = r * c.inertia.asDiagonal() * r.transpose();
  return 0.5 * c.mass * c.vel.squaredNorm() + 0.5 * c.angvel.dot(i * c.angvel);
}

}  // namespace gs::solver
