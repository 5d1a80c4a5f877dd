// Rigid motion of mesh walls: rotation about a centre, a servo on the force summed over a
// mesh's walls, switching a mesh off, per-facet forces and group torques, and checkpoints of a
// rotating mesh. Each against the analytic wall it must reproduce or an exact answer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "mesh_walls.hpp"
#include "simulation.hpp"

using namespace gs;
using solver::MeshContact;
using solver::MeshTriangles;

namespace {

solver::SimulationConfig config() {
  solver::SimulationConfig c;
  c.material.young_ec = 1e6;
  c.material.stiffness_ratio = 0.3;
  c.material.friction_deg = 30;
  c.material.density = 2500;
  c.dt = 2e-6;
  c.max_overlap_ratio = 1.0;
  return c;
}

Particle sphere(std::int64_t id, Eigen::Vector3d x, double r) {
  Particle p;
  p.id = id;
  p.position = x;
  p.radius = r;
  return p;
}

/// The square [−a/2, a/2]² at z = 0 as two triangles, normal +z.
MeshTriangles square(double a) {
  const double h = a / 2;
  MeshTriangles m;
  m.triangles = {{Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, -h, 0), Eigen::Vector3d(h, h, 0)},
                 {Eigen::Vector3d(-h, -h, 0), Eigen::Vector3d(h, h, 0), Eigen::Vector3d(-h, h, 0)}};
  m.group = {"floor", "floor"};
  return m;
}

std::vector<Particle> pile() {
  std::vector<Particle> ps;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      ps.push_back(sphere(static_cast<std::int64_t>(ps.size()),
                          {-2.2e-3 + 2.2e-3 * i, -2.2e-3 + 2.2e-3 * j, 1.0e-3}, 1e-3));
  return ps;
}

double worst_difference(const solver::Simulation& a, const solver::Simulation& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.particles().size(); ++i)
    worst = std::max(worst, (a.particles().pos[i] - b.particles().pos[i]).norm());
  return worst;
}

}  // namespace

// A mesh turning about a centre away from it: after N steps its vertices are where the exact
// rotation by ω·N·dt puts them (the rotation is composed from the initial triangles, no drift).
TEST(MeshMotion, RotationAboutACentreIsExact) {
  auto walls = solver::mesh_walls(square(0.01), MeshContact::YadeParity);
  const Eigen::Vector3d omega(0.3, -0.2, 1.5), centre(0.02, -0.01, 0.005);
  for (auto& w : walls) {
    w.angular_velocity = omega;
    w.rotation_center = centre;
  }
  auto c = config();
  c.dt = 1e-3;
  solver::Simulation sim(c, {sphere(0, {1, 1, 1}, 1e-3)}, walls);
  const int n = 20000;
  for (int s = 0; s < n; ++s) sim.step();
  const Eigen::AngleAxisd turn(omega.norm() * n * c.dt, omega.normalized());
  const auto tri = square(0.01);
  double worst = 0;
  for (std::size_t t = 0; t < 2; ++t) {
    const auto& w = sim.walls()[t];
    const auto& f = w.facets[0];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d now = w.pos + (f.offset + f.vertex[k]).eigen();
      const Eigen::Vector3d exact = centre + turn * (tri.triangles[t][k] - centre);
      worst = std::max(worst, (now - exact).norm());
    }
    EXPECT_NEAR(f.normal.eigen().dot(turn * Eigen::Vector3d::UnitZ()), 1.0, 1e-14);
  }
  std::printf("vertices after %d steps (%.1f turns): %.2e m from the exact rotation\n", n,
              omega.norm() * n * c.dt / (2 * M_PI), worst);
  EXPECT_LT(worst, 1e-14);
}

