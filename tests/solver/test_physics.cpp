// The solver against exact answers: impact, inclined plane, moment–rotation, determinism.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>

#include "cuboid_walls.hpp"
#include "scene_file.hpp"
#include "simulation.hpp"

using namespace gs;
using namespace gs::solver;

namespace {

Material material(double young = 1e8, double mu_deg = 30, double beta = 0, double eta = -1) {
  Material m;
  m.young_ec = young;
  m.stiffness_ratio = 0.3;
  m.friction_deg = mu_deg;
  m.density = 2600;
  m.rolling_beta = beta;
  m.rolling_eta = eta;
  return m;
}

Particle sphere(std::int64_t id, Eigen::Vector3d x, double r,
                Eigen::Vector3d v = Eigen::Vector3d::Zero()) {
  Particle p;
  p.id = id;
  p.position = x;
  p.radius = r;
  p.velocity = v;
  return p;
}

WallSpec plane(Eigen::Vector3d point, Eigen::Vector3d normal) {
  WallSpec w;
  w.shape = WallShape::Plane;
  w.center = point;
  w.normal = normal.normalized();
  return w;
}

}  // namespace

// Two equal spheres, head on, no damping: contact lasts π·sqrt(m*/Kn) (m* = m/2) and the
// rebound speed equals the approach speed. Then, between two fixed planes, the pair keeps
// colliding with each other and the planes for 1e5 steps: the kinetic energy in free flight
// stays at its initial value.
TEST(Physics, HeadOnImpactDurationRestitutionEnergy) {
  const double r = 1e-3, v0 = 0.05;
  SimulationConfig c;
  c.material = material();
  const double m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double kn = c.material.young_ec * r;  // 2·r·r/(r + r)
  const double duration = M_PI * std::sqrt(0.5 * m / kn);
  c.dt = duration / 2000;
  const double gap = 4e-6;
  Simulation sim(
      c, {sphere(0, {0, 0, 0}, r, {v0, 0, 0}), sphere(1, {2 * r + gap, 0, 0}, r, {-v0, 0, 0})},
      {plane({-r - gap, 0, 0}, {1, 0, 0}), plane({3 * r + 2 * gap, 0, 0}, {-1, 0, 0})});
  const double e0 = sim.kinetic_energy();
  std::int64_t first = -1, last = -1;
  double max_energy_error = 0;
  int collisions = 0;
  bool in_contact = false;
  for (int s = 0; s < 100000; ++s) {
    sim.step();
    const auto f = sim.frame();
    const bool pair_contact =
        std::any_of(f.contacts.begin(), f.contacts.end(),
                    [](const Contact& k) { return k.id1 == 0 && k.id2 == 1; });
    if (pair_contact && collisions == 0) {
      if (first < 0) first = s;
      last = s;
    }
    if (!pair_contact && first >= 0 && collisions == 0) {
      collisions = 1;
      // Restitution after the first sphere–sphere collision.
      const double v_after = sim.particles().vel[1].x() - sim.particles().vel[0].x();
      EXPECT_NEAR(v_after / (2 * v0), 1.0, 1e-6);
    }
    if (!f.contacts.empty()) {
      in_contact = true;
      continue;
    }
    if (in_contact) ++collisions;
    in_contact = false;
    max_energy_error = std::max(max_energy_error, std::abs(sim.kinetic_energy() - e0) / e0);
  }
  ASSERT_GE(first, 0);
  const double measured = static_cast<double>(last - first + 1) * c.dt;
  EXPECT_NEAR(measured / duration, 1.0, 0.01);
  EXPECT_GE(collisions, 8);  // sphere–sphere and sphere–plane impacts
  EXPECT_LT(max_energy_error, 1e-6) << "over 1e5 steps";
}

// A sphere on a plane inclined at θ (gravity along −z, plane normal rotated about y).
namespace {
struct InclineResult {
  double accel, roll_rate;
};
InclineResult incline(double theta_deg, double mu_deg, bool block_rotation, double beta = 0,
                      double* max_travel = nullptr) {
  const double th = theta_deg * M_PI / 180, r = 1e-3, g = 9.81;
  SimulationConfig c;
  c.material = material(1e8, mu_deg, beta, beta > 0 ? 1e9 : -1);
  c.gravity = Eigen::Vector3d(0, 0, -g);
  const Eigen::Vector3d n(-std::sin(th), 0, std::cos(th)),
      down_slope(-std::cos(th), 0, -std::sin(th));
  // Start at static overlap so the normal direction is at rest.
  const double m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double delta = m * g * std::cos(th) / (c.material.young_ec * r);
  c.dt = 2e-7;
  Simulation sim(c, {sphere(0, n * (r - delta), r)}, {plane({0, 0, 0}, n)});
  sim.particles().rot_blocked[0] = block_rotation;
  const int steps = 50000;  // 10 ms
  const Eigen::Vector3d x0 = sim.particles().pos[0];
  for (int s = 0; s < steps / 2; ++s) {
    sim.step();
    if (max_travel)
      *max_travel = std::max(*max_travel, std::abs((sim.particles().pos[0] - x0).dot(down_slope)));
  }
  const double v1 = sim.particles().vel[0].dot(down_slope), w1 = sim.particles().angvel[0].y();
  sim.run(steps / 2);
  const double v2 = sim.particles().vel[0].dot(down_slope), w2 = sim.particles().angvel[0].y();
  const double t = steps / 2 * c.dt;
  return {(v2 - v1) / t, (w2 - w1) / t};
}
}  // namespace

TEST(Physics, InclineSticksBelowFrictionAngle) {
  // Sliding would travel ½·a·t² ≈ 3e-6 m in 5 ms even at a = 0.25 m/s²; sticking leaves only
  // the elastic tangential displacement m·g·sinθ/Ks ≈ 1e-9 m (oscillating, undamped).
  double travel = 0;
  incline(15, 20, /*block_rotation=*/true, 0, &travel);
  EXPECT_LT(travel, 1e-8);
}

TEST(Physics, InclineSlidesAboveFrictionAngleWithAnalyticAcceleration) {
  const double th = 30 * M_PI / 180, mu = 20 * M_PI / 180;
  const auto res = incline(30, 20, /*block_rotation=*/true);
  const double expected = 9.81 * (std::sin(th) - std::cos(th) * std::tan(mu));
  EXPECT_NEAR(res.accel / expected, 1.0, 1e-3);
}

TEST(Physics, InclineRollsAtFiveSeventhsGSinTheta) {
  const double th = 20 * M_PI / 180;
  const auto res = incline(20, 30, /*block_rotation=*/false);  // tan μ > 2/7 tan θ: rolls
  EXPECT_NEAR(res.accel / (5.0 / 7.0 * 9.81 * std::sin(th)), 1.0, 1e-3);
  EXPECT_NEAR(res.roll_rate * 1e-3, -res.accel, 1e-3 * res.accel);  // v = −ω_y·r: no slip
}

