// The periodic cell against exact answers: affine motion of a contact-free assembly, a pair
// touching across a face against the same pair inside the cell, bit-for-bit resumption, 2D
// emulation, and the cell's error cases.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "packing_csv.hpp"
#include "periodic_case.hpp"
#include "reference_case.hpp"
#include "simulation.hpp"

using namespace gs;
using solver::Simulation;

namespace {

solver::SimulationConfig config(double damping = 0.2) {
  solver::SimulationConfig c;
  c.material = test::periodic_material();
  c.damping = damping;
  c.dt = 2e-6;
  return c;
}

Particle sphere(std::int64_t id, const Eigen::Vector3d& x, double r) {
  Particle p;
  p.id = id;
  p.position = x;
  p.radius = r;
  return p;
}

Eigen::Matrix3d cube(double side) {
  return side * Eigen::Matrix3d::Identity();
}

}  // namespace

// x_n = (I + dt·L)^n·x_0 and v_n = L·x_{n−1} exactly for YADE's scheme (the mean field enters
// as ΔL·x in the first step, then as the convective term L·v); the cell follows one step late:
// H_n = (I + dt·L)^{n−1}·H_0; spins are W's axial vector.
TEST(PeriodicCell, ContactFreeAssemblyMovesAffinely) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 0.02);
  std::vector<Particle> ps;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)  // on a 6.67 mm grid with jitter, radius 0.5 mm: no contact
        ps.push_back(
            sphere(static_cast<int>(ps.size()),
                   Eigen::Vector3d(0.0033 + i * 0.0067, 0.0033 + j * 0.0067, 0.0033 + k * 0.0067) +
                       Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.02,
                   0.0005));
  Simulation sim(config(0.3), ps, {});
  Eigen::Matrix3d hsize;
  hsize << 0.02, 0.002, 0, 0, 0.021, 0.001, 0, 0, 0.019;  // a sheared cell
  sim.set_periodic(hsize);
  Eigen::Matrix3d l;
  l << 0.5, 2.0, -0.3, -0.4, -0.2, 0.7, 0.1, 0.6, 0.3;
  sim.set_velocity_gradient(l);
  const double dt = sim.config().dt;
  const Eigen::Matrix3d step_map = Eigen::Matrix3d::Identity() + dt * l;
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();  // (I + dt·L)^n
  const Eigen::Matrix3d w = 0.5 * (l - l.transpose());
  const Eigen::Vector3d spin(-w(1, 2), w(0, 2), -w(0, 1));
  double worst_x = 0, worst_v = 0, worst_h = 0;
  std::vector<Eigen::Vector3d> prev(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) prev[i] = ps[i].position;
  for (int n = 1; n <= 2000; ++n) {
    const Eigen::Matrix3d f_prev = f;
    sim.step();
    f = step_map * f;
    const auto& p = sim.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
      worst_x = std::max(worst_x, (p.pos[i] - f * ps[i].position).norm() / 0.02);
      worst_v = std::max(worst_v, (p.vel[i] - l * prev[i]).norm() / (l.norm() * 0.02));
      EXPECT_LT((p.angvel[i] - spin).norm(), 1e-14 * spin.norm()) << "step " << n;
      prev[i] = p.pos[i];
    }
    worst_h = std::max(worst_h, (sim.cell().hsize - f_prev * hsize).norm() / hsize.norm());
    ASSERT_EQ(sim.contact_count(), 0u);
  }
  EXPECT_LT(worst_x, 1e-12) << "positions relative to the cell size";  // (2000 steps of ulps)
  EXPECT_LT(worst_v, 1e-12) << "velocities relative to |L|·L_cell";
  EXPECT_LT(worst_h, 1e-12) << "cell one step behind";
  // The frame holds the cell and the positions wrapped into it.
  const Frame fr = sim.frame();
  EXPECT_TRUE(fr.domain.periodic);
  EXPECT_EQ(fr.domain.cell, sim.cell().hsize);
  const Eigen::Matrix3d inv = sim.cell().hsize.inverse();
  for (const auto& q : fr.particles) {
    const Eigen::Vector3d s = inv * q.position;
    EXPECT_TRUE((s.array() >= -1e-12).all() && (s.array() < 1 + 1e-12).all()) << s.transpose();
  }
}

