// Triangle-mesh walls: YADE's facet contact cases, the edge artefact of YADE's layout, and the
// merged default (one contact per sphere and flat region, plane-wall stiffness) against the
// analytic walls it approximates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "mesh_walls.hpp"
#include "simulation.hpp"

using namespace gs;
using solver::MeshContact;
using solver::MeshTriangles;

namespace {

solver::SimulationConfig config(double young = 3e7) {
  solver::SimulationConfig c;
  c.material.young_ec = young;
  c.material.stiffness_ratio = 0.3;
  c.material.friction_deg = 30;
  c.material.density = 2500;
  c.dt = 1e-7;
  return c;
}

Particle sphere(std::int64_t id, Eigen::Vector3d x, double r) {
  Particle p;
  p.id = id;
  p.position = x;
  p.radius = r;
  return p;
}

/// The square [0, a]² in the plane z = 0 as an n × n grid of squares, each split along a
/// diagonal (alternating), normals +z.
MeshTriangles flat_square(double a, int n) {
  MeshTriangles m;
  const double h = a / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3d p00(i * h, j * h, 0), p10((i + 1) * h, j * h, 0),
          p01(i * h, (j + 1) * h, 0), p11((i + 1) * h, (j + 1) * h, 0);
      if ((i + j) % 2 == 0) {
        m.triangles.push_back({p00, p10, p11});
        m.triangles.push_back({p00, p11, p01});
      } else {
        m.triangles.push_back({p00, p10, p01});
        m.triangles.push_back({p10, p11, p01});
      }
      m.group.push_back("floor");
      m.group.push_back("floor");
    }
  return m;
}

double total_fz(const solver::Simulation& sim) {
  double f = 0;
  for (const auto& w : sim.walls()) f += w.force.z();
  return f;
}

}  // namespace

// Exact answers (README of ../shared/reference/yade/facets): with R = 1 mm, un = 10 µm and the
// centre 42 µm from the diagonal of a square split in two triangles, YADE's layout gives a face
// contact (Kn = 4/3·Ec·R: 0.400 N) plus an edge contact with the other triangle at distance
// √((R − un)² + d²) from the centre: Kn·(R − that)·cos — 0.764 N in all; the merged default
// gives the one plane-wall contact, Ec·R·un = 0.300 N, the force of an infinite plane.
TEST(MeshWalls, InternalEdgeDoublesYadesForceAndNotTheMergedOne) {
  const double r = 1e-3, un = 1e-5, d = 42e-6, ec = 3e7;
  MeshTriangles sq;
  sq.triangles = {
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d(0.01, 0.01, 0)},
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.01, 0.01, 0), Eigen::Vector3d(0, 0.01, 0)}};
  sq.group = {"sq", "sq"};
  // 42 µm from the diagonal x = y, on the side of the first triangle (x > y).
  const Eigen::Vector3d x(0.005 + d / std::sqrt(2.0), 0.005 - d / std::sqrt(2.0), r - un);
  auto force = [&](MeshContact mode) {
    solver::Simulation sim(config(ec), {sphere(0, x, r)}, solver::mesh_walls(sq, mode));
    sim.step();
    return std::make_pair(total_fz(sim), sim.contact_count());
  };
  const double kn_yade = 2.0 * ec * (2 * r) * ec * r / (ec * (2 * r) + ec * r);
  const double l = r - un, dist = std::sqrt(l * l + d * d);
  const double expected_yade = kn_yade * un + kn_yade * (r - dist) * (l / dist);
  const auto [f_yade, n_yade] = force(MeshContact::YadeParity);
  EXPECT_EQ(n_yade, 2u);
  EXPECT_NEAR(-f_yade, expected_yade, 1e-12 * expected_yade);  // (force on the walls is −z)
  EXPECT_NEAR(-f_yade, 0.764, 0.001);
  const auto [f_merged, n_merged] = force(MeshContact::Merged);
  EXPECT_EQ(n_merged, 1u);
  EXPECT_NEAR(-f_merged, ec * r * un, 1e-12 * ec * r * un);
  // The same sphere on an infinite plane.
  solver::WallSpec plane;
  plane.shape = solver::WallShape::Plane;
  plane.normal = Eigen::Vector3d::UnitZ();
  solver::Simulation sp(config(ec), {sphere(0, x, r)}, {plane});
  sp.step();
  EXPECT_NEAR(f_merged, sp.walls()[0].force.z(), 1e-15 * std::abs(f_merged));
}