// Spheres on a floor tilting about a horizontal axis through a point on it: the mesh floor
// (merged: plane-wall physics) gives the trajectories of the analytic rotating plane.
TEST(MeshMotion, TiltingMeshFloorMatchesTheRotatingPlane) {
  auto c = config();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.damping = 0.05;
  const Eigen::Vector3d omega(0, 2.0, 0), pivot(0.001, 0.0005, 0);
  auto mesh = solver::mesh_walls(square(0.05), MeshContact::Merged);
  for (auto& w : mesh) {
    w.angular_velocity = omega;
    w.rotation_center = pivot;
  }
  solver::WallSpec plane;
  plane.shape = solver::WallShape::Plane;
  plane.center = pivot;
  plane.normal = Eigen::Vector3d::UnitZ();
  plane.angular_velocity = omega;
  solver::Simulation with_plane(c, pile(), {plane}), with_mesh(c, pile(), mesh);
  double worst = 0, moved = 0;
  for (int s = 0; s < 20000; ++s) {
    with_plane.step();
    with_mesh.step();
    worst = std::max(worst, worst_difference(with_plane, with_mesh));
  }
  for (std::size_t i = 0; i < 9; ++i)
    moved = std::max(moved, (with_mesh.particles().pos[i] - pile()[i].position).norm());
  std::printf("tilting floor, 20000 steps: spheres moved up to %.2e m, mesh vs plane %.2e m\n",
              moved, worst);
  EXPECT_GT(moved, 1e-4);  // they rolled down the tilted floor (0.3 mm)
  EXPECT_LT(worst, 1e-12);
}

// A servo on a mesh acts on the force summed over all its triangles: a two-triangle lid in YADE's
// layout (two walls, one body) holds the stress a plane lid with the same servo holds, and moves
// like it.
TEST(MeshMotion, ServoOnAMeshUsesTheForceOfTheWholeMesh) {
  auto c = config();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.damping = 0.2;
  auto servo = [](solver::WallSpec& w) {
    w.servo_stress_Pa = 400;
    w.servo_area_m2 = 1e-4;
    w.servo_gain = 1e-5;
    w.servo_max_velocity = 0.05;
  };
  // Floor plane at z = 0, lid from above.
  solver::WallSpec floor;
  floor.shape = solver::WallShape::Plane;
  floor.normal = Eigen::Vector3d::UnitZ();
  solver::WallSpec lid = floor;
  lid.center = Eigen::Vector3d(0, 0, 2.2e-3);
  lid.normal = -Eigen::Vector3d::UnitZ();
  servo(lid);
  MeshTriangles down = square(0.05);
  for (auto& t : down.triangles) {
    for (auto& v : t) v.z() = 2.2e-3;
    std::swap(t[1], t[2]);  // normal −z
  }
  auto mesh = solver::mesh_walls(down, MeshContact::Merged);
  ASSERT_EQ(mesh.size(), 1u);
  auto parity = solver::mesh_walls(down, MeshContact::YadeParity);
  ASSERT_EQ(parity.size(), 2u);
  for (auto* ws : {&mesh, &parity})
    for (auto& w : *ws) {
      servo(w);
      w.normal = -Eigen::Vector3d::UnitZ();
      w.body = 0;
    }
  std::vector<solver::WallSpec> with_mesh_walls{floor}, with_parity_walls{floor};
  for (auto& w : mesh) with_mesh_walls.push_back(w);
  for (auto& w : parity) with_parity_walls.push_back(w);
  solver::Simulation a(c, pile(), {floor, lid}), b(c, pile(), with_mesh_walls),
      y(c, pile(), with_parity_walls);
  for (int s = 0; s < 40000; ++s) {
    a.step();
    b.step();
    y.step();
  }
  const double stress_plane = -a.walls()[1].force.dot(-Eigen::Vector3d::UnitZ()) / 1e-4;
  double fz = 0;
  for (std::size_t w = 1; w < 3; ++w) fz += y.walls()[w].force.z();
  const double stress_parity = fz / 1e-4;
  std::printf(
      "servo lid: plane %.2f Pa at z = %.6e m, merged mesh at %.6e m (diff %.1e m), "
      "YADE-layout mesh %.2f Pa at %.6e m\n",
      stress_plane, a.walls()[1].pos.z(), b.walls()[1].pos.z(), worst_difference(a, b),
      stress_parity, y.walls()[1].pos.z());
  EXPECT_NEAR(stress_plane, 400, 4);
  EXPECT_LT(worst_difference(a, b), 1e-12);
  EXPECT_NEAR(b.walls()[1].pos.z(), a.walls()[1].pos.z(), 1e-12);
  // The two triangles of the YADE layout move together and hold the target together (stiffer
  // contacts, 4/3·Ec·R: a different lid height, the same stress).
  EXPECT_EQ(y.walls()[1].pos.z(), y.walls()[2].pos.z());
  EXPECT_NEAR(stress_parity, 400, 4);
}

