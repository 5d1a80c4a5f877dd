// Invariants of stress and deformation with known eigen-structure (seed 003 eq 11–12, 17, App. 1–2)
// and the Kanatani fabric (eq 18–21): exact anisotropies and the sampling error of isotropy.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "fabric.hpp"
#include "tensor_invariants.hpp"

namespace ga = gs::analysis;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

Eigen::Matrix3d rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(StressInvariants, Eq17RoundTripWithRotatedAxes) {
  // Build sigma from p, eta and the Lode angle by eq 17, rotate it, and get them back.
  const double p = 500e3, eta = 0.8;
  const Eigen::Matrix3d r = rotation(0.3, -1.1, 0.7);
  for (double theta_deg : {0.0, 17.0, 30.0, 45.0, 60.0}) {
    const double t = theta_deg * kDeg;
    const Eigen::Vector3d s(p * (1 + 2.0 / 3 * eta * std::cos(t)),
                            p * (1 + 2.0 / 3 * eta * std::cos(2 * std::numbers::pi / 3 - t)),
                            p * (1 + 2.0 / 3 * eta * std::cos(2 * std::numbers::pi / 3 + t)));
    const Eigen::Matrix3d sigma = r * s.asDiagonal() * r.transpose();
    const auto inv = ga::stress_invariants(sigma);
    EXPECT_NEAR(inv.p, p, 1e-9 * p);
    EXPECT_NEAR(inv.eta, eta, 1e-12);
    EXPECT_NEAR(inv.q, eta * p, 1e-9 * p);
    EXPECT_NEAR(inv.lode_deg, theta_deg, 1e-9) << theta_deg;
    const double b = 2 * std::tan(t) / (std::sqrt(3.0) + std::tan(t));  // tan t = sqrt3 b/(2-b)
    if (theta_deg > 0) {
      EXPECT_NEAR(inv.b, b, 1e-12) << theta_deg;
    }
    EXPECT_NEAR((inv.principal - s).norm(), 0.0, 1e-9 * p);
    EXPECT_NEAR(std::sin(inv.phi_mob_deg * kDeg), (s[0] - s[2]) / (s[0] + s[2]), 1e-12);
    // Principal directions: the rotated axes (up to sign) where the values are distinct.
    if (theta_deg > 0 && theta_deg < 60) {
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(std::abs(inv.directions.col(k).dot(r.col(k))), 1.0, 1e-9) << k;
    }
    EXPECT_NEAR(inv.asymmetry, 0.0, 1e-15);
  }
}