// Exact answers for YADE's three contact cases of one facet (Ig2_Facet_Sphere_ScGeom): face
// (penetration R − L along the normal, from either side), edge (closest point on the edge) and
// vertex (the vertex), with the contact point R − un/2 back from the centre.
TEST(MeshWalls, FaceEdgeAndVertexContactsOfOneFacet) {
  const Eigen::Vector3d a(0, 0, 0), b(3e-3, 0, 0), c(0, 4e-3, 0);
  const auto f = solver::make_triangle_facet(a, b, c, solver::incircle_centre(a, b, c));
  EXPECT_NEAR(f.incircle_radius, 1e-3, 1e-18);  // 3-4-5 triangle: r = (3 + 4 − 5)/2 mm
  EXPECT_NEAR(f.area, 6e-6, 1e-20);
  const solver::V3 w(solver::incircle_centre(a, b, c));
  const double r = 1e-3;
  auto geom = [&](Eigen::Vector3d x) {
    solver::ContactGeometry g;
    solver::facet_sphere_geometry(f, w, solver::V3(x), r, false, g);
    return g;
  };
  // Face, from below (two-sided): normal −z.
  auto g = geom({1e-3, 1e-3, -0.9e-3});
  EXPECT_NEAR(g.penetration, 0.1e-3, 1e-18);
  EXPECT_NEAR(g.normal.z, -1.0, 1e-15);
  EXPECT_NEAR(g.point.z, -0.9e-3 + (r - 0.05e-3), 1e-18);
  EXPECT_EQ(g.radius1, 2 * r);
  // Edge a–b (y = 0), centre at y = −0.6 mm, z = 0.6 mm: distance √0.72 mm.
  g = geom({1.5e-3, -0.6e-3, 0.6e-3});
  EXPECT_NEAR(g.penetration, r - std::sqrt(0.72) * 1e-3, 1e-17);
  EXPECT_NEAR(g.normal.y, -std::sqrt(0.5), 1e-14);
  // Vertex b, centre 0.5 mm beyond it along x.
  g = geom({3.5e-3, -0.0e-3, 0.5e-3});
  EXPECT_NEAR(g.penetration, r - std::sqrt(0.5) * 1e-3, 1e-17);
  EXPECT_NEAR(g.normal.x, std::sqrt(0.5), 1e-14);
  EXPECT_THROW(solver::make_triangle_facet(a, b, 2 * b, a), std::invalid_argument);  // zero area
}

// Exact answer: on a flat mesh (16 squares, 32 triangles, vertices where 4 and 8 triangles meet)
// a sphere rolling under gravity at constant height crosses edges and vertices with the normal
// force of the plane, m·g, unchanged to round-off in the merged default; YADE's layout jumps at
// every internal edge.
TEST(MeshWalls, RollingAcrossEdgesAndVerticesFeelsNoJump) {
  const double r = 1e-3;
  const MeshTriangles floor = flat_square(8e-3, 4);
  auto run = [&](MeshContact mode) {
    auto c = config(1e7);
    c.gravity = Eigen::Vector3d(0, 0, -9.81);
    c.dt = 1e-6;
    c.damping = 0;
    Particle p = sphere(0, {0.3e-3, 0.5e-3, r}, r);
    solver::Simulation sim(c, {p}, solver::mesh_walls(floor, mode));
    // Settle, then roll along the diagonal (through the vertices of the grid) at 0.5 m/s.
    const double m = sim.particles().mass[0];
    sim.particles().pos[0].z() = r - m * 9.81 / (c.material.young_ec * r);  // resting overlap
    sim.particles().vel[0] = Eigen::Vector3d(0.35, 0.35, 0);
    sim.particles().angvel[0] = Eigen::Vector3d(-0.35, 0.35, 0) / r;  // rolling, no slip
    double fmin = HUGE_VAL, fmax = 0;
    std::size_t max_contacts = 0;
    for (int s = 0; s < 30000 && sim.particles().pos[0].x() < 7.5e-3; ++s) {
      sim.step();
      fmin = std::min(fmin, -total_fz(sim));
      fmax = std::max(fmax, -total_fz(sim));
      max_contacts = std::max(max_contacts, sim.contact_count());
    }
    EXPECT_GT(sim.particles().pos[0].x(), 7e-3);  // crossed the mesh diagonally
    return std::make_tuple(fmin, fmax, max_contacts, m * 9.81);
  };
  const auto [lo, hi, contacts, weight] = run(MeshContact::Merged);
  std::printf("merged: normal force within [%.3e, %.3e] of m g\n", lo / weight - 1,
              hi / weight - 1);
  EXPECT_EQ(contacts, 1u);
  EXPECT_NEAR(lo, weight, 1e-9 * weight);
  EXPECT_NEAR(hi, weight, 1e-9 * weight);
  const auto [ylo, yhi, ycontacts, yweight] = run(MeshContact::YadeParity);
  std::printf("YADE layout: normal force from %.3f to %.3f m g, up to %zu contacts\n",
              ylo / yweight, yhi / yweight, ycontacts);
  EXPECT_GT(ycontacts, 1u);
  EXPECT_GT(yhi, 1.5 * yweight);  // the edge artefact
}