namespace {

/// The loads of a two-sphere run in a 10 mm cube with v_y = 100/s·x (the pair's branch along x,
/// so the mean field shears the contact while the overlap pushes the spheres apart): x1, x2 are
/// the unwrapped centres.
struct PairRun {
  std::vector<Eigen::Vector3d> force1, torque1;
  std::vector<std::size_t> contacts;
};

PairRun run_pair(const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  Simulation sim(config(0.0), {sphere(0, x1, 0.001), sphere(1, x2, 0.001)}, {});
  sim.set_periodic(cube(0.01));
  Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
  l(1, 0) = 100.0;
  sim.set_velocity_gradient(l);
  PairRun r;
  for (int n = 0; n < 40; ++n) {
    sim.step();
    r.contacts.push_back(sim.contact_count());
    r.force1.push_back(sim.particles().force[0]);
    r.torque1.push_back(sim.particles().torque[0]);
  }
  return r;
}

}  // namespace

// Across the x faces the image of sphere 2 moves with its own velocity plus L·H·cellDist; the
// contact must see what the same pair sees inside the cell (round-off of the positions apart).
TEST(PeriodicCell, PairAcrossBoundaryFeelsTheSameForceAsInside) {
  const PairRun inside = run_pair({0.00403, 0.005, 0.005}, {0.00597, 0.005, 0.005});
  // (sphere 1's image at 10.97 mm: the same branch, +1.94 mm along x, as inside)
  const PairRun across = run_pair({0.00903, 0.005, 0.005}, {0.00097, 0.005, 0.005});
  EXPECT_EQ(inside.contacts, across.contacts);
  ASSERT_EQ(inside.contacts.at(5), 1u);
  double fmax = 0, worst = 0, shear = 0, tmax = 0, worst_t = 0;
  for (std::size_t n = 0; n < inside.force1.size(); ++n) {
    fmax = std::max(fmax, inside.force1[n].norm());
    worst = std::max(worst, (across.force1[n] - inside.force1[n]).norm());
    worst_t = std::max(worst_t, (across.torque1[n] - inside.torque1[n]).norm());
    tmax = std::max(tmax, inside.torque1[n].norm());
    shear = std::max(shear, std::abs(inside.force1[n].y()));
  }
  EXPECT_GT(shear, 1e-3 * fmax) << "the mean field shears the contact";
  EXPECT_LT(worst, 1e-9 * fmax) << "force across the boundary";
  EXPECT_LT(worst_t, 1e-9 * tmax) << "torque across the boundary";
}

TEST(PeriodicCell, ResumesBitForBit) {
  // The dense packing of the shared YADE case (tests/data/yade_periodic), sheared and compressed.
  const auto ps = read_packing_csv(test::reference_case_dir("periodic") / "packing.csv").particles;
  Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
  l(0, 2) = 20.0;
  l.diagonal().setConstant(-1.0);
  auto make = [&] {
    auto sim = std::make_unique<Simulation>(config(), ps, std::vector<solver::WallSpec>{});
    sim->set_periodic(cube(0.019384323656096786));
    sim->set_velocity_gradient(l);
    return sim;
  };
  auto a = make();
  a->run(300);
  const auto ckpt = std::filesystem::temp_directory_path() / "gs_periodic_resume.ckpt";
  a->save_checkpoint(ckpt);
  a->run(300);
  auto b = make();
  b->load_checkpoint(ckpt);
  b->run(300);
  std::filesystem::remove(ckpt);
  ASSERT_GT(a->contact_count(), 2000u);
  EXPECT_EQ(a->cell().hsize, b->cell().hsize);
  EXPECT_EQ(a->cell_stress(), b->cell_stress());
  for (std::size_t i = 0; i < ps.size(); ++i) {
    EXPECT_EQ(a->particles().pos[i], b->particles().pos[i]) << i;
    EXPECT_EQ(a->particles().vel[i], b->particles().vel[i]) << i;
    EXPECT_EQ(a->particles().angvel[i], b->particles().angvel[i]) << i;
  }
}

