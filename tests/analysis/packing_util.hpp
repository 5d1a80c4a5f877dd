// Synthetic packings with exact answers for the REV, stress and fabric tests: lattices loaded
// isotropically and random polydisperse packings with overlap contacts.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>

#include "snapshot.hpp"

namespace gs::test {

/// Simple-cubic lattice of n^3 spheres of radius r at spacing 2r (touching), centres at
/// (2r i, 2r j, 2r k). Every neighbour pair is a contact pushed apart by the force `force` (N),
/// and with `walls` the six faces carry plane walls (ids after the particles) pressing the outer
/// spheres with the same force: an isotropically loaded lattice at pressure force / (2r)^2.
inline Frame cubic_lattice(int n, double r, double force, bool walls) {
  Frame f;
  auto id = [n](int i, int j, int k) { return static_cast<std::int64_t>(i + n * (j + n * k)); };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Particle p;
        p.id = id(i, j, k);
        p.position = 2.0 * r * Eigen::Vector3d(i, j, k);
        p.radius = r;
        p.rotation = Eigen::Vector3d(0.01 * i, -0.02 * j, 0.03 * k);
        f.particles.push_back(p);
      }
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) {
          int q[3] = {i, j, k};
          if (++q[d] >= n) continue;
          Contact c;
          c.id1 = id(i, j, k);
          c.id2 = id(q[0], q[1], q[2]);
          c.normal = Eigen::Vector3d::Unit(d);
          c.point = f.particles[static_cast<std::size_t>(c.id1)].position + r * c.normal;
          c.normal_force = force * c.normal;  // by id1 on id2: compressive
          f.contacts.push_back(c);
        }
  if (walls) {
    const auto np = static_cast<std::int64_t>(f.particles.size());
    for (int w = 0; w < 6; ++w) {
      const int d = w / 2;
      const bool high = w % 2 == 1;
      Wall wall;
      wall.id = np + w;
      wall.a = Eigen::Vector3d::Zero();
      wall.a[d] = high ? 2.0 * r * (n - 1) + r : -r;
      wall.b = (high ? -1.0 : 1.0) * Eigen::Vector3d::Unit(d);
      f.walls.push_back(wall);
      for (const auto& p : f.particles) {
        const double x = p.position[d] / (2.0 * r);
        if (std::lround(x) != (high ? n - 1 : 0)) continue;
        Contact c;  // the wall (id1) pushes the sphere (id2) inwards
        c.id1 = wall.id;
        c.id2 = p.id;
        c.normal = wall.b;
        c.point = p.position - r * wall.b;
        c.normal_force = force * wall.b;
        f.contacts.push_back(c);
      }
    }
  }
  return f;
}

/// Face-centred cubic lattice (cube side a = 2 sqrt(2) r, spheres touching), n^3 unit cells.
inline Frame fcc_lattice(int n, double r) {
  Frame f;
  const double a = 2.0 * std::sqrt(2.0) * r;
  const Eigen::Vector3d basis[4] = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.5, 0.5, 0),
                                    Eigen::Vector3d(0.5, 0, 0.5), Eigen::Vector3d(0, 0.5, 0.5)};
  std::int64_t id = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& b : basis) {
          Particle p;
          p.id = id++;
          p.position = a * (Eigen::Vector3d(i, j, k) + b);
          p.radius = r;
          f.particles.push_back(p);
        }
  return f;
}

/// Random polydisperse spheres (radius in [0.35, 0.6] x spacing) on a jittered cubic lattice of
/// n^3 sites at `spacing`; contacts for all overlapping pairs with random forces (compressive
/// normal part, random shear), random rotations, velocities and masses; two plane walls at
/// z = 0 and z = top with contacts to the spheres that reach them.
inline Frame random_packing(int n, double spacing, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), ur(0.35, 0.6), uf(0.1, 2.0);
  Frame f;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Particle p;
        p.id = static_cast<std::int64_t>(f.particles.size()) * 3 + 7;  // ids not = indices
        p.position = spacing * (Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) +
                                0.12 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
        p.radius = spacing * ur(rng);
        p.rotation = Eigen::Vector3d(u(rng), u(rng), u(rng));
        p.velocity = Eigen::Vector3d(u(rng), u(rng), u(rng));
        p.mass = 2650.0 * 4.0 / 3.0 * 3.141592653589793 * std::pow(p.radius, 3);
        f.particles.push_back(p);
      }
  const auto idx = [n](int i, int j, int k) {
    return static_cast<std::size_t>(i + n * (j + n * k));
  };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int dk = 0; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              if (dk == 0 && (dj < 0 || (dj == 0 && di <= 0))) continue;  // each pair once
              const int a = i + di, b = j + dj, c = k + dk;
              if (a < 0 || b < 0 || a >= n || b >= n || c >= n) continue;
              const Particle& p = f.particles[idx(i, j, k)];
              const Particle& q = f.particles[idx(a, b, c)];
              const Eigen::Vector3d d = q.position - p.position;
              if (d.norm() >= p.radius + q.radius) continue;
              Contact ct;
              ct.id1 = p.id;
              ct.id2 = q.id;
              ct.normal = d.normalized();
              ct.point = p.position + p.radius * ct.normal;
              ct.normal_force = uf(rng) * ct.normal;
              Eigen::Vector3d t(u(rng), u(rng), u(rng));
              ct.shear_force = 0.3 * (t - t.dot(ct.normal) * ct.normal);
              ct.overlap = p.radius + q.radius - d.norm();
              f.contacts.push_back(ct);
            }
  const auto np = static_cast<std::int64_t>(f.particles.size()) * 3 + 7;
  const double top = spacing * n;
  for (int w = 0; w < 2; ++w) {
    Wall wall;
    wall.id = np + w;
    wall.a = Eigen::Vector3d(0, 0, w == 0 ? 0.0 : top);
    wall.b = Eigen::Vector3d(0, 0, w == 0 ? 1.0 : -1.0);
    f.walls.push_back(wall);
    for (const auto& p : f.particles) {
      const double gap = w == 0 ? p.position.z() : top - p.position.z();
      if (gap >= p.radius) continue;
      Contact c;
      c.id1 = p.id;  // particle first here, wall second
      c.id2 = wall.id;
      c.normal = -wall.b;
      c.point = p.position + gap * c.normal;
      c.normal_force = uf(rng) * c.normal;
      Eigen::Vector3d t(u(rng), u(rng), 0.0);
      c.shear_force = 0.2 * t;
      f.contacts.push_back(c);
    }
  }
  return f;
}

/// Simple-cubic lattice nx x ny x nz (spacing d) whose particles rotate about y in a Gaussian
/// band (standard deviation sigma, peak 0.8 rad) through `centre`, inclined at angle_deg to x in
/// the x-z plane: the rotation field of a shear band.
inline Frame band_lattice(int nx, int ny, int nz, double d, double angle_deg, double sigma,
                          const Eigen::Vector3d& centre) {
  Frame f;
  const double a = angle_deg * 3.141592653589793 / 180.0;
  const Eigen::Vector3d nrm(-std::sin(a), 0, std::cos(a));
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        Particle p;
        p.id = static_cast<std::int64_t>(f.particles.size());
        p.radius = 0.5 * d;
        p.position = d * Eigen::Vector3d(i, j, k);
        const double dist = (p.position - centre).dot(nrm);
        p.rotation = Eigen::Vector3d(0, 0.8 * std::exp(-dist * dist / (2 * sigma * sigma)), 0);
        f.particles.push_back(p);
      }
  return f;
}

}  // namespace gs::test