// Exact answer: a cube of 12 triangles (merged default) is, for spheres inside it, the six
// planes through its faces: the same trajectories to round-off (the two geometries compute the
// same distances in a different order of operations).
TEST(MeshWalls, TwelveTriangleBoxGivesThePlaneWallsTrajectories) {
  const double a = 10e-3;
  MeshTriangles box;
  const Eigen::Vector3d v[8] = {{0, 0, 0}, {a, 0, 0}, {a, a, 0}, {0, a, 0},
                                {0, 0, a}, {a, 0, a}, {a, a, a}, {0, a, a}};
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  for (const auto& q : quads) {
    box.triangles.push_back({v[q[0]], v[q[1]], v[q[2]]});
    box.triangles.push_back({v[q[0]], v[q[2]], v[q[3]]});
    box.group.push_back("box");
    box.group.push_back("box");
  }
  std::vector<solver::WallSpec> planes;
  const Eigen::Vector3d lo(0, 0, 0), hi(a, a, a);
  for (int k = 0; k < 3; ++k)
    for (int side = 0; side < 2; ++side) {
      solver::WallSpec w;
      w.shape = solver::WallShape::Plane;
      w.center = side == 0 ? lo : hi;
      w.normal = Eigen::Vector3d::Zero();
      w.normal[k] = side == 0 ? 1 : -1;
      planes.push_back(w);
    }
  std::vector<Particle> ps;
  std::uint32_t seed = 7;
  auto rnd = [&] { return (seed = seed * 1664525u + 1013904223u) / 4294967296.0; };
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k) {
        Particle p =
            sphere(static_cast<std::int64_t>(ps.size()),
                   {1.6e-3 + 2.2e-3 * i, 1.6e-3 + 2.2e-3 * j, 1.6e-3 + 2.2e-3 * k}, 0.8e-3);
        p.velocity = {rnd() - 0.5, rnd() - 0.5, rnd() - 0.5};
        ps.push_back(p);
      }
  auto c = config(1e6);
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.dt = 2e-6;
  c.damping = 0.05;
  c.max_overlap_ratio = 1.0;
  solver::Simulation with_planes(c, ps, planes),
      with_mesh(c, ps, solver::mesh_walls(box, MeshContact::Merged));
  ASSERT_EQ(with_mesh.walls().size(), 6u);  // six flat regions
  double worst = 0;
  std::size_t wall_contacts = 0;
  for (int s = 0; s < 5000; ++s) {
    with_planes.step();
    with_mesh.step();
    for (std::size_t i = 0; i < ps.size(); ++i)
      worst =
          std::max(worst, (with_planes.particles().pos[i] - with_mesh.particles().pos[i]).norm());
    wall_contacts += with_mesh.contact_count() - with_mesh.sphere_contact_count();
  }
  std::printf("5000 steps, %zu sphere-wall contact-steps: largest position difference %.2e m\n",
              wall_contacts, worst);
  EXPECT_GT(wall_contacts, 1000u);
  EXPECT_LT(worst, 1e-12);
}
