// Seed 003's tangential polyhedron (App. 3) and its walls under an imposed F (§2.1.2, Eqs 4-9),
// against exact answers: the cube for n = 4, the counts, tangency and convexity for n = 4..10,
// the paper's n = 8 figures (volume 4.797 R³, circumscribed radius 1.1589 R), and a homogeneous
// F recovered from the face polygons (Eq 4) to round-off.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <utility>

#include "simulation.hpp"
#include "tangential_polyhedron.hpp"

namespace {

using gs::solver::TangentialPolyhedron;

double circumradius(const TangentialPolyhedron& P) {
  double r = 0.0;
  for (const auto& v : P.vertices) r = std::max(r, v.norm());
  return r;
}

// Closed form of the circumscribed radius: the vertices of layer i are at height
// R cos a / cos ϖ and horizontal radius R sin a / cos² ϖ, a = (2i - 1) ϖ; the largest is the
// layer nearest the equator.
double circumradius_formula(int n, double R) {
  const double w = std::numbers::pi / n, c = std::cos(w);
  double r = 0.0;
  for (int i = 1; i <= n / 2; ++i) {
    const double a = (2 * i - 1) * w;
    r = std::max(r, R * std::hypot(std::cos(a) / c, std::sin(a) / (c * c)));
  }
  return r;
}

}  // namespace

TEST(TangentialPolyhedron, FourSidesIsTheCube) {
  const double R = 0.0066;
  const TangentialPolyhedron P = gs::solver::tangential_polyhedron(4, R);
  ASSERT_EQ(P.vertices.size(), 8u);
  ASSERT_EQ(P.faces.size(), 6u);
  for (const auto& v : P.vertices)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::abs(v[k]), R, 1e-15);
  EXPECT_NEAR(gs::solver::polyhedron_volume(P.vertices, P.faces), 8 * R * R * R, 1e-20);
  EXPECT_NEAR(circumradius(P), std::sqrt(3.0) * R, 1e-16);
}

TEST(TangentialPolyhedron, CountsTangencyAndConvexityForEvenN) {
  const double R = 1.0;
  for (const int n : {4, 6, 8, 10, 12}) {
    SCOPED_TRACE(n);
    const TangentialPolyhedron P = gs::solver::tangential_polyhedron(n, R);
    // App. 3: n²/2 vertices, (n/2 - 1) n side walls and two end walls.
    ASSERT_EQ(P.vertices.size(), static_cast<std::size_t>(n * n / 2));
    ASSERT_EQ(P.faces.size(), static_cast<std::size_t>((n / 2 - 1) * n + 2));
    std::set<std::pair<int, int>> edges;
    for (std::size_t f = 0; f < P.faces.size(); ++f) {
      const auto& face = P.faces[f];
      std::vector<Eigen::Vector3d> p;
      for (const int k : face) p.push_back(P.vertices[static_cast<std::size_t>(k)]);
      const auto m = gs::solver::polygon_measure(p);
      // Planar, outward (counter-clockwise from outside), tangent to the sphere at its tangent
      // point, which lies inside the face.
      EXPECT_NEAR((m.normal - P.normals[f]).norm(), 0.0, 1e-14);
      for (const auto& x : p) EXPECT_NEAR(x.dot(P.normals[f]), R, 1e-14);
      EXPECT_NEAR((P.tangent[f] - R * P.normals[f]).norm(), 0.0, 1e-15);
      for (std::size_t k = 0; k < p.size(); ++k) {
        const Eigen::Vector3d edge = p[(k + 1) % p.size()] - p[k];
        EXPECT_GT(edge.cross(P.tangent[f] - p[k]).dot(P.normals[f]), 0.0);
        const int a = face[k], b = face[(k + 1) % face.size()];
        edges.insert({std::min(a, b), std::max(a, b)});
      }
      // Convex: every vertex on the inner side of every face's plane.
      for (const auto& v : P.vertices) EXPECT_LE(v.dot(P.normals[f]), R * (1 + 1e-14));
    }
    // Euler's formula of a closed convex polyhedron, and each edge shared by exactly two faces.
    const auto V = static_cast<long>(P.vertices.size()), E = static_cast<long>(edges.size()),
               F = static_cast<long>(P.faces.size());
    EXPECT_EQ(V - E + F, 2);
    std::map<std::pair<int, int>, int> uses;
    for (const auto& face : P.faces)
      for (std::size_t k = 0; k < face.size(); ++k) {
        const int a = face[k], b = face[(k + 1) % face.size()];
        ++uses[{a, b}];  // directed: an edge runs both ways in its two faces
      }
    for (const auto& [e, count] : uses) {
      EXPECT_EQ(count, 1);
      EXPECT_EQ(uses.count({e.second, e.first}), 1u);
    }
    // End walls: regular n-gons of side 2 R tan² ϖ (App. 3 (c)) at z = ±R.
    const double w = std::numbers::pi / n;
    const auto& top = P.faces[P.faces.size() - 2];
    for (std::size_t k = 0; k < top.size(); ++k) {
      const auto& a = P.vertices[static_cast<std::size_t>(top[k])];
      const auto& b = P.vertices[static_cast<std::size_t>(top[(k + 1) % top.size()])];
      EXPECT_NEAR((a - b).norm(), 2 * R * std::pow(std::tan(w), 2), 1e-14);
      EXPECT_NEAR(a.z(), R, 1e-15);
    }
    EXPECT_NEAR(circumradius(P), circumradius_formula(n, R), 1e-14);
    // The volume lies between the inscribed sphere's and the circumscribed one's.
    const double vol = gs::solver::polyhedron_volume(P.vertices, P.faces);
    EXPECT_GT(vol, 4.0 / 3.0 * std::numbers::pi * R * R * R);
    EXPECT_LT(vol, 4.0 / 3.0 * std::numbers::pi * std::pow(circumradius(P), 3));
  }
}