TEST(StressInvariants, HandValuesTwoDAndAsymmetry) {
  const auto inv = ga::stress_invariants(Eigen::Vector3d(3, 2, 1).asDiagonal());
  EXPECT_DOUBLE_EQ(inv.p, 2.0);
  EXPECT_NEAR(inv.q, std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(inv.b, 0.5, 1e-15);
  EXPECT_NEAR(inv.lode_deg, 30.0, 1e-12);
  EXPECT_NEAR(inv.phi_mob_deg, 30.0, 1e-12);  // sin = (3 - 1)/(3 + 1)
  EXPECT_NEAR(inv.j2d, 1.0, 1e-15);           // ((1)^2 + 0 + (-1)^2) / 2
  Eigen::Matrix3d a = Eigen::Vector3d(3, 2, 1).asDiagonal();
  a(0, 1) = 1.0;  // skew part 0.5
  const auto ia = ga::stress_invariants(a);
  EXPECT_NEAR(ia.asymmetry, std::sqrt(0.5) / a.norm(), 1e-15);  // skew part [[0, .5], [-.5, 0]]
  const auto i2 = ga::stress_invariants(Eigen::Vector3d(3, 1, 7).asDiagonal(), 2);
  EXPECT_DOUBLE_EQ(i2.p, 2.0);
  EXPECT_DOUBLE_EQ(i2.q, 1.0);
  EXPECT_NEAR(i2.phi_mob_deg, 30.0, 1e-12);
  EXPECT_TRUE(std::isnan(i2.b));
  // Isotropic: b and the Lode angle undefined, q = 0.
  const auto iso = ga::stress_invariants(5.0 * Eigen::Matrix3d::Identity());
  EXPECT_DOUBLE_EQ(iso.q, 0.0);
  EXPECT_TRUE(std::isnan(iso.b));
  EXPECT_DOUBLE_EQ(iso.phi_mob_deg, 0.0);
}

TEST(StrainInvariants, KnownStretchRotationAndAppendix2) {
  const Eigen::Vector3d lambda(0.93, 1.04, 0.98);  // principal stretches
  const Eigen::Matrix3d q = rotation(0.4, 0.2, -0.9), r = rotation(-0.3, 0.5, 0.1);
  const Eigen::Matrix3d u = q * lambda.asDiagonal() * q.transpose();
  const auto e = ga::strain_invariants(r * u);
  const double j = lambda.prod();
  EXPECT_NEAR(e.J, j, 1e-14);
  EXPECT_NEAR(e.eps_v, 1.0 - j, 1e-14);  // eq 11
  EXPECT_NEAR((e.U - u).norm(), 0.0, 1e-13);
  EXPECT_NEAR((e.R - r).norm(), 0.0, 1e-13);
  EXPECT_NEAR((e.Fv * e.Fd - r * u).norm(), 0.0, 1e-14);  // eq 12
  EXPECT_NEAR(e.Fd.determinant(), 1.0, 1e-14);
  // Biot strain 1 - U, principal values in decreasing order: 1 - 0.93, 1 - 0.98, 1 - 1.04.
  EXPECT_NEAR((e.principal - Eigen::Vector3d(0.07, 0.02, -0.04)).norm(), 0.0, 1e-13);
  EXPECT_NEAR(std::abs(e.directions.col(0).dot(q.col(0))), 1.0, 1e-12);
  EXPECT_NEAR(e.b_eps, (0.02 + 0.04) / (0.07 + 0.04), 1e-12);
  EXPECT_NEAR(e.b_stretch, 1.0 - e.b_eps, 1e-12);
  const Eigen::Vector3d ud = lambda / std::cbrt(j);
  const double mean = ud.sum() / 3;
  const double j2d = 0.5 * (ud.array() - mean).square().sum();
  EXPECT_NEAR(e.eps_q, 2 * std::sqrt(j2d / 3), 1e-14);
  // App. 2 rebuilds the principal deviatoric stretches from eps_q and b_F (eq 23–26).
  Eigen::Vector3d sorted = ud;
  std::sort(sorted.data(), sorted.data() + 3, std::greater<>());
  EXPECT_NEAR((ga::deviatoric_stretch(e.eps_q, e.b_stretch) - sorted).norm(), 0.0, 1e-13);
  // Isochoric pure shear: J = 1, eps_v = 0.
  EXPECT_NEAR(ga::strain_invariants(Eigen::Vector3d(1.1, 1.0, 1 / 1.1).asDiagonal()).eps_v, 0.0,
              1e-15);
  EXPECT_THROW(ga::strain_invariants(Eigen::Vector3d(1, 1, -1).asDiagonal()),
               std::invalid_argument);
  EXPECT_THROW(ga::strain_invariants(Eigen::Matrix3d::Constant(std::nan(""))),
               std::invalid_argument);
}

TEST(Fabric, AlignedNormalsGiveTheExactAnisotropy) {
  // 100 contacts along +-z among 40 particles: M = 2 * 100 / 40 e_z e_z, omega = 5,
  // D = 15/2 (diag(0, 0, 1) - I/3) = diag(-2.5, -2.5, 5) (eq 20–21).
  std::vector<Eigen::Vector3d> n;
  for (int k = 0; k < 100; ++k) n.push_back((k % 2 ? -1.0 : 1.0) * Eigen::Vector3d::UnitZ());
  const auto f = ga::contact_fabric(n, 40, 3);
  EXPECT_NEAR(f.omega, 5.0, 1e-15);
  EXPECT_NEAR((f.D - Eigen::Vector3d(-2.5, -2.5, 5).asDiagonal().toDenseMatrix()).norm(), 0.0,
              1e-14);
  EXPECT_NEAR(f.D_principal[0], 5.0, 1e-14);
  EXPECT_NEAR(std::abs(f.D_directions.col(0).z()), 1.0, 1e-14);
  // 2D: along x: D = 4 (diag(1, 0) - I/2) = diag(2, -2).
  std::vector<Eigen::Vector3d> n2(10, Eigen::Vector3d::UnitX());
  const auto f2 = ga::contact_fabric(n2, 10, 2);
  EXPECT_NEAR(f2.omega, 2.0, 1e-15);
  EXPECT_NEAR(f2.D(0, 0), 2.0, 1e-15);
  EXPECT_NEAR(f2.D(1, 1), -2.0, 1e-15);
  EXPECT_THROW(ga::contact_fabric({}, 10, 3), std::invalid_argument);
  EXPECT_THROW(ga::contact_fabric(n, 0, 3), std::invalid_argument);
}

TEST(Fabric, UniformNormalsHaveAnisotropyWithinTheSamplingError) {
  // For N uniform normals E|D|^2 = 37.5 / N (3D) and 8 / N (2D): the mean of N |D|^2 / 37.5
  // over 200 samples is 1 within its standard error sqrt(2/5) / sqrt(200) = 0.045 (0.05 in 2D);
  // tested at 4 standard errors. One sample stays below 3 sqrt(37.5 / N).
  std::mt19937_64 rng(21);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 2000, reps = 200;
  double m3 = 0.0, m2 = 0.0;
  for (int rep = 0; rep < reps; ++rep) {
    std::vector<Eigen::Vector3d> v3, v2;
    for (int k = 0; k < n; ++k) {
      v3.emplace_back(g(rng), g(rng), g(rng));
      v2.emplace_back(g(rng), g(rng), 0.0);
    }
    const auto f3 = ga::contact_fabric(v3, 1000, 3);
    const auto f2 = ga::contact_fabric(v2, 1000, 2);
    EXPECT_LT(f3.D_norm, 3 * std::sqrt(37.5 / n));
    EXPECT_NEAR(f3.omega, 2.0 * n / 1000, 1e-12);
    m3 += n * f3.D_norm * f3.D_norm / 37.5 / reps;
    m2 += n * f2.D_norm * f2.D_norm / 8.0 / reps;
  }
  EXPECT_NEAR(m3, 1.0, 4 * std::sqrt(0.4 / reps));
  EXPECT_NEAR(m2, 1.0, 4 * std::sqrt(1.0 / reps));  // 2 components: var of chi2_2/2 is 1
}

TEST(Fabric, ClumpOrientation) {
  // Two-sphere clumps (centre distance 1.4 r as in seed 003 §2.4), all along x except one.
  gs::Frame f;
  for (int c = 0; c < 4; ++c)
    for (int m = 0; m < 2; ++m) {
      gs::Particle p;
      p.id = 2 * c + m;
      p.radius = 1e-3;
      p.clump_id = c;
      const Eigen::Vector3d axis = c < 3 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      p.position = Eigen::Vector3d(0.01 * c, 0, 0) + (m ? 0.7e-3 : -0.7e-3) * axis;
      f.particles.push_back(p);
    }
  gs::Particle single;  // not in a clump
  single.id = 99;
  single.radius = 1e-3;
  f.particles.push_back(single);
  const auto o = ga::orientation_fabric(f);
  ASSERT_EQ(o.bodies, 4u);
  EXPECT_NEAR(o.Phi(0, 0), 0.75, 1e-14);
  EXPECT_NEAR(o.Phi(1, 1), 0.25, 1e-14);
  EXPECT_NEAR(o.D(0, 0), 7.5 * (0.75 - 1.0 / 3), 1e-13);
  EXPECT_NEAR(std::abs(o.axis[0].x()), 1.0, 1e-14);
  EXPECT_EQ(ga::orientation_fabric(gs::Frame{}).bodies, 0u);
}

// A clump body whose long axis (the principal axis of its smallest moment, body x) points along
// `axis` in the lab frame: a two-sphere clump's inertia ordering, I_x < I_y = I_z.
gs::Clump body_along(std::int64_t id, const Eigen::Vector3d& axis,
                     const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
  gs::Clump c;
  c.id = id;
  c.template_name = "dimer";
  c.position = centre;
  c.orientation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), axis);
  c.mass = 1e-5;
  c.principal_inertia = {2e-12, 5e-12, 5e-12};
  return c;
}