TEST(PeriodicCell, PlanarEmulationKeepsTheDisksInThePlane) {
  // The packing of the shared YADE 2D case (tests/data/yade_periodic2d), sheared and compressed.
  const auto ps =
      read_packing_csv(test::reference_case_dir("periodic2d") / "packing.csv").particles;
  Simulation sim(config(), ps, {});
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  h.diagonal() << 0.04783235800060865, 0.04783235800060865, 0.008;
  sim.set_periodic(h, true);
  Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
  l(0, 0) = -2;
  l(1, 1) = -2;
  l(0, 1) = 5;
  sim.set_velocity_gradient(l);
  sim.run(1000);
  ASSERT_GT(sim.contact_count(), 1000u);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    EXPECT_EQ(sim.particles().pos[i].z(), 0.004);
    EXPECT_EQ(sim.particles().vel[i].z(), 0.0);
    EXPECT_EQ(sim.particles().angvel[i].x(), 0.0);
    EXPECT_EQ(sim.particles().angvel[i].y(), 0.0);
  }
  EXPECT_TRUE(sim.frame().two_d);
  // A non-planar packing, a velocity gradient out of the plane.
  auto bad = ps;
  bad[7].position.z() = 0.0041;
  Simulation off(config(), bad, {});
  EXPECT_THROW(off.set_periodic(h, true), std::invalid_argument);
  Eigen::Matrix3d lz = Eigen::Matrix3d::Zero();
  lz(0, 2) = 1;
  EXPECT_THROW(sim.set_velocity_gradient(lz), std::invalid_argument);
}

TEST(PeriodicCell, RejectsDegenerateInvertedAndTooSmallCells) {
  const std::vector<Particle> ps = {sphere(0, {0.002, 0.002, 0.002}, 0.001),
                                    sphere(1, {0.006, 0.006, 0.006}, 0.001)};
  Simulation s1(config(), ps, {});
  Eigen::Matrix3d singular = cube(0.01);
  singular.col(2) = singular.col(0);
  EXPECT_THROW(s1.set_periodic(singular), std::invalid_argument);
  Eigen::Matrix3d inverted = cube(0.01);
  inverted(2, 2) = -0.01;
  EXPECT_THROW(s1.set_periodic(inverted), std::invalid_argument);
  // 3·(2·r_max + skin) = 3·(2 + 0.5) mm = 7.5 mm: a 7 mm cell is too small, 8 mm is fine.
  EXPECT_THROW(s1.set_periodic(cube(0.007)), solver::PeriodicTooSmall);
  EXPECT_NO_THROW(s1.set_periodic(cube(0.008)));
  Simulation s2(config(), ps, {solver::WallSpec{}});
  EXPECT_THROW(s2.set_periodic(cube(0.01)), std::invalid_argument);  // walls
  Simulation s3(config(), ps, {});
  EXPECT_THROW(s3.set_velocity_gradient(Eigen::Matrix3d::Identity()), std::invalid_argument);
}

