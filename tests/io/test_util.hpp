// Helpers shared by the io tests: synthetic frames and scratch directories.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <string>

#include "snapshot.hpp"

namespace gs::test {

/// A fresh empty directory under the build tree, removed at destruction.
struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& name) {
    path = std::filesystem::temp_directory_path() /
           ("gs_test_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::filesystem::path operator/(const std::string& f) const { return path / f; }
};

/// A frame with every field set to distinct, non-round values (exercise exact round trips).
inline Frame random_frame(std::size_t np, std::size_t nc, unsigned seed, double time = 0.25) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto v3 = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  Frame f;
  f.time = time;
  f.step = 1234 + seed;
  f.dt = 1.1e-6;
  f.two_d = seed % 2 == 1;
  f.domain.lo = v3();
  f.domain.hi = f.domain.lo + Eigen::Vector3d(1.5, 2.5, 3.5);
  f.domain.periodic = seed % 3 == 0;
  f.domain.cell = Eigen::Matrix3d::Random();
  if (f.domain.periodic) f.domain.velocity_gradient = Eigen::Matrix3d::Random();
  for (std::size_t i = 0; i < np; ++i) {
    Particle p;
    p.id = static_cast<std::int64_t>(i * 7 + seed);
    p.position = v3() * 0.01;
    p.radius = 1e-3 * (1.0 + 0.5 * u(rng));
    p.velocity = v3();
    p.angular_velocity = v3() * 10;
    p.orientation = Eigen::Quaterniond(v3().x(), v3().y(), v3().z(), u(rng)).normalized();
    p.rotation = v3();
    p.mass = 1e-5 * (1.5 + u(rng));
    p.clump_id = i % 4 == 0 ? static_cast<std::int64_t>(i / 4) : -1;
    p.material_id = static_cast<std::int32_t>(i % 3);
    f.particles.push_back(p);
  }
  for (std::size_t k = 0; k < nc && np > 1; ++k) {
    Contact c;
    c.id1 = f.particles[k % np].id;
    c.id2 = f.particles[(k + 1) % np].id;
    c.point = v3() * 0.01;
    c.normal = v3().normalized();
    c.normal_force = c.normal * (1 + u(rng));
    c.shear_force = v3() * 0.1;
    c.bending_moment = v3() * 1e-4;
    c.twisting_moment = v3() * 1e-5;
    c.overlap = 1e-6 * (1 + u(rng));
    f.contacts.push_back(c);
  }
  for (int w = 0; w < 2; ++w) {
    Wall wall;
    wall.id = static_cast<std::int64_t>(np + w);
    wall.kind = w == 0 ? WallKind::Plane : WallKind::Box;
    wall.a = v3();
    wall.b = w == 0 ? Eigen::Vector3d(v3().normalized()) : Eigen::Vector3d(1, 2, 3);
    wall.force = v3();
    wall.torque = v3();
    f.walls.push_back(wall);
  }
  return f;
}

/// Gives every clump_id of the frame a clump body (distinct, non-round values; template names of
/// different lengths, up to the 64-byte limit).
inline Frame with_clump_bodies(Frame f, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  std::vector<std::int64_t> ids;
  for (const auto& p : f.particles)
    if (p.clump_id >= 0 && std::find(ids.begin(), ids.end(), p.clump_id) == ids.end())
      ids.push_back(p.clump_id);
  const std::string names[3] = {"dimer", "", std::string(64, 't')};
  for (const auto id : ids) {
    Clump c;
    c.id = id;
    c.template_name = names[static_cast<std::size_t>(id) % 3];
    c.position = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.01;
    c.orientation = Eigen::Quaterniond(u(rng), -u(rng), u(rng), u(rng) - 1.0).normalized();
    c.velocity = Eigen::Vector3d(u(rng), -u(rng), u(rng));
    c.angular_velocity = Eigen::Vector3d(u(rng), u(rng), -u(rng)) * 10;
    c.mass = 1e-5 * u(rng);
    c.principal_inertia = Eigen::Vector3d(u(rng), 2 * u(rng), 2 * u(rng)) * 1e-11;
    f.clumps.push_back(c);
  }
  return f;
}