// Seed 003 §4.3 (D^p by eq 20–21 over the bodies' long axes): all long axes along x give
// Phi = diag(1, 0, 0) and D^p = 15/2 (Phi - I/3) = diag(5, -2.5, -2.5) exactly, |D^p| =
// sqrt(37.5); in 2D 4 (Phi - I/2) = diag(2, -2). Axes equally along x, y and z (the discrete
// isotropic set) give Phi = I/3 and D^p = 0. A body whose smallest moment is not distinct (one
// sphere) has no long axis and is left out.
TEST(Fabric, ClumpBodyOrientationExactValues) {
  std::vector<gs::Clump> aligned;
  for (int i = 0; i < 6; ++i) {
    const double sign = i % 2 ? -1.0 : 1.0;  // m and -m are the same orientation
    aligned.push_back(body_along(i, sign * Eigen::Vector3d::UnitX()));
  }
  gs::Clump round = body_along(99, Eigen::Vector3d::UnitY());
  round.principal_inertia = {4e-12, 4e-12, 4e-12};
  aligned.push_back(round);
  EXPECT_FALSE(ga::clump_long_axis(round).has_value());
  const auto o = ga::body_orientation_fabric(aligned, 3);
  EXPECT_EQ(o.source, ga::OrientationSource::Bodies);
  ASSERT_EQ(o.bodies, 6u);
  const Eigen::Matrix3d want = Eigen::Vector3d(5.0, -2.5, -2.5).asDiagonal();
  EXPECT_LT((o.D - want).norm(), 1e-14) << o.D;
  EXPECT_NEAR(o.D_norm, std::sqrt(37.5), 1e-14);
  EXPECT_NEAR(o.Phi.trace(), 1.0, 1e-15);
  const auto o2 = ga::body_orientation_fabric(aligned, 2);
  const Eigen::Matrix3d want2 = Eigen::Vector3d(2.0, -2.0, 0.0).asDiagonal();
  EXPECT_LT((o2.D - want2).norm(), 1e-14) << o2.D;

  std::vector<gs::Clump> iso;
  const Eigen::Vector3d dirs[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ()};
  for (int i = 0; i < 9; ++i) iso.push_back(body_along(i, dirs[i % 3]));
  const auto oi = ga::body_orientation_fabric(iso, 3);
  ASSERT_EQ(oi.bodies, 9u);
  EXPECT_LT(oi.D.norm(), 1e-14) << oi.D;
  EXPECT_LT((oi.Phi - Eigen::Matrix3d::Identity() / 3.0).norm(), 1e-15);
  // The long axis is the body's principal axis of the smallest moment, whichever column it is.
  gs::Clump z = body_along(5, Eigen::Vector3d::UnitX());
  z.principal_inertia = {5e-12, 5e-12, 2e-12};  // body z the long axis -> lab z
  z.orientation = Eigen::Quaterniond::Identity();
  EXPECT_LT((ga::clump_long_axis(z).value() - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
}

// For two-sphere clumps (seed 003 §2.4: centre distance 1.4 r) the body path (smallest principal
// moment) and the member path (largest volume second moment) give the same axes and the same
// D^p, for 50 random orientations; orientation_fabric prefers the bodies when the frame has them.
TEST(Fabric, ClumpBodyAndMemberOrientationAgreeForTwoSphereClumps) {
  std::mt19937_64 rng(14);
  std::normal_distribution<double> g(0.0, 1.0);
  gs::Frame f;
  const double r = 1e-3;
  for (int c = 0; c < 50; ++c) {
    const Eigen::Vector3d axis = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    const Eigen::Vector3d centre = Eigen::Vector3d(0.01 * c, 0.002 * (c % 7), 0.0);
    gs::Clump body = body_along(1000 + c, axis, centre);
    // A dimer's inertia: about its axis 2 * 2/5 m r^2; across it that plus 2 m (0.7 r)^2.
    const double m = 0.5 * body.mass;
    body.principal_inertia = {2 * 0.4 * m * r * r, 2 * 0.4 * m * r * r + 2 * m * 0.49 * r * r,
                              2 * 0.4 * m * r * r + 2 * m * 0.49 * r * r};
    f.clumps.push_back(body);
    for (int k = 0; k < 2; ++k) {
      gs::Particle p;
      p.id = 2 * c + k;
      p.radius = r;
      p.clump_id = body.id;
      p.position = centre + (k ? 0.7 : -0.7) * r * axis;
      f.particles.push_back(p);
    }
  }
  const auto bodies = ga::orientation_fabric(f);
  EXPECT_EQ(bodies.source, ga::OrientationSource::Bodies);
  const auto members = ga::member_orientation_fabric(f);
  EXPECT_EQ(members.source, ga::OrientationSource::Members);
  ASSERT_EQ(bodies.bodies, 50u);
  ASSERT_EQ(members.bodies, 50u);
  for (std::size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(bodies.clump[i], members.clump[i]);
    EXPECT_NEAR(std::abs(bodies.axis[i].dot(members.axis[i])), 1.0, 1e-12) << i;
    EXPECT_LT((bodies.centroid[i] - members.centroid[i]).norm(), 1e-15) << i;
  }
  EXPECT_LT((bodies.D - members.D).norm(), 1e-11) << bodies.D << "\n" << members.D;
  EXPECT_GT(bodies.D_norm, 0.0);
  f.clumps.clear();  // imported data: clump_id without bodies
  EXPECT_EQ(ga::orientation_fabric(f).source, ga::OrientationSource::Members);
  EXPECT_EQ(ga::orientation_fabric(gs::Frame{}).source, ga::OrientationSource::None);
}

}  // namespace