TEST(TangentialPolyhedron, ThePapersEightSides) {
  // Seed 003 §2.4 (n = 8, R = 6.6 mm): 32 vertices, 26 walls, volume 4.797 R³, circumscribed
  // radius 1.1589 R (the figures issue 19 quotes, to their printed digits).
  const double R = 6.6e-3;
  const TangentialPolyhedron P = gs::solver::tangential_polyhedron(8, R);
  EXPECT_EQ(P.vertices.size(), 32u);
  EXPECT_EQ(P.faces.size(), 26u);
  EXPECT_NEAR(gs::solver::polyhedron_volume(P.vertices, P.faces) / (R * R * R), 4.797, 5e-4);
  EXPECT_NEAR(circumradius(P) / R, 1.1589, 5e-5);
}

TEST(TangentialPolyhedron, HomogeneousDeformationIsRecoveredFromTheFaces) {
  // Eq 4 on the faces' area centres, the vertices mapped by F, and again through the walls'
  // planes moved as Eqs 5-7 say (vertices rebuilt as the planes' intersections).
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (const int n : {4, 6, 8, 10}) {
    SCOPED_TRACE(n);
    const TangentialPolyhedron P = gs::solver::tangential_polyhedron(n, 6.6e-3);
    for (int trial = 0; trial < 5; ++trial) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) F(i, j) += u(rng);
      ASSERT_GT(F.determinant(), 0.0);
      std::vector<Eigen::Vector3d> x;
      for (const auto& X : P.vertices) x.push_back(F * X);
      EXPECT_LT((gs::solver::deformation_gradient_from_faces(P, x) - F).norm(), 1e-12);
      const auto walls = gs::solver::wall_motions(P, Eigen::Matrix3d::Identity(), F, 1.0);
      const auto moved = gs::solver::wall_motions(P, F, F, 1.0);
      std::vector<Eigen::Vector3d> point, normal;
      for (const auto& m : moved) {
        point.push_back(m.centre);
        normal.push_back(m.normal);
        EXPECT_NEAR(m.velocity.norm(), 0.0, 1e-18);
        EXPECT_NEAR(m.angular_velocity.norm(), 0.0, 1e-15);
      }
      const auto rebuilt = gs::solver::vertices_from_planes(P, point, normal);
      for (std::size_t k = 0; k < x.size(); ++k) EXPECT_LT((rebuilt[k] - x[k]).norm(), 1e-15);
      EXPECT_LT((gs::solver::deformation_gradient_from_faces(P, rebuilt) - F).norm(), 1e-12);
      // Eq 8: the centre's velocity from the identity carries it to F X_o in one unit step;
      // Eq 9: the spin turns the reference normal towards Eq 7's (|n x n_t| = sin of the angle).
      for (std::size_t w = 0; w < walls.size(); ++w) {
        EXPECT_LT((P.tangent[w] + walls[w].velocity - moved[w].centre).norm(), 1e-15);
        const double s = P.normals[w].cross(moved[w].normal).norm();
        EXPECT_NEAR(walls[w].angular_velocity.norm(), s, 1e-15);
        EXPECT_NEAR(walls[w].angular_velocity.dot(P.normals[w]), 0.0, 1e-15);
      }
    }
  }
}