inline void expect_same_clumps(const Frame& a, const Frame& b) {
  ASSERT_EQ(a.clumps.size(), b.clumps.size());
  for (std::size_t i = 0; i < a.clumps.size(); ++i) {
    const auto &c = a.clumps[i], &d = b.clumps[i];
    EXPECT_EQ(c.id, d.id);
    EXPECT_EQ(c.template_name, d.template_name);
    EXPECT_EQ(c.position, d.position);
    EXPECT_EQ(c.orientation.coeffs(), d.orientation.coeffs());
    EXPECT_EQ(c.velocity, d.velocity);
    EXPECT_EQ(c.angular_velocity, d.angular_velocity);
    EXPECT_EQ(c.mass, d.mass);
    EXPECT_EQ(c.principal_inertia, d.principal_inertia);
  }
}

inline void expect_same_frame(const Frame& a, const Frame& b, bool with_walls = true) {
  ASSERT_EQ(a.particles.size(), b.particles.size());
  ASSERT_EQ(a.contacts.size(), b.contacts.size());
  EXPECT_EQ(a.time, b.time);
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_EQ(a.two_d, b.two_d);
  EXPECT_EQ(a.domain.lo, b.domain.lo);
  EXPECT_EQ(a.domain.hi, b.domain.hi);
  EXPECT_EQ(a.domain.periodic, b.domain.periodic);
  EXPECT_EQ(a.domain.cell, b.domain.cell);
  EXPECT_EQ(a.domain.velocity_gradient, b.domain.velocity_gradient);
  for (std::size_t i = 0; i < a.particles.size(); ++i) {
    const auto &p = a.particles[i], &q = b.particles[i];
    EXPECT_EQ(p.id, q.id);
    EXPECT_EQ(p.position, q.position);  // exact, bit for bit
    EXPECT_EQ(p.radius, q.radius);
    EXPECT_EQ(p.velocity, q.velocity);
    EXPECT_EQ(p.angular_velocity, q.angular_velocity);
    EXPECT_EQ(p.orientation.coeffs(), q.orientation.coeffs());
    EXPECT_EQ(p.rotation, q.rotation);
    EXPECT_EQ(p.mass, q.mass);
    EXPECT_EQ(p.clump_id, q.clump_id);
    EXPECT_EQ(p.material_id, q.material_id);
  }
  for (std::size_t i = 0; i < a.contacts.size(); ++i) {
    const auto &c = a.contacts[i], &d = b.contacts[i];
    EXPECT_EQ(c.id1, d.id1);
    EXPECT_EQ(c.id2, d.id2);
    EXPECT_EQ(c.point, d.point);
    EXPECT_EQ(c.normal, d.normal);
    EXPECT_EQ(c.normal_force, d.normal_force);
    EXPECT_EQ(c.shear_force, d.shear_force);
    EXPECT_EQ(c.bending_moment, d.bending_moment);
    EXPECT_EQ(c.twisting_moment, d.twisting_moment);
    EXPECT_EQ(c.overlap, d.overlap);
  }
  expect_same_clumps(a, b);
  ASSERT_EQ(a.facet_loads.size(), b.facet_loads.size());
  for (std::size_t i = 0; i < a.facet_loads.size(); ++i) {
    EXPECT_EQ(a.facet_loads[i].wall_id, b.facet_loads[i].wall_id);
    EXPECT_EQ(a.facet_loads[i].facet, b.facet_loads[i].facet);
    EXPECT_EQ(a.facet_loads[i].centroid, b.facet_loads[i].centroid);
    EXPECT_EQ(a.facet_loads[i].force, b.facet_loads[i].force);
  }
  if (!with_walls) return;
  ASSERT_EQ(a.walls.size(), b.walls.size());
  for (std::size_t i = 0; i < a.walls.size(); ++i) {
    EXPECT_EQ(a.walls[i].id, b.walls[i].id);
    EXPECT_EQ(a.walls[i].kind, b.walls[i].kind);
    EXPECT_EQ(a.walls[i].a, b.walls[i].a);
    EXPECT_EQ(a.walls[i].b, b.walls[i].b);
    EXPECT_EQ(a.walls[i].force, b.walls[i].force);
    EXPECT_EQ(a.walls[i].torque, b.walls[i].torque);
  }
}

}  // namespace gs::test