// Two pressed spheres; the upper one is turned at a constant rate about x: the rolling moment
// grows with slope Kr, saturates at η·R_roll·|Fn|, and unloads elastically with slope Kr.
TEST(Physics, MomentRotationSlopePlateauUnloading) {
  const double ra = 1e-3, rb = 2e-3, beta = 0.7, eta = 0.4;
  for (auto rr : {RollingRadius::Min, RollingRadius::Mean}) {
    SimulationConfig c;
    c.material = material(1e8, 30, beta, eta);
    c.material.rolling_radius = rr;
    c.dt = 1e-7;
    const double overlap = 1e-6;
    Simulation sim(c, {sphere(0, {0, 0, 0}, ra), sphere(1, {0, 0, ra + rb - overlap}, rb)}, {});
    auto& p = sim.particles();
    p.fixed[0] = p.fixed[1] = 1;
    const double omega = 0.5;  // rad/s
    p.angvel[1] = Eigen::Vector3d(omega, 0, 0);
    const auto k = contact_stiffness(c.material.young_ec, 0.3, beta, ra, rb, rr);
    const double fn = k.kn * overlap;
    const double plateau = eta * k.rolling_radius_m * fn;
    const double theta_yield = plateau / k.kr;
    const int load_steps = static_cast<int>(1.5 * theta_yield / (omega * c.dt));
    double m_prev = 0;
    for (int s = 1; s <= load_steps; ++s) {
      sim.step();
      const double m = std::abs(sim.frame().contacts.at(0).bending_moment.x());
      const double elastic = k.kr * omega * c.dt * s;
      if (elastic < plateau * (1 - 1e-9)) {
        EXPECT_NEAR(m, elastic, 1e-9 * elastic) << "step " << s;
      } else {
        EXPECT_NEAR(m, plateau, 1e-12 * plateau) << "step " << s;
      }
      m_prev = m;
    }
    EXPECT_NEAR(m_prev, plateau, 1e-12 * plateau);
    p.angvel[1] = Eigen::Vector3d(-omega, 0, 0);  // unload
    for (int s = 1; s <= 100; ++s) {
      sim.step();
      const double m = std::abs(sim.frame().contacts.at(0).bending_moment.x());
      EXPECT_NEAR(m, plateau - k.kr * omega * c.dt * s, 1e-9 * plateau) << "unloading step " << s;
    }
  }
}

// Twisting moment (off unless enabled): incremental, slope Ktw = βtw·Ks·RA·RB, plateau at
// ηtw·R_roll·|Fn|, elastic unloading; the bending moment stays zero under a pure twist.
TEST(Physics, TwistMomentSlopePlateauUnloadingAndOffByDefault) {
  const double ra = 1e-3, rb = 2e-3, beta_tw = 0.5, eta_tw = 0.3;
  for (bool enabled : {true, false}) {
    SimulationConfig c;
    c.material = material(1e8, 30, 0.7, 0.4);
    c.dt = 1e-7;
    if (enabled) {
      c.twist_beta = beta_tw;
      c.twist_eta = eta_tw;
    }
    const double overlap = 1e-6;
    Simulation sim(c, {sphere(0, {0, 0, 0}, ra), sphere(1, {0, 0, ra + rb - overlap}, rb)}, {});
    auto& p = sim.particles();
    p.fixed[0] = p.fixed[1] = 1;
    const double omega = 0.5;  // rad/s about the contact normal
    p.angvel[1] = Eigen::Vector3d(0, 0, omega);
    const auto k = contact_stiffness(c.material.young_ec, 0.3, 0.7, ra, rb, RollingRadius::Min);
    const double ktw = beta_tw * k.ks * ra * rb;
    const double plateau = eta_tw * k.rolling_radius_m * k.kn * overlap;
    const int load_steps = static_cast<int>(1.5 * plateau / ktw / (omega * c.dt));
    for (int s = 1; s <= load_steps; ++s) {
      sim.step();
      const auto contact = sim.frame().contacts.at(0);
      EXPECT_EQ(contact.bending_moment.norm(), 0.0) << "step " << s;
      const double m = std::abs(contact.twisting_moment.z());
      if (!enabled) {
        ASSERT_EQ(contact.twisting_moment.norm(), 0.0) << "step " << s;
        continue;
      }
      const double elastic = ktw * omega * c.dt * s;
      if (elastic < plateau * (1 - 1e-9))
        EXPECT_NEAR(m, elastic, 1e-9 * elastic) << "step " << s;
      else
        EXPECT_NEAR(m, plateau, 1e-12 * plateau) << "step " << s;
    }
    if (!enabled) continue;
    p.angvel[1] = Eigen::Vector3d(0, 0, -omega);  // unload
    for (int s = 1; s <= 100; ++s) {
      sim.step();
      const double m = std::abs(sim.frame().contacts.at(0).twisting_moment.z());
      EXPECT_NEAR(m, plateau - ktw * omega * c.dt * s, 1e-9 * plateau) << "unloading step " << s;
    }
  }
}

namespace {
std::vector<Particle> random_packing(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Particle> ps;
  // Jittered lattice, slightly overlapping neighbours, random velocities.
  const int side = static_cast<int>(std::ceil(std::cbrt(n)));
  for (int i = 0; i < n; ++i) {
    const int x = i % side, y = (i / side) % side, z = i / (side * side);
    ps.push_back(sphere(
        i, Eigen::Vector3d(x, y, z) * 1.98e-3 + Eigen::Vector3d(u(rng), u(rng), u(rng)) * 5e-5,
        1e-3 * (0.95 + 0.1 * u(rng)),
        Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) * 0.1));
  }
  return ps;
}
SimulationConfig packing_config(int threads) {
  SimulationConfig c;
  c.material = material(1e8, 25, 0.5, 0.3);
  c.dt = 2e-7;
  c.damping = 0.1;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.threads = threads;
  c.max_overlap_ratio = 0.2;
  return c;
}
std::vector<WallSpec> box_walls() {
  WallSpec b;
  b.shape = WallShape::Box;
  b.center = Eigen::Vector3d(0.01, 0.01, -0.00205);
  b.half_extents = Eigen::Vector3d(0.05, 0.05, 0.001);
  return {b};
}
}  // namespace

TEST(Physics, OneAndTwoThreadsGiveIdenticalResults) {
  const auto ps = random_packing(343, 3);
  Simulation a(packing_config(1), ps, box_walls()), b(packing_config(2), ps, box_walls());
  std::size_t most = 0;
  for (int s = 0; s < 1500; ++s) {
    a.step();
    b.step();
    most = std::max(most, a.contact_count());
  }
  ASSERT_GT(most, 100u);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    ASSERT_EQ(a.particles().pos[i], b.particles().pos[i]) << i;
    ASSERT_EQ(a.particles().angvel[i], b.particles().angvel[i]) << i;
  }
  EXPECT_EQ(a.walls()[0].force, b.walls()[0].force);
}