TEST(TangentialPolyhedron, BadSidesOrRadiusAreRejected) {
  for (const int n : {-2, 0, 2, 3, 5, 9})
    EXPECT_THROW(gs::solver::tangential_polyhedron(n, 1.0), std::invalid_argument) << n;
  for (const double R : {0.0, -1.0, std::nan("")})
    EXPECT_THROW(gs::solver::tangential_polyhedron(8, R), std::invalid_argument) << R;
}

TEST(TangentialPolyhedron, EngineWallsFollowAnImposedDeformationPath) {
  // The 26 walls of the n = 8 polyhedron as the engine's plane walls, driven step by step along
  // F(t) = I + t H (stretch, shear and spin at once) for 2000 steps; Eq 4 on the walls' planes
  // gives F(t) back at every check to round-off, and the one sphere at the centre, touching
  // nothing, stays put.
  const TangentialPolyhedron P = gs::solver::tangential_polyhedron(8, 6.6e-3);
  gs::solver::SimulationConfig cfg;
  cfg.dt = 1e-6;
  cfg.material.young_ec = 1e7;
  cfg.material.stiffness_ratio = 0.3;
  cfg.material.friction_deg = 30;
  cfg.material.density = 2700;
  gs::Particle p;
  p.radius = 1e-4;
  gs::solver::Simulation sim(cfg, {p}, gs::solver::polyhedron_walls(P));
  ASSERT_EQ(sim.walls().size(), 26u);
  EXPECT_LT(
      (gs::solver::polyhedron_deformation_gradient(sim, 0, P) - Eigen::Matrix3d::Identity()).norm(),
      1e-14);
  Eigen::Matrix3d H;
  H << -0.10, 0.04, 0.02, -0.03, 0.05, 0.01, 0.06, -0.02, -0.08;
  const int steps = 2000;
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + (double(k) / steps) * H;
    gs::solver::drive_polyhedron(sim, 0, P, F, cfg.dt);
    sim.step();
    if (k % 500 == 0) {
      SCOPED_TRACE(k);
      EXPECT_LT((gs::solver::polyhedron_deformation_gradient(sim, 0, P) - F).norm(), 1e-12);
      for (const auto& w : sim.walls()) EXPECT_NEAR(w.normal.norm(), 1.0, 1e-15);
    }
  }
  EXPECT_EQ(sim.particles().pos[0], Eigen::Vector3d::Zero());
  EXPECT_EQ(sim.contact_count(), 0u);
}