// Two axes held at a stress while the third is compressed at a constant rate: the held axes
// come to their target and stay within 2 % of it, the rate axis deforms exactly at its rate
// (H_zz(n) = (1 + dt·rate)^(n−1)·H_zz(0), the cell one step behind as for any gradient), and no
// stress axis ever exceeds the rate limit.
TEST(PeriodicCell, ServoHoldsStressAxesAndDrivesRateAxes) {
  const auto ps = read_packing_csv(test::reference_case_dir("periodic") / "packing.csv").particles;
  auto cfg = config(0.2);
  cfg.dt = 2.58e-6;
  Simulation sim(cfg, ps, {});
  const double side = 0.019384323656096786;
  sim.set_periodic(cube(side));
  solver::CellServo servo;
  servo.stress = {true, true, false};
  servo.target = {-1.2e5, -1.2e5, -0.5};
  servo.gain = 2e-4;  // (steady error ≈ the lateral rate needed / gain ≈ 0.25/2e-4 = 1.3 kPa)
  servo.max_rate = 0.5;
  sim.set_cell_servo(servo);
  double worst_rate = 0, worst_late = 0;
  double hzz = side;
  for (int n = 1; n <= 6000; ++n) {
    sim.step();
    if (n >= 2) hzz += cfg.dt * -0.5 * hzz;  // (the gradient set before step 1 is current then)
    EXPECT_EQ(sim.cell().hsize(2, 2), hzz) << "step " << n;
    for (int i = 0; i < 2; ++i)
      worst_rate = std::max(worst_rate, std::abs(sim.cell().vel_grad(i, i)));
    if (n > 4000) {
      const Eigen::Matrix3d s = sim.cell_stress();
      for (int i = 0; i < 2; ++i)
        worst_late = std::max(worst_late, std::abs(s(i, i) - servo.target[i]) / 1.2e5);
    }
  }
  EXPECT_LE(worst_rate, servo.max_rate);
  EXPECT_LT(worst_late, 0.02) << "stress axes within 2 % of the target over the last 2000 steps";
  EXPECT_EQ(sim.cell().hsize(0, 1), 0.0);  // (no off-diagonal gradient was set)
  servo.gain = -1;
  EXPECT_THROW(sim.set_cell_servo(servo), std::invalid_argument);
}

// True disks: m = ρ·π·r²·t, I = m·r²/2, Kn = Ec·t. Two equal disks meeting head on (no damping,
// no friction work: a central impact) stay in contact for half a period of the reduced mass on
// Kn, π·sqrt(m/(2·Kn)), and leave with the speed they came with.
TEST(PeriodicCell, DisksHaveDiskMassInertiaAndLineStiffness) {
  const double r = 0.001, t = 0.004, v0 = 0.05;
  auto a = sphere(0, {0.004, 0.005, 0.002}, r);
  auto b = sphere(1, {0.00601, 0.005, 0.002}, r);
  a.velocity = {v0, 0, 0};
  b.velocity = {-v0, 0, 0};
  auto cfg = config(0.0);
  cfg.dt = 1e-7;
  Simulation sim(cfg, {a, b}, {});
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  h.diagonal() << 0.012, 0.012, t;
  sim.set_periodic(h, true);
  sim.set_disks(t);
  const double m = 2550.0 * M_PI * r * r * t;
  EXPECT_NEAR(sim.particles().mass[0], m, 1e-15 * m);
  EXPECT_NEAR(sim.particles().inertia[0], 0.5 * m * r * r, 1e-15 * m * r * r);
  int first = -1, last = -1;
  for (int n = 1; n <= 20000; ++n) {
    sim.step();
    if (sim.contact_count() == 1) {
      if (first < 0) first = n;
      last = n;
    }
  }
  ASSERT_GT(first, 0);
  const double kn = 3.0e7 * t;
  const double duration = M_PI * std::sqrt(0.5 * m / kn);
  EXPECT_NEAR((last - first + 1) * cfg.dt, duration, 2 * cfg.dt);
  EXPECT_NEAR(sim.particles().vel[0].x(), -v0, 1e-6 * v0);
  EXPECT_NEAR(sim.particles().vel[1].x(), v0, 1e-6 * v0);
  Simulation not_planar(cfg, {a, b}, {});
  not_planar.set_periodic(cube(0.012));
  EXPECT_THROW(not_planar.set_disks(t), std::invalid_argument);
}

// The sums are the same for any number of threads (pair order, per particle): one and two
// threads give the same bits on the dense shared packing under shear.
TEST(PeriodicCell, ThreadCountDoesNotChangeABit) {
  const auto ps = read_packing_csv(test::reference_case_dir("periodic") / "packing.csv").particles;
  Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
  l(0, 2) = 5.0;
  auto run = [&](int threads) {
    auto cfg = config();
    cfg.threads = threads;
    auto sim = std::make_unique<Simulation>(cfg, ps, std::vector<solver::WallSpec>{});
    sim->set_periodic(cube(0.019384323656096786));
    sim->set_velocity_gradient(l);
    sim->run(300);
    return sim;
  };
  const auto one = run(1), two = run(2);
  ASSERT_GT(one->contact_count(), 2000u);
  EXPECT_EQ(one->cell_stress(), two->cell_stress());
  for (std::size_t i = 0; i < ps.size(); ++i) {
    EXPECT_EQ(one->particles().pos[i], two->particles().pos[i]) << i;
    EXPECT_EQ(one->particles().angvel[i], two->particles().angvel[i]) << i;
  }
}