// The threads' shares of the contact pass are cut by the time each share took, the cost per pair
// taken as constant within an old share (hand-computed cuts).
TEST(Physics, SharesAreCutWhereTheTimedCostIsEven) {
  using gs::solver::balanced_cuts;
  // Untimed, or a share not timed: equal counts of pairs.
  EXPECT_EQ(balanced_cuts(2, {}, {}), (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(balanced_cuts(2, {0, 50, 100}, {0.0, 1.0}), (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(balanced_cuts(2, {0, 50, 100}, {1.0, NAN}), (std::vector<double>{0.0, 0.5, 1.0}));
  // Two shares of 50 pairs, the second three times as slow: the cost is 1 on [0, 0.5) and 3 on
  // [0.5, 1); half of the total 4 is reached at 0.5 + 0.5 · (1/3).
  auto c = balanced_cuts(2, {0, 50, 100}, {1.0, 3.0});
  ASSERT_EQ(c.size(), 3u);
  EXPECT_DOUBLE_EQ(c[1], 0.5 + 0.5 / 3);
  EXPECT_EQ(c[2], 1.0);
  // Three uneven shares (pairs 0-20, 20-80, 80-100 of 100, taking 1, 1 and 4 s): thirds of the
  // total 6 at cost 2 (the end of the second share, 0.8) and 4 (half-way into the third, 0.9).
  c = balanced_cuts(3, {0, 20, 80, 100}, {1.0, 1.0, 4.0});
  EXPECT_DOUBLE_EQ(c[1], 0.8);
  EXPECT_DOUBLE_EQ(c[2], 0.9);
  // An empty old share (no pairs) with its time does not make the cuts go backwards.
  c = balanced_cuts(3, {0, 0, 50, 100}, {1.0, 1.0, 1.0});
  EXPECT_LE(c[1], c[2]);
  EXPECT_GE(c[1], 0.0);
  EXPECT_LE(c[2], 1.0);
}

// Past 20 000 particles the neighbour search and the attaching of histories run on threads too,
// and the contact pass gives each thread a share of the particles (those loaded from another
// share gathered after it). Particles in shuffled order make many of those; a rebuild halfway
// attaches the histories of kept contacts. One, two and three threads give the same bits.
TEST(Physics, LargePackingGivesTheSameBitsOnAnyNumberOfThreads) {
  auto ps = random_packing(27000, 11);
  std::mt19937 rng(4);
  std::shuffle(ps.begin(), ps.begin() + 9000, rng);  // (a third out of order)
  auto run = [&](int threads) {
    auto sim = std::make_unique<Simulation>(packing_config(threads), ps, box_walls());
    sim->run(60);
    sim->invalidate_neighbors();
    sim->run(60);
    return sim;
  };
  const auto one = run(1);
  ASSERT_GT(one->contact_count(), 20000u);
  for (const int threads : {2, 3}) {
    const auto more = run(threads);
    ASSERT_EQ(one->pairs(), more->pairs()) << threads;
    for (std::size_t i = 0; i < ps.size(); ++i) {
      ASSERT_EQ(one->particles().pos[i], more->particles().pos[i]) << threads << " " << i;
      ASSERT_EQ(one->particles().angvel[i], more->particles().angvel[i]) << threads << " " << i;
    }
    std::size_t kept = 0;
    for (std::size_t k = 0; k < one->histories().size(); ++k) {
      ASSERT_EQ(one->histories()[k].shear_force, more->histories()[k].shear_force) << k;
      kept += one->histories()[k].real && one->histories()[k].shear_force.norm() > 0;
    }
    EXPECT_GT(kept, 10000u);  // (histories carried across the rebuild)
    EXPECT_EQ(one->walls()[0].force, more->walls()[0].force);
    EXPECT_EQ(one->energy().residual(), more->energy().residual());
  }
}

// A rebuild of the neighbour list moves each kept pair's history and parameters in place to its
// new index (no copy of them is kept): a run with extra, forced rebuilds is the same run to the
// bit, as a rebuild only adds or drops pairs that do not touch. On 1, 2 and 3 threads, where
// the moves cross the threads' shares of the list.
TEST(Physics, ExtraRebuildsCarryEveryHistoryInPlace) {
  // Fast spheres and a thin skin (20 µm, the spheres move 10–40 µm a leg): every rebuild finds
  // pairs to add and drop, so the kept ones move both ways along the list.
  auto ps = random_packing(12000, 3);
  for (auto& p : ps) p.velocity *= 40;
  std::mt19937 rng(9);
  std::shuffle(ps.begin() + 3000, ps.begin() + 7000, rng);
  for (const int threads : {1, 2, 3}) {
    SimulationConfig config = packing_config(threads);
    config.skin = 2e-5;
    Simulation plain(config, ps, box_walls());
    plain.run(300);
    Simulation rebuilt(config, ps, box_walls());
    for (int leg = 0; leg < 5; ++leg) {
      rebuilt.run(60);
      rebuilt.invalidate_neighbors();
    }
    ASSERT_GT(plain.contact_count(), 12000u);
    for (std::size_t i = 0; i < ps.size(); ++i) {
      ASSERT_EQ(plain.particles().pos[i], rebuilt.particles().pos[i]) << threads << " " << i;
      ASSERT_EQ(plain.particles().angvel[i], rebuilt.particles().angvel[i]) << threads << " " << i;
    }
    // The touching pairs carry the same histories (the candidate lists differ).
    std::map<std::pair<std::uint32_t, std::uint32_t>, const ContactHistory*> touching;
    for (const auto& h : plain.histories())
      if (h.real) touching[{h.a, h.b}] = &h;
    std::size_t matched = 0;
    for (const auto& h : rebuilt.histories()) {
      if (!h.real) continue;
      const auto it = touching.find({h.a, h.b});
      ASSERT_NE(it, touching.end()) << threads;
      ASSERT_EQ(it->second->shear_force, h.shear_force) << threads;
      ASSERT_EQ(it->second->bending, h.bending) << threads;
      ASSERT_EQ(it->second->normal, h.normal) << threads;
      ASSERT_EQ(it->second->fn, h.fn) << threads;
      ASSERT_EQ(it->second->point, h.point) << threads;
      ++matched;
    }
    EXPECT_EQ(matched, touching.size()) << threads;
    EXPECT_EQ(plain.energy().residual(), rebuilt.energy().residual()) << threads;
  }
}

// frame() in pieces is frame() whole: the same particles and contacts in the same order.
TEST(Physics, FramePiecesMakeTheWholeFrame) {
  Simulation sim(packing_config(1), random_packing(300, 2), box_walls());
  sim.run(200);
  const Frame whole = sim.frame();
  ASSERT_GT(whole.contacts.size(), 100u);
  Frame pieces = sim.frame_head();
  EXPECT_TRUE(pieces.particles.empty() && pieces.contacts.empty());
  std::size_t count = 0;
  for (std::size_t i = 0;; ++i) {
    ++count;
    if (!sim.frame_piece(i, 37, pieces)) break;
  }
  EXPECT_EQ(count, (std::max(whole.particles.size(), sim.histories().size()) + 36) / 37);
  ASSERT_EQ(pieces.particles.size(), whole.particles.size());
  ASSERT_EQ(pieces.contacts.size(), whole.contacts.size());
  for (std::size_t i = 0; i < whole.particles.size(); ++i) {
    EXPECT_EQ(pieces.particles[i].id, whole.particles[i].id);
    EXPECT_EQ(pieces.particles[i].position, whole.particles[i].position);
  }
  for (std::size_t k = 0; k < whole.contacts.size(); ++k) {
    EXPECT_EQ(pieces.contacts[k].id1, whole.contacts[k].id1);
    EXPECT_EQ(pieces.contacts[k].id2, whole.contacts[k].id2);
    EXPECT_EQ(pieces.contacts[k].normal_force, whole.contacts[k].normal_force);
  }
  EXPECT_EQ(pieces.domain.lo, whole.domain.lo);
  EXPECT_EQ(pieces.domain.hi, whole.domain.hi);
  EXPECT_EQ(pieces.domain.lo, particle_bounds(whole).first);
  EXPECT_THROW(sim.frame_piece(0, 0, pieces), std::invalid_argument);
}

TEST(Physics, CheckpointResumesBitForBit) {
  const auto ps = random_packing(216, 5);
  Simulation straight(packing_config(2), ps, box_walls());
  straight.run(1200);
  Simulation first(packing_config(2), ps, box_walls());
  first.run(500);
  const auto ckpt =
      std::filesystem::temp_directory_path() / ("gs_ckpt_" + std::to_string(::getpid()));
  first.save_checkpoint(ckpt);
  Simulation resumed(packing_config(1), ps, box_walls());
  resumed.load_checkpoint(ckpt);
  std::filesystem::remove(ckpt);
  EXPECT_EQ(resumed.step_count(), 500);
  resumed.run(700);
  for (std::size_t i = 0; i < ps.size(); ++i) {
    ASSERT_EQ(straight.particles().pos[i], resumed.particles().pos[i]) << i;
    ASSERT_EQ(straight.particles().vel[i], resumed.particles().vel[i]) << i;
  }
  EXPECT_EQ(straight.energy().residual(), resumed.energy().residual());
}

TEST(Physics, BlowUpIsDetected) {
  SimulationConfig c;
  c.material = material();
  c.dt = 1e-4;  // far above critical
  Simulation sim(
      c, {sphere(0, {0, 0, 0}, 1e-3, {1, 0, 0}), sphere(1, {2.1e-3, 0, 0}, 1e-3, {-1, 0, 0})}, {});
  EXPECT_THROW(sim.run(100), BlowUp);
}

// The overlap limit sees every pair of the pass, the last ones of the last particle included: a
// sphere overlapping 0 by its radius, listed after a light contact of 0, stops the first step
// (on one thread and on two).
TEST(Physics, DeepOverlapOfTheLastPairStopsTheStep) {
  for (const int threads : {1, 2}) {
    SimulationConfig c;
    c.material = material();
    c.dt = 1e-9;
    c.threads = threads;
    c.max_overlap_ratio = 0.5;
    const double r = 1e-3;
    Simulation sim(
        c, {sphere(0, {0, 0, 0}, r), sphere(1, {1.99e-3, 0, 0}, r), sphere(2, {0, 1.0e-3, 0}, r)},
        {});
    EXPECT_THROW(sim.step(), BlowUp) << threads << " thread(s)";
  }
}

// A servo-controlled plane presses a sphere onto a fixed floor and settles at the target stress.
TEST(Physics, ServoWallReachesTargetStress) {
  const double r = 1e-3;
  SimulationConfig c;
  c.material = material(1e8, 30);
  c.dt = 1e-7;
  c.damping = 0.3;
  WallSpec top = plane({0, 0, 2 * r + 1e-5}, {0, 0, -1});
  top.servo_stress_Pa = 1e3;
  top.servo_area_m2 = 1e-6;  // target force 1e-3 N
  top.servo_gain = 1e-4;     // m/s per Pa
  top.servo_max_velocity = 0.05;
  Simulation sim(c, {sphere(0, {0, 0, r}, r)}, {plane({0, 0, 0}, {0, 0, 1}), top});
  sim.run(200000);
  const double force = sim.walls()[1].force.dot(Eigen::Vector3d(0, 0, 1));
  EXPECT_NEAR(force, 1e-3, 1e-5);                      // stress within 1 %
  EXPECT_NEAR(sim.walls()[0].force.z(), -1e-3, 1e-5);  // transmitted to the floor
  // Fn = Kn·u on both contacts (floor and servo plane) of the same frame: the overlap equals
  // |Fn|/Kn with Kn = Ec·2·r·r/(r + r), a sphere–wall contact taking both radii the sphere's
  // (docs/physics.md), to round-off.
  const double kn = c.material.young_ec * 2 * r * r / (r + r);
  const auto f = sim.frame();
  ASSERT_EQ(f.contacts.size(), 2u);
  for (const auto& k : f.contacts) {
    const double u = k.normal_force.norm() / kn;
    EXPECT_NEAR(k.overlap, u, 1e-12 * u);
  }
}

TEST(Physics, EnergyLedgerCatchesAnUnstableRun) {
  // A sphere resting on a floor with dt above the critical 2/ω: each bounce creates energy and
  // the ledger residual flags it before anything becomes non-finite.
  SimulationConfig c;
  c.material = material();
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.max_overlap_ratio = 1e9;  // let the ledger be the one to catch it
  const double r = 1e-3, m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double omega = std::sqrt(c.material.young_ec * r / m);
  auto make = [&](double dt) {
    c.dt = dt;
    return Simulation(c, {sphere(0, {0, 0, r - 2e-9}, r)}, {plane({0, 0, 0}, {0, 0, 1})});
  };
  Simulation bad = make(2.2 / omega);
  EXPECT_THROW(
      {
        for (int s = 0; s < 10000; ++s) {
          bad.step();
          bad.check_energy();
        }
      },
      BlowUp);
  Simulation good = make(0.2 / omega);  // the same check passes a stable run
  for (int s = 0; s < 10000; ++s) {
    good.step();
    good.check_energy();
  }
}

// Simple-cubic lattice under uniform overlap δ, sheared at γ̇: I = γ̇·d/sqrt(p/ρ) with the
// Love–Weber mean stress p = (Σ Fn·|l|)/(3V) computed by hand.
TEST(Physics, InertialNumberOfAShearedLattice) {
  const double r = 1e-3, delta = 1e-6, rate = 2.0;
  const int n = 3;
  std::vector<Particle> ps;
  for (int i = 0; i < n * n * n; ++i) {
    const Eigen::Vector3d x = Eigen::Vector3d(i % n, (i / n) % n, i / (n * n)) * (2 * r - delta);
    ps.push_back(sphere(i, x, r, Eigen::Vector3d(rate * x.y(), 0, 0)));
  }
  SimulationConfig c;
  c.material = material(1e8, 30);
  c.dt = 1e-9;
  Simulation sim(c, ps, {});
  sim.step();
  ASSERT_EQ(sim.contact_count(), 54u);  // 3·(n−1)·n²
  const double kn = c.material.young_ec * r;
  const double volume = std::pow((n - 1) * (2 * r - delta) + 2 * r, 3);  // bounding box
  const double p = 54 * kn * delta * (2 * r - delta) / 3 / volume;
  const double expected = rate * 2 * r / std::sqrt(p / c.material.density);
  EXPECT_NEAR(sim.inertial_number() / expected, 1.0, 1e-6);
}

// A sphere spinning at a constant ω with no contacts, no gravity and no damping: after n steps
// its orientation is the rotation by |ω|·t about ω (t = n·dt) and its rotation vector is ω·t,
// to round-off; its spin stays ω bit for bit. Two time steps: a half-angle per step below 1e-3
// rad (the integrator's series) and above it (sincos).
TEST(Physics, FreeSpinOrientationIsTheRotationByOmegaT) {
  const Eigen::Vector3d w(3, -2, 6);  // |ω| = 7 rad/s
  for (double dt : {1e-4, 1e-3}) {
    SimulationConfig c;
    c.material = material();
    c.dt = dt;
    Particle p = sphere(0, {0, 0, 0}, 1e-3);
    p.angular_velocity = w;
    Simulation sim(c, {p}, {});
    const int n = 2000;
    sim.run(n);
    const double t = n * dt;
    const Eigen::Quaterniond expect(Eigen::AngleAxisd(w.norm() * t, w.normalized()));
    const auto& q = sim.particles().ori[0];
    EXPECT_LT(q.angularDistance(expect), 1e-12) << "dt " << dt;
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT((sim.particles().rot[0] - w * t).norm(), 1e-12 * (w * t).norm()) << "dt " << dt;
    EXPECT_EQ(sim.particles().angvel[0], w);
  }
}

// A sphere sliding without rotation on a horizontal plane, Coulomb friction μ, no damping. Exact
// binary radius and overlap (r = 2⁻¹⁰ m, δ = 2⁻³⁰ m) make Fn = Kn·δ exact, and gravity is set to
// g = Fn/m so that the normal direction is in equilibrium bit for bit: the sphere stays at
// overlap δ and decelerates at exactly μ·g. The ledger's friction dissipation is μ·Fn times the
// plastic slip: the tangential displacement s = Σ vₖ·dt (the velocities the law sees, vₖ = v0 −
// k·μg·dt) less the elastic stretch μ·Fn/Ks of the shear spring. The kinetic energy lost is that
// plus the stored ½(μFn)²/Ks, less the leapfrog's n·m·(μg·dt)²/2: the ledger residual is
// n·m·(μg·dt)²/2 − ½(μFn)²/Ks. All to round-off.
TEST(Physics, SlidingSphereFrictionWorkIsMuFnTimesSlip) {
  const double r = std::ldexp(1.0, -10), delta = std::ldexp(1.0, -30), v0 = 0.1;
  SimulationConfig c;
  c.material = material(1e8, 20);
  c.dt = 2e-7;
  Simulation sim(c, {sphere(0, {0, 0, r - delta}, r, {v0, 0, 0})}, {plane({0, 0, 0}, {0, 0, 1})});
  sim.particles().rot_blocked[0] = 1;
  const double m = sim.particles().mass[0];
  const double kn = c.material.young_ec * 2 * r * r / (r + r), ks = 0.3 * kn;
  const double fn = kn * delta, g = fn / m, tan_mu = std::tan(20 * M_PI / 180);
  sim.set_gravity({0, 0, -g});
  const double e0 = sim.energy().initial;
  const int n = 20000;  // 4 ms; it would stop after 0.03 s
  sim.run(n);
  const double a = tan_mu * g, dt = c.dt;
  const double vn = v0 - n * a * dt;
  const double s = n * v0 * dt - a * dt * dt * n * (n - 1) / 2.0;
  const auto& e = sim.energy();
  EXPECT_EQ(sim.particles().pos[0].z(), r - delta);
  const double vx = sim.particles().vel[0].x();
  // Deceleration μ·g: v carries the round-off of n additions, at most n·ε·v0.
  const double eps = std::numeric_limits<double>::epsilon();
  EXPECT_NEAR(vx, vn, n * eps * v0);
  const double dissipation = tan_mu * fn * (s - tan_mu * fn / ks);
  EXPECT_NEAR(e.friction_dissipation, dissipation, 1e-12 * dissipation);
  const double shear = sim.frame().contacts.at(0).shear_force.norm();
  EXPECT_NEAR(shear, tan_mu * fn, 1e-14 * tan_mu * fn);  // the Coulomb limit
  const double residual = n * m * (a * dt) * (a * dt) / 2 - 0.5 * tan_mu * fn * tan_mu * fn / ks;
  // Round-off: the velocity's n·ε·v0 carried into ½·m·v² (2·n·ε·E0).
  EXPECT_NEAR(e.residual(), residual, 2 * n * eps * e0);
}

// Cundall's local damping λ on a free body under gravity alone: the acceleration is g·(1 − λ)
// while it falls from rest (a·v > 0) and g·(1 + λ) while it is thrown up (a·v < 0). The ledger's
// damping term is λ·m·g·Σ|vₖ|·dt over the velocities at the start of each step, in closed form
// (sums of arithmetic series), and the ledger residual is the leapfrog's n·m·(a·dt)²/2. All to
// round-off.
TEST(Physics, LocalDampingOfAFreeBodyInClosedForm) {
  const double g = 9.81, lambda = 0.3, dt = 1e-5;
  const int n = 1000;
  for (double v0 : {0.0, 1.0}) {  // from rest (down), thrown up (stays rising: v0 > n·a·dt)
    SimulationConfig c;
    c.material = material();
    c.dt = dt;
    c.damping = lambda;
    c.gravity = Eigen::Vector3d(0, 0, -g);
    Simulation sim(c, {sphere(0, {0, 0, 0}, 1e-3, {0, 0, v0})}, {});
    const double m = sim.particles().mass[0];
    const double e0 = sim.energy().initial;
    sim.run(n);
    const double a = v0 > 0 ? g * (1 + lambda) : g * (1 - lambda);  // deceleration / acceleration
    const double sign = v0 > 0 ? 1 : -1;                            // direction of motion
    // Speeds at the start of step k: down from rest k·a·dt; up v0 − k·a·dt.
    const double sum_v = v0 > 0 ? n * v0 - a * dt * n * (n - 1) / 2.0 : a * dt * n * (n - 1) / 2.0;
    const double vn = v0 > 0 ? v0 - n * a * dt : -n * a * dt;
    const auto& e = sim.energy();
    EXPECT_NEAR(sim.particles().vel[0].z(), vn, 1e-12 * std::abs(vn));
    const double damping = lambda * m * g * sum_v * dt;
    EXPECT_NEAR(e.damping_dissipation, damping, 1e-12 * damping);
    EXPECT_NEAR(e.gravity_work, -sign * m * g * sum_v * dt, 1e-12 * m * g * sum_v * dt);
    EXPECT_NEAR(e.residual(), n * m * (a * dt) * (a * dt) / 2,
                1e-12 * (e0 + std::abs(e.gravity_work)));
  }
}

// A damped linear oscillator: a sphere on a floor under gravity, released at rest from 1.5 times
// its static overlap δ = m·g/Kn (the contact stays closed: a linear spring about δ), with
// Cundall's local damping λ, 3 periods. (1) The ledger's damping term equals Σ λ·|F + m·g|·|v|·dt
// summed by hand over the recorded steps (F the contact force, v the velocity at the start of the
// step), to round-off. (2) It equals the loss of KE + PE (½m·v² + ½Kn·(u − δ)²) to the
// integration's first order: relative difference below ω·dt (the ledger takes each step's
// power at the velocity of its start; measured 2.7e-5 for ω·dt = 3.1e-3). (3) The amplitude
// ratio of successive half-cycles is the analytic sqrt((1 − λ)/(1 + λ)) of local damping (a
// quarter cycle accelerating with force × (1 − λ), the next decelerating with × (1 + λ)), to
// (ω·dt)² (extrema sampled at steps).
TEST(Physics, DampedOscillatorLedgerAndAmplitudeDecay) {
  const double r = 1e-3, g = 9.81, lambda = 0.1;
  const int per_period = 2000;
  SimulationConfig c;
  c.material = material();
  c.damping = lambda;
  c.gravity = Eigen::Vector3d(0, 0, -g);
  const double m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  const double kn = c.material.young_ec * r;
  const double omega = std::sqrt(kn / m);
  c.dt = 2 * M_PI / omega / per_period;
  const double deq = m * g / kn;
  Simulation sim(c, {sphere(0, {0, 0, r - 1.5 * deq}, r)}, {plane({0, 0, 0}, {0, 0, 1})});
  auto energy = [&] {  // KE + elastic + gravity potential, about the static equilibrium
    const double x = r - sim.particles().pos[0].z() - deq, v = sim.particles().vel[0].z();
    return 0.5 * m * v * v + 0.5 * kn * x * x;
  };
  const double e0 = energy();
  sim.energy();  // the ledger starts here
  double hand = 0, last_u = 1.5 * deq, last_du = 0;
  std::vector<double> amplitudes;
  for (int s = 0; s < 3 * per_period; ++s) {
    const double v = sim.particles().vel[0].z();
    sim.step();
    const auto& k = sim.frame().contacts.at(0);
    hand += lambda * std::abs(k.normal_force.z() - m * g) * std::abs(v) * c.dt;
    const double du = k.overlap - last_u;
    if (s > 0 && du * last_du < 0) amplitudes.push_back(std::abs(last_u - deq));
    last_u = k.overlap;
    last_du = du;
  }
  const double damping = sim.energy().damping_dissipation;
  EXPECT_NEAR(damping, hand, 1e-12 * hand);
  EXPECT_NEAR(damping, e0 - energy(), omega * c.dt * damping);
  ASSERT_GE(amplitudes.size(), 5u);
  const double ratio = std::sqrt((1 - lambda) / (1 + lambda));
  for (std::size_t i = 1; i < amplitudes.size(); ++i) {
    EXPECT_NEAR(amplitudes[i] / amplitudes[i - 1], ratio, (omega * c.dt) * (omega * c.dt)) << i;
  }
}

// A plane wall turning at a prescribed ω about its point: after n steps its normal is the
// initial one rotated by |ω|·t about ω (t = n·dt), to round-off; its point does not move, and
// the frame reports the same normal.
TEST(Physics, RotatingPlaneNormalIsTheAnalyticRotation) {
  SimulationConfig c;
  c.material = material();
  c.dt = 1e-4;
  const Eigen::Vector3d n0(0, 0, 1), w(0.5, -1.0, 2.0);
  WallSpec spec = plane({0, 0, 0}, n0);
  spec.angular_velocity = w;
  // A sphere on the rotation axis keeps its distance from the plane (n·ω̂ is constant): no
  // contact.
  Simulation sim(c, {sphere(0, 0.1 * w.normalized(), 1e-3)}, {spec});
  const int n = 5000;  // 0.5 s, 1.15 rad
  sim.run(n);
  const Eigen::Vector3d expect = Eigen::AngleAxisd(w.norm() * n * c.dt, w.normalized()) * n0;
  EXPECT_LT((sim.walls()[0].normal - expect).norm(), 1e-12);
  EXPECT_EQ(sim.walls()[0].pos, Eigen::Vector3d::Zero());
  EXPECT_EQ(sim.frame().walls.at(0).b, sim.walls()[0].normal);
  EXPECT_EQ(sim.contact_count(), 0u);
}

// Per-wall friction: a sphere slides without rotation along x between two pairs of parallel
// planes, each pressed by the same exact overlap δ = 2⁻³⁰ m (r = 2⁻¹⁰ m: Fn = Kn·δ exact; the
// normal forces cancel bit for bit, so the sphere stays on the x axis). The walls have friction
// 10°, 35°, the material's 25° (friction_deg unset) and 0°. On each wall the tangential force is
// the Coulomb limit tan μ_w·Fn against the motion (zero on the frictionless one) and the wall
// feels it along +x; the sphere decelerates at Σ tan μ_w·Fn/m; the ledger's friction
// dissipation is Σ tan μ_w·Fn·(s − tan μ_w·Fn/Ks) (s = Σ vₖ·dt, less each spring's elastic
// stretch). All to round-off.
TEST(Physics, PerWallFrictionLimitsAndDeceleration) {
  const double r = std::ldexp(1.0, -10), delta = std::ldexp(1.0, -30), v0 = 0.1;
  SimulationConfig c;
  c.material = material(1e8, 25);
  c.dt = 2e-7;
  const double d = r - delta;
  std::vector<WallSpec> walls = {plane({0, -d, 0}, {0, 1, 0}), plane({0, d, 0}, {0, -1, 0}),
                                 plane({0, 0, -d}, {0, 0, 1}), plane({0, 0, d}, {0, 0, -1})};
  const double mu_deg[4] = {10, 35, 25, 0};
  walls[0].friction_deg = 10;
  walls[1].friction_deg = 35;  // walls[2]: the material's 25°
  walls[3].friction_deg = 0;
  Simulation sim(c, {sphere(0, {0, 0, 0}, r, {v0, 0, 0})}, walls);
  sim.particles().rot_blocked[0] = 1;
  const double m = sim.particles().mass[0];
  const double kn = c.material.young_ec * 2 * r * r / (r + r), ks = 0.3 * kn, fn = kn * delta;
  double tan_sum = 0;
  for (double mu : mu_deg) tan_sum += std::tan(mu * M_PI / 180);
  const int n = 5000;
  sim.run(n);
  const double dt = c.dt, a = tan_sum * fn / m;
  const double s = n * v0 * dt - a * dt * dt * n * (n - 1) / 2.0;
  const auto& p = sim.particles();
  EXPECT_EQ(p.pos[0].y(), 0.0);
  EXPECT_EQ(p.pos[0].z(), 0.0);
  const double eps = std::numeric_limits<double>::epsilon();
  EXPECT_NEAR(p.vel[0].x(), v0 - n * a * dt, n * eps * v0);  // n additions' round-off
  const auto f = sim.frame();
  ASSERT_EQ(f.contacts.size(), 4u);
  double dissipation = 0;
  for (std::size_t w = 0; w < 4; ++w) {
    const double limit = std::tan(mu_deg[w] * M_PI / 180) * fn;
    dissipation += limit * (s - limit / ks);
    const auto k = std::find_if(f.contacts.begin(), f.contacts.end(),
                                [&](const Contact& x) { return x.id1 == sim.wall_id(w); });
    ASSERT_NE(k, f.contacts.end()) << w;
    EXPECT_EQ(k->normal_force.norm(), fn) << w;
    if (mu_deg[w] == 0) {
      EXPECT_EQ(k->shear_force.norm(), 0.0);
      EXPECT_EQ(sim.walls()[w].force.x(), 0.0);
      continue;
    }
    // Shear force on the sphere: −tan μ_w·Fn along x; the wall gets +tan μ_w·Fn.
    EXPECT_NEAR(k->shear_force.x(), -limit, 1e-14 * limit) << w;
    EXPECT_EQ(k->shear_force.y(), 0.0) << w;
    EXPECT_EQ(k->shear_force.z(), 0.0) << w;
    EXPECT_NEAR(sim.walls()[w].force.x(), limit, 1e-14 * limit) << w;
  }
  const double got = sim.energy().friction_dissipation;
  EXPECT_NEAR(got, dissipation, 1e-12 * dissipation);
}

// Rolling resistance of a sphere–wall contact (Kr = β·Ks·R², |M| ≤ η·R·|Fn|) on an incline θ,
// with friction high enough that the sphere does not slip. At rest the friction force
// m·g·sinθ has the moment R·m·g·sinθ about the centre, which the rolling moment must balance:
// the sphere holds while R·m·g·sinθ ≤ η·R·m·g·cosθ, i.e. tanθ ≤ η, and rolls above. Rolling
// with M at its plateau η·R·Fn: m·a = m·g·sinθ − Fs and (2/5)·m·R²·a/R = Fs·R − η·R·m·g·cosθ give
// a = (5/7)·g·(sinθ − η·cosθ). The plane is horizontal and gravity is tilted by θ.
namespace {
struct RollingRun {
  double accel = 0, roll_rate = 0;  // down-slope; least-squares slopes over the second half
  double travel = 0;                // largest down-slope displacement over the second half
  double plateau_error = 0;  // max | |M| − η·R·|Fn| | / (η·R·|Fn|) over the second half
  double moment_ratio = 0;   // |M| / (η·R·|Fn|) at the end
};
RollingRun rolling_incline(double theta_deg, double eta, double damping) {
  const double r = 1e-3, g = 9.81, beta = 0.7;
  SimulationConfig c;
  c.material = material(1e8, 30, beta, eta);
  c.dt = 2e-7;
  c.damping = damping;
  const double m = (4.0 / 3.0) * M_PI * r * r * r * c.material.density;
  auto gravity = [&](double th) {
    return Eigen::Vector3d(-g * std::sin(th), 0, -g * std::cos(th));  // down-slope: −x
  };
  c.gravity = gravity(0);
  const double th = theta_deg * M_PI / 180;
  // At rest at the static overlap; gravity turned quasi-statically to θ over 4 ms (a sudden tilt
  // would set the elastic tangential and rolling springs oscillating).
  Simulation sim(c, {sphere(0, {0, 0, r - m * g / (c.material.young_ec * r)}, r)},
                 {plane({0, 0, 0}, {0, 0, 1})});
  const int ramp = 20000;
  for (int s = 1; s <= ramp; ++s) {
    sim.set_gravity(gravity(th * s / ramp));
    sim.step();
  }
  const int steps = 50000;  // 10 ms at θ
  sim.run(steps / 2);
  RollingRun out;
  const double x0 = sim.particles().pos[0].x();
  double st = 0, sv = 0, sw = 0, stt = 0, stv = 0, stw = 0;
  for (int s = 1; s <= steps / 2; ++s) {
    sim.step();
    const double t = s * c.dt, v = -sim.particles().vel[0].x(), w = sim.particles().angvel[0].y();
    st += t;
    sv += v;
    sw += w;
    stt += t * t;
    stv += t * v;
    stw += t * w;
    out.travel = std::max(out.travel, std::abs(sim.particles().pos[0].x() - x0));
    const auto& k = sim.frame().contacts.at(0);
    const double limit = eta * r * k.normal_force.norm();
    out.moment_ratio = k.bending_moment.norm() / limit;
    out.plateau_error = std::max(out.plateau_error, std::abs(out.moment_ratio - 1));
  }
  const double n = steps / 2, den = n * stt - st * st;
  out.accel = (n * stv - st * sv) / den;
  out.roll_rate = (n * stw - st * sw) / den;
  return out;
}
}  // namespace

TEST(Physics, RollingResistanceHoldsBelowTanThetaEqualsEtaAndRollsAbove) {
  const double eta = 0.3, r = 1e-3, kn = 1e8 * r;  // threshold θc = atan 0.3 = 16.70°
  {
    // 16.5°: tanθ = 0.296, 1.3 % below η. With local damping (it leaves the statics unchanged)
    // the sphere settles: it does not move (rolling at even 0.01·g would travel 1.2e-7 m in the
    // 5 ms), and the rolling moment balances the friction force's moment, M = (R − δ/2)·m·g·sinθ
    // (the contact point lies δ/2 inside the sphere, δ = |Fn|/Kn), i.e.
    // |M|/(η·R·|Fn|) = (tanθ/η)·(1 − δ/(2R)), to the settling residual.
    const double th = 16.5 * M_PI / 180;
    const auto hold = rolling_incline(16.5, eta, 0.2);
    const double m = (4.0 / 3.0) * M_PI * r * r * r * 2600;
    const double delta = m * 9.81 * std::cos(th) / kn;
    const double expected = std::tan(th) / eta * (1 - delta / (2 * r));
    EXPECT_LT(hold.travel, 1e-9);
    EXPECT_NEAR(hold.moment_ratio, expected, 1e-8);
  }
  for (double deg : {17.0, 20.0}) {
    // Above (tanθ = 0.306 at 17°, 1.9 % over η): rolling without slip (v = −ω_y·R) at the
    // analytic acceleration, the rolling moment at its plateau η·R·|Fn| at every step, to
    // round-off. The acceleration and spin rate are least-squares slopes; the residual elastic
    // oscillation of the quasi-static tilt is below 1e-4 of them.
    const double th = deg * M_PI / 180;
    const auto roll = rolling_incline(deg, eta, 0.0);
    const double expected = 5.0 / 7.0 * 9.81 * (std::sin(th) - eta * std::cos(th));
    EXPECT_NEAR(roll.accel, expected, 1e-4 * expected) << deg;
    EXPECT_NEAR(-roll.roll_rate * r, roll.accel, 1e-4 * roll.accel) << deg;
    EXPECT_LT(roll.plateau_error, 1e-14) << deg;
  }
}

// The membrane of a plane-strain test (the shipped tiny scene, prepared by its own programme,
// then loaded): at every refresh the loads on the x− face add up to +σc × (projected area) along
// x and those on the x+ face to −σc × (projected area), the area being the span between the
// plane-strain walls (y) times the height between the clamps (z), read from the walls; to
// round-off.
TEST(Membrane, PlaneStrainLoadsSumToSigmaCTimesProjectedArea) {
  Scene s =
      load_scene(std::filesystem::path(GS_TEST_DATA_DIR) / "scenes" / "plane_strain_tiny.toml");
  auto programmes = scene_programmes(s);
  ASSERT_EQ(programmes.size(), 2u);
  Simulation sim(s.config, s.particles, s.walls);
  auto& prep = *programmes[0];
  prep.start(sim);
  while (!prep.finished(sim)) {
    prep.control(sim);
    if (prep.finished(sim)) break;
    sim.step();
  }
  auto& test = *programmes[1];
  test.start(sim);
  const double sigma = s.plane_strain.confining_Pa;
  const std::int64_t refresh = s.plane_strain.refresh_steps;
  int checked = 0;
  for (std::int64_t k = 0; k < 5 * refresh; ++k) {
    test.control(sim);
    if (k % refresh == 0) {
      const auto& w = sim.walls();
      const double y_span = w[kYmax].pos.y() - w[kYmin].pos.y();
      const double z_lo = w[6].pos.z() + w[6].spec.half_extents.z();  // top of the bottom clamp
      const double z_hi = w[8].pos.z() - w[8].spec.half_extents.z();  // bottom of the top clamp
      const double area = y_span * (z_hi - z_lo);
      Eigen::Vector3d minus = Eigen::Vector3d::Zero(), plus = Eigen::Vector3d::Zero();
      std::size_t loaded = 0;
      for (const auto& f : sim.particles().external_force) {
        if (f.x() > 0) minus += f;
        if (f.x() < 0) plus += f;
        loaded += f.x() != 0;
      }
      EXPECT_GT(loaded, 20u);
      // The rays that hit a face carry its area: all of it when none misses (a ray between two
      // sphere rows can pass through a loose specimen; each miss leaves its bin unloaded).
      const auto m = dynamic_cast<const PlaneStrainCompression&>(test).membrane(sim);
      std::size_t hit_minus = 0, hit_plus = 0;
      for (std::size_t r = 0; r < m.x_minus.size(); ++r) {
        hit_minus += !std::isnan(m.x_minus[r]);
        hit_plus += !std::isnan(m.x_plus[r]);
      }
      const double rays = static_cast<double>(m.ny) * m.nz;
      EXPECT_NEAR(m.bin_area_m2 * rays, area, 1e-12 * area) << "step " << k;
      EXPECT_NEAR(m.total_minus.x(), sigma * area * (hit_minus / rays), 1e-12 * sigma * area)
          << "step " << k << ", " << m.missed_rays << " missed rays";
      EXPECT_NEAR(m.total_plus.x(), -sigma * area * (hit_plus / rays), 1e-12 * sigma * area)
          << "step " << k;
      // What the particles carry is those loads (a sphere touched by both faces' rays carries
      // both, so the faces are told apart by the library's sums, not by the sign of a load).
      EXPECT_NEAR((minus + plus).x(), (m.total_minus + m.total_plus).x(), 1e-12 * sigma * area);
      EXPECT_LT(m.missed_rays, rays / 50) << "step " << k;
      ++checked;
    }
    sim.step();
  }
  EXPECT_EQ(checked, 5);
}

// A triaxial specimen whose spheres are replaced by seed 004's four-sphere clumps (the union
// mass model: each clump weighs what its sphere weighed): the clumps start apart (every member
// pair of two clumps separated), and the test's void ratio counts each clump's union volume
// once. Its solid volume is Σ m/ρ of the clumps, to the union quadrature's 2e-5; the members'
// summed volumes would count the overlaps twice (a factor 1/clump_solid_factor more).
TEST(ClumpReplacement, TriaxialSpecimenStartsApartAndCountsTheUnionVolume) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("gs_clump_triaxial_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ifstream in(std::filesystem::path(GS_TEST_DATA_DIR) / "scenes" / "triaxial_tiny.toml");
    std::ofstream out(dir / "scene.toml");
    out << in.rdbuf()
        << "\n[[clump_template]]\nname = \"grain\"\nshape = \"asymmetric4\"\n"
           "diameter_m = 0.006\n[clumps]\nreplace = \"grain\"\nmass = \"union\"\nseed = 1\n";
  }
  Scene s = load_scene(dir / "scene.toml");
  auto programmes = scene_programmes(s);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(programmes.size(), 2u);
  ASSERT_GT(s.clumps.size(), 100u);
  ASSERT_EQ(s.particles.size(), 4 * s.clumps.size());
  EXPECT_GT(s.triaxial.clump_solid_factor, 0.5);
  EXPECT_LT(s.triaxial.clump_solid_factor, 0.95);
  // Apart: no member touches a member of another clump.
  double closest = 1e9;
  for (std::size_t i = 0; i < s.particles.size(); ++i)
    for (std::size_t j = i + 1; j < s.particles.size(); ++j) {
      if (s.particles[i].clump_id == s.particles[j].clump_id) continue;
      const double gap = (s.particles[i].position - s.particles[j].position).norm() -
                         s.particles[i].radius - s.particles[j].radius;
      closest = std::min(closest, gap);
    }
  EXPECT_GT(closest, 0.0);
  Simulation sim(s.config, s.particles, s.walls);
  sim.set_clumps(s.clumps);
  double solid = 0;
  for (const auto& c : sim.clumps()) solid += c.mass / s.config.material.density;
  const double expected = (cuboid_hi(sim) - cuboid_lo(sim)).prod() / solid - 1;
  const std::string row = programmes[1]->curve_row(sim);
  // void_ratio is the curve's 14th column (curve_header).
  std::size_t at = 0;
  for (int k = 0; k < 13; ++k) at = row.find(',', at) + 1;
  const double e = std::strtod(row.c_str() + at, nullptr);
  EXPECT_NEAR(e, expected, 1e-4 * (1 + expected)) << row;
}