TEST(TangentialPolyhedron, Eq17StatesHaveTheirInvariantsAndDirections) {
  // p, q = η p, b and the major direction back from the tensor, for states along the path.
  for (const double eta : {0.0, 0.5, 0.9})
    for (const double b : {0.0, 0.5, 1.0})
      for (const double deg : {0.0, 30.0, 90.0, 135.0}) {
        SCOPED_TRACE(eta);
        SCOPED_TRACE(b);
        SCOPED_TRACE(deg);
        const double p = 5e5, alpha = deg * std::numbers::pi / 180;
        const Eigen::Matrix3d s = gs::solver::principal_stress_state(p, eta, b, alpha);
        EXPECT_NEAR((s - s.transpose()).norm(), 0.0, 1e-9);
        EXPECT_NEAR(s.trace() / 3, p, 1e-9 * p);
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(s);
        const Eigen::Vector3d v = e.eigenvalues();  // ascending: σ3, σ2, σ1
        const double q =
            std::sqrt(0.5 * ((v[2] - v[1]) * (v[2] - v[1]) + (v[1] - v[0]) * (v[1] - v[0]) +
                             (v[2] - v[0]) * (v[2] - v[0])));
        EXPECT_NEAR(q, eta * p, 1e-9 * p);
        if (eta > 0) {
          EXPECT_NEAR((v[1] - v[0]) / (v[2] - v[0]), b, 1e-12);
          const Eigen::Vector3d n1 = e.eigenvectors().col(2);
          if (b < 1.0) {  // (b = 1: σ1 = σ2, the major direction is not unique)
            const Eigen::Vector3d major(std::cos(alpha), 0, std::sin(alpha));
            EXPECT_NEAR(std::abs(n1.dot(major)), 1.0, 1e-12);
          }
        }
        // σ2 acts along y: y is a principal direction whatever α.
        EXPECT_NEAR(s(0, 1), 0.0, 1e-9);
        EXPECT_NEAR(s(2, 1), 0.0, 1e-9);
      }
}

TEST(TangentialPolyhedron, CarvingKeepsWholeSpheresAndWholeClumps) {
  const double R = 6.6e-3, r = 0.4e-3;
  const TangentialPolyhedron P = gs::solver::tangential_polyhedron(8, R);
  std::vector<Eigen::Vector3d> x;
  std::vector<double> rad;
  std::vector<std::int64_t> clump;
  // Dimers along x on a grid through and beyond the polyhedron (members 1.4 r apart).
  std::int64_t c = 0;
  for (double gx = -9e-3; gx <= 9e-3; gx += 1.5e-3)
    for (double gy = -9e-3; gy <= 9e-3; gy += 1.1e-3)
      for (double gz = -9e-3; gz <= 9e-3; gz += 1.1e-3, ++c)
        for (const double dx : {-0.7 * r, 0.7 * r}) {
          x.emplace_back(gx + dx, gy, gz);
          rad.push_back(r);
          clump.push_back(c);
        }
  const auto spheres = gs::solver::carve_polyhedron(P, x, rad);
  const auto clumps = gs::solver::carve_polyhedron(P, x, rad, clump);
  std::vector<std::uint8_t> kept(x.size(), 0);
  for (const auto k : spheres) kept[k] = 1;
  for (std::size_t k = 0; k < x.size(); ++k) {
    // Kept: every point of the sphere inside every face; gone: some point outside some face.
    double reach = -1e9;
    for (const auto& n : P.normals) reach = std::max(reach, x[k].dot(n) + rad[k] - R);
    EXPECT_EQ(kept[k] == 1, reach <= 0.0) << k;
  }
  // Whole clumps: both members kept or both gone, and only clumps whose members both fit.
  std::vector<std::uint8_t> kc(x.size(), 0);
  for (const auto k : clumps) kc[k] = 1;
  std::size_t both = 0;
  for (std::size_t k = 0; k + 1 < x.size(); k += 2) {
    EXPECT_EQ(kc[k], kc[k + 1]);
    EXPECT_EQ(kc[k] == 1, kept[k] == 1 && kept[k + 1] == 1);
    both += kc[k];
  }
  EXPECT_GT(both, 100u);
  EXPECT_LT(clumps.size(), spheres.size());
}