// Switched off at t: the sphere resting on it falls freely from then on.
TEST(MeshMotion, SwitchedOffMeshLetsTheSphereFall) {
  auto c = config();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  auto walls = solver::mesh_walls(square(0.01), MeshContact::Merged);
  const double t_off = 2000 * c.dt;
  for (auto& w : walls) w.off_at_s = t_off - 0.5 * c.dt;
  solver::Simulation sim(c, {sphere(0, {0, 0, 0.999e-3}, 1e-3)}, walls);
  for (int s = 0; s < 2000; ++s) sim.step();
  EXPECT_FALSE(sim.walls()[0].active);
  const double z0 = sim.particles().pos[0].z(), v0 = sim.particles().vel[0].z();
  const int n = 3000;
  for (int s = 0; s < n; ++s) sim.step();
  // Leapfrog under constant g: v_n = v0 − n·g·dt, z_n = z0 + n·dt·v0 − n(n+1)/2·g·dt².
  const double dt = c.dt, g = 9.81;
  const double z = z0 + n * dt * v0 - 0.5 * n * (n + 1.0) * g * dt * dt;
  EXPECT_NEAR(sim.particles().pos[0].z(), z, 1e-15);
  EXPECT_EQ(sim.contact_count(), 0u);
}

// Per-facet forces sum to the wall's force, on the facet the sphere touches; a group's torque is
// taken about the rotation centre.
TEST(MeshMotion, PerFacetForcesAndGroupTorque) {
  auto c = config();
  auto walls = solver::mesh_walls(square(0.01), MeshContact::Merged);
  const Eigen::Vector3d centre(0.001, 0, 0);
  for (auto& w : walls) w.rotation_center = centre;
  // Inside the first triangle (x > y), pressed 10 µm into the floor.
  const Eigen::Vector3d x(0.003, -0.002, 1e-3 - 1e-5);
  solver::Simulation sim(c, {sphere(0, x, 1e-3)}, walls);
  sim.set_facet_forces(true);
  sim.step();
  const auto& w = sim.walls()[0];
  ASSERT_EQ(w.facet_force.size(), 2u);
  EXPECT_EQ(w.facet_force[1], Eigen::Vector3d::Zero());
  EXPECT_EQ(w.facet_force[0], w.force);
  EXPECT_NEAR(w.force.z(), -1e6 * 1e-3 * 1e-5, 1e-12);  // Kn = Ec·R, pushed down
  const auto g = solver::group_forces(sim).at(0);
  // The force acts at the contact point below the centre: torque (p − c) × F about the centre.
  const Eigen::Vector3d p(x.x(), x.y(), 0);
  const Eigen::Vector3d expect = (p - centre).cross(g.force);
  EXPECT_LT((g.torque - expect).norm(), 1e-15);
}