// K_ii = (1/V) Σ l_i² (kn n_i² + ks (1 − n_i²)) by hand for one pair of disks touching at 30°
// to x (kn = Ec·t, ks = νc·kn): the servo's stiffness is the affine modulus of the contacts.
TEST(PeriodicCell, CellStiffnessIsTheAffineModulusOfTheContacts) {
  const double r = 0.001, t = 0.004, gap = -2e-6;  // 2 µm overlap
  const double th = M_PI / 6, d = 2 * r + gap;
  const Eigen::Vector3d c1(0.004, 0.005, 0.002);
  const Eigen::Vector3d c2 = c1 + d * Eigen::Vector3d(std::cos(th), std::sin(th), 0);
  auto cfg = config(0.0);
  cfg.dt = 1e-8;
  Simulation sim(cfg, {sphere(0, c1, r), sphere(1, c2, r)}, {});
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  h.diagonal() << 0.012, 0.012, t;
  sim.set_periodic(h, true);
  sim.set_disks(t);
  sim.step();
  ASSERT_EQ(sim.contact_count(), 1u);
  const double kn = 3.0e7 * t, ks = 0.3 * kn, v = 0.012 * 0.012 * t;
  const Eigen::Vector3d l = sim.particles().pos[0] - sim.particles().pos[1];
  const Eigen::Vector3d n = -l.normalized();  // (the normal points from 1 to 2; squared below)
  for (int i = 0; i < 3; ++i) {
    const double want = l[i] * l[i] * (kn * n[i] * n[i] + ks * (1 - n[i] * n[i])) / v;
    EXPECT_NEAR(sim.cell_stiffness()[i], want, 1e-12 * std::abs(want) + 1e-30) << i;
  }
  EXPECT_GT(sim.cell_stiffness()[0], 0.0);
  EXPECT_EQ(sim.cell_stiffness()[2], 0.0);  // (no branch along z)
}

// The stiffness-scaled servo (fraction f of the error per step from the affine stiffness)
// brings two axes of the dense YADE packing to their target without a tuned gain and holds
// them within 1 % while the third axis is compressed; the servo (and its base gradient) is in
// the checkpoint, so a run resumed in a Simulation that never set one continues bit for bit.
TEST(PeriodicCell, StiffnessScaledServoHoldsTheTargetAndResumesBitForBit) {
  const auto ps = read_packing_csv(test::reference_case_dir("periodic") / "packing.csv").particles;
  auto cfg = config(0.2);
  cfg.dt = 2.58e-6;
  const double side = 0.019384323656096786;
  auto make = [&] {
    auto sim = std::make_unique<Simulation>(cfg, ps, std::vector<solver::WallSpec>{});
    sim->set_periodic(cube(side));
    return sim;
  };
  auto a = make();
  solver::CellServo servo;
  servo.stress = {true, true, false};
  servo.target = {-1.2e5, -1.2e5, -0.5};
  servo.stiffness_fraction = 0.3;
  servo.max_rate = 0.5;
  a->set_cell_servo(servo);
  double worst_late = 0;
  for (int n = 1; n <= 3000; ++n) {
    a->step();
    if (n > 2000) {
      const Eigen::Matrix3d s = a->cell_stress();
      for (int i = 0; i < 2; ++i)
        worst_late = std::max(worst_late, std::abs(s(i, i) - servo.target[i]) / 1.2e5);
    }
  }
  EXPECT_LT(worst_late, 0.01) << "stress axes within 1 % over steps 2000–3000";
  const auto ckpt = std::filesystem::temp_directory_path() / "gs_periodic_servo.ckpt";
  a->save_checkpoint(ckpt);
  a->run(200);
  auto b = make();  // (no servo set: it comes from the checkpoint)
  b->load_checkpoint(ckpt);
  ASSERT_TRUE(b->cell_servo().has_value());
  EXPECT_EQ(b->cell_servo()->stiffness_fraction, 0.3);
  b->run(200);
  std::filesystem::remove(ckpt);
  EXPECT_EQ(a->cell().hsize, b->cell().hsize);
  EXPECT_EQ(a->cell().vel_grad, b->cell().vel_grad);
  for (std::size_t i = 0; i < ps.size(); ++i)
    EXPECT_EQ(a->particles().pos[i], b->particles().pos[i]) << i;
  servo.stiffness_fraction = 1.5;
  EXPECT_THROW(a->set_cell_servo(servo), std::invalid_argument);
}

// A rattler spinning alone keeps its energy (nothing damps a free body); the equilibrium checks
// of a cell count only the bodies in contact: exactly the kinetic energy of the touching pair.
TEST(PeriodicCell, KineticEnergyInContactLeavesTheRattlersOut) {
  const double r = 0.001, t = 0.004;
  auto a = sphere(0, {0.004, 0.005, 0.002}, r);
  auto b = sphere(1, {0.005999, 0.005, 0.002}, r);
  auto c = sphere(2, {0.009, 0.009, 0.002}, r);
  a.velocity = {0.01, 0, 0};
  c.angular_velocity = {0, 0, 30.0};
  auto cfg = config(0.3);
  cfg.dt = 1e-7;
  Simulation sim(cfg, {a, b, c}, {});
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  h.diagonal() << 0.012, 0.012, t;
  sim.set_periodic(h, true);
  sim.set_disks(t);
  for (int n = 0; n < 50; ++n) sim.step();
  ASSERT_EQ(sim.contact_count(), 1u);
  const auto& p = sim.particles();
  double pair = 0;
  for (int i = 0; i < 2; ++i)
    pair +=
        0.5 * p.mass[i] * p.vel[i].squaredNorm() + 0.5 * p.inertia[i] * p.angvel[i].squaredNorm();
  const double spin = 0.5 * p.inertia[2] * p.angvel[2].squaredNorm();
  EXPECT_EQ(p.angvel[2].z(), 30.0);  // (undamped: no force, no damping)
  EXPECT_NEAR(sim.kinetic_energy_in_contact(), pair, 1e-15 * pair);
  EXPECT_NEAR(sim.kinetic_energy(), pair + spin, 1e-15 * (pair + spin));
}

// A frame's velocities are a field over its wrapped positions: a free sphere moving through the
// z face of a cell sheared along x by z (the flow differs by 20/s · 10 mm across it) has, in the
// frame, the same fluctuation about the mean flow at its wrapped position as the engine's about the
// flow at its unwrapped one.
TEST(PeriodicCell, FrameVelocitiesFollowTheWrappedPositions) {
  auto cfg = config(0.0);
  cfg.dt = 1e-5;
  auto s0 = sphere(0, {0.005, 0.005, 0.0095}, 0.0005);
  s0.velocity = {0, 0, 0.5};  // up through the z face: its image is shifted by H·(0, 0, −1)
  Simulation sim(cfg, {s0}, {});
  sim.set_periodic(cube(0.01));
  Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
  l(0, 2) = 20.0;  // v_x = 20/s · z
  sim.set_velocity_gradient(l);
  for (int n = 0; n < 1000; ++n) sim.step();  // 5 mm along z
  const auto& p = sim.particles();
  const Frame f = sim.frame();
  const Eigen::Vector3d xw = f.particles[0].position;
  const Eigen::Vector3d sw = f.domain.cell.inverse() * xw;
  EXPECT_GT((p.pos[0] - xw).norm(), 0.005) << "the sphere has left the cell (unwrapped)";
  EXPECT_TRUE((sw.array() >= 0).all() && (sw.array() < 1).all()) << sw.transpose();
  const Eigen::Vector3d fluct = p.vel[0] - l * p.pos[0];
  EXPECT_NEAR(fluct.z(), 0.5, 1e-9);
  EXPECT_NEAR((f.particles[0].velocity - l * xw - fluct).norm(), 0.0, 1e-12);
  EXPECT_EQ(f.domain.velocity_gradient, l);
}