// A rotating mesh resumes from a checkpoint bit for bit.
TEST(MeshMotion, RotatingMeshCheckpointResumesBitForBit) {
  auto c = config();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  auto walls = solver::mesh_walls(square(0.05), MeshContact::Merged);
  for (auto& w : walls) {
    w.angular_velocity = Eigen::Vector3d(0.5, 1.0, 0.2);
    w.rotation_center = Eigen::Vector3d(0.002, 0, 0);
    w.velocity = Eigen::Vector3d(0, 0, 1e-3);
  }
  solver::Simulation a(c, pile(), walls), b(c, pile(), walls);
  for (int s = 0; s < 3000; ++s) a.step();
  const auto ck = std::filesystem::temp_directory_path() / "gs_mesh_motion_ck.bin";
  a.save_checkpoint(ck);
  solver::Simulation r(c, pile(), walls);
  r.load_checkpoint(ck);
  std::filesystem::remove(ck);
  for (int s = 0; s < 3000; ++s) b.step();
  for (int s = 0; s < 3000; ++s) {
    a.step();
    r.step();
  }
  for (std::size_t i = 0; i < 9; ++i) {
    EXPECT_EQ(a.particles().pos[i], r.particles().pos[i]);
    EXPECT_EQ(a.particles().vel[i], r.particles().vel[i]);
  }
  EXPECT_EQ(a.walls()[0].pos, r.walls()[0].pos);
  EXPECT_EQ(a.walls()[0].facets[1].vertex[2].eigen(), r.walls()[0].facets[1].vertex[2].eigen());
}

// The engine looks only at the walls that move (or have moved since the last neighbour-list
// build), that carry a servo or a switch-off time, or that were loaded in the last step; the
// others stand still and carry no load. Against a twin that rebuilds its list every step (every
// wall looked at every step): the same bits, while a mesh floor of many walls is lifted by
// set_wall_velocity, stops, a side wall is moved through mutable_walls(), and a switch-off time
// passes.
TEST(MeshMotion, StillWallsLeftOutOfTheStepChangeNoResult) {
  auto c = config();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.damping = 0.1;
  auto floor = solver::mesh_walls(square(0.05), MeshContact::YadeParity);  // two walls, one body
  ASSERT_EQ(floor.size(), 2u);
  solver::WallSpec side;
  side.shape = solver::WallShape::Plane;
  side.center = Eigen::Vector3d(-3.4e-3, 0, 0);
  side.normal = Eigen::Vector3d::UnitX();
  solver::WallSpec gone = side;  // a far wall that switches off half-way
  gone.center = Eigen::Vector3d(0, 3.4e-3, 0);
  gone.normal = -Eigen::Vector3d::UnitY();
  gone.off_at_s = 2500 * c.dt;
  std::vector<solver::WallSpec> walls = floor;
  walls.push_back(side);
  walls.push_back(gone);
  solver::Simulation sim(c, pile(), walls), twin(c, pile(), walls);
  const Eigen::Vector3d up(0, 0, 0.02);
  bool side_touched = false;
  for (int s = 0; s < 5000; ++s) {
    for (auto* x : {&sim, &twin}) {
      if (s == 1000)
        for (std::size_t w = 0; w < 2; ++w) x->set_wall_velocity(w, up);
      if (s == 2000)
        for (std::size_t w = 0; w < 2; ++w) x->set_wall_velocity(w, Eigen::Vector3d::Zero());
      if (s == 3000) x->mutable_walls()[2].pos.x() += 2.5e-4;  // 50 µm into the pile
      if (x == &twin) x->invalidate_neighbors();
      x->step();
    }
    for (std::size_t i = 0; i < sim.particles().size(); ++i)
      ASSERT_EQ(sim.particles().pos[i], twin.particles().pos[i]) << "step " << s;
    for (std::size_t w = 0; w < walls.size(); ++w) {
      ASSERT_EQ(sim.walls()[w].pos, twin.walls()[w].pos) << "step " << s;
      ASSERT_EQ(sim.walls()[w].force, twin.walls()[w].force) << "step " << s;
    }
    side_touched = side_touched || sim.walls()[2].force != Eigen::Vector3d::Zero();
  }
  EXPECT_NEAR(sim.walls()[0].pos.z(), 0.02 * 1000 * c.dt, 1e-15);  // lifted 40 µm, then still
  EXPECT_FALSE(sim.walls()[3].active);
  EXPECT_TRUE(side_touched);  // the moved side wall pushed the pile
  EXPECT_EQ(sim.energy().wall_work, twin.energy().wall_work);
  EXPECT_GT(std::abs(sim.energy().wall_work), 0);
}
