// The engine's parts against exact answers: each SIMD variant of the batch kernels against the
// plain code (bit for bit), the Verlet list against an all-pairs search, box–sphere geometry
// against hand-computed values, and dt = "auto" against its documented formula.
#include <gtest/gtest.h>
#include <omp.h>

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "cohesive_frictional_law.hpp"
#include "contact_geometry.hpp"
#include "errors.hpp"
#include "mesh_walls.hpp"
#include "newton_integrator.hpp"
#include "scene_file.hpp"
#include "simd_level.hpp"
#include "simulation.hpp"

using namespace gs;
using namespace gs::solver;

namespace gs::solver {
void PrintTo(SimdLevel level, std::ostream* os) {
  *os << simd_level_name(level);
}  // (test names and messages show the level's name)
}  // namespace gs::solver

namespace {

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
bool same_bits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return same_bits(a[0], b[0]) && same_bits(a[1], b[1]) && same_bits(a[2], b[2]);
}
bool same_bits(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return same_bits(a.w(), b.w()) && same_bits(a.vec(), b.vec());
}

/// Restores the kernels' SIMD level when a test ends.
struct SimdLevelGuard {
  SimdLevel saved = simd_level();
  ~SimdLevelGuard() { set_simd_level(saved); }
};

Eigen::Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::Vector3d v(g(rng), g(rng), g(rng));
  return v.normalized();
}

Material engine_material(double beta = 0.7, double eta = 0.05) {
  Material m;
  m.young_ec = 1e7;
  m.stiffness_ratio = 0.3;
  m.friction_deg = 12;
  m.density = 2600;
  m.rolling_beta = beta;
  m.rolling_eta = eta;
  return m;
}

WallSpec box_wall(Eigen::Vector3d c, Eigen::Vector3d h, Eigen::Vector3d v = {0, 0, 0}) {
  WallSpec w;
  w.shape = WallShape::Box;
  w.center = c;
  w.half_extents = h;
  w.velocity = v;
  return w;
}

WallSpec plane_wall(Eigen::Vector3d p, Eigen::Vector3d n, Eigen::Vector3d v = {0, 0, 0}) {
  WallSpec w;
  w.shape = WallShape::Plane;
  w.center = p;
  w.normal = n.normalized();
  w.velocity = v;
  return w;
}

// ------------------------------------------------------------------ SIMD variants

/// A batch of random contacts in which every branch of the law occurs on some lanes: fresh and
/// old contacts, the radii and contact-point forms of the relative velocity, histories below and
/// above the Coulomb, rolling and twisting limits, no rolling stiffness, unbounded limits.
ContactBatch random_contact_batch(std::mt19937_64& rng) {
  using F = ContactBatch::Field;
  std::uniform_real_distribution<double> u(0, 1);
  ContactBatch b{};
  for (int j = 0; j < ContactBatch::kLanes; ++j) {
    auto put = [&](F f, const Eigen::Vector3d& x) {
      for (int k = 0; k < 3; ++k) b.v[f + k][j] = x[k];
    };
    const Eigen::Vector3d n = random_unit(rng);
    const double r1 = 1e-3 * (0.5 + u(rng)), r2 = 1e-3 * (0.5 + u(rng));
    const double pen = 0.02 * std::min(r1, r2) * u(rng);
    put(F::NX, n);
    b.v[F::PEN][j] = pen;
    b.v[F::R1][j] = r1;
    b.v[F::R2][j] = r2;
    b.v[F::RATCHET][j] = u(rng) < 0.5 ? 1 : 0;
    put(F::V1X, 0.1 * random_unit(rng) * u(rng));
    put(F::V2X, 0.1 * random_unit(rng) * u(rng));
    put(F::W1X, 50 * random_unit(rng) * u(rng));
    put(F::W2X, 50 * random_unit(rng) * u(rng));
    put(F::C1X, (r1 - 0.5 * pen) * n);
    put(F::C2X, -(r2 - 0.5 * pen) * n);
    b.v[F::FRESH][j] = u(rng) < 0.25 ? 1 : 0;
    put(F::ONX, (n + 1e-3 * random_unit(rng)).normalized());
    const double kn = 1e7 * 2 * r1 * r2 / (r1 + r2), ks = 0.3 * kn;
    b.v[F::KN][j] = kn;
    b.v[F::KS][j] = ks;
    b.v[F::KR][j] = u(rng) < 0.2 ? 0 : 0.7 * ks * r1 * r2;
    b.v[F::KTW][j] = u(rng) < 0.2 ? 0 : 0.5 * ks * r1 * r2;
    const double tan_mu = 0.1 + 0.5 * u(rng);
    b.v[F::TAN_FRICTION][j] = tan_mu;
    const double max_roll = u(rng) < 0.2 ? -1 : 0.05 * std::min(r1, r2);
    const double max_twist = u(rng) < 0.2 ? -1 : 0.05 * std::min(r1, r2);
    b.v[F::MAX_ROLL][j] = max_roll;
    b.v[F::MAX_TWIST][j] = max_twist;
    // Stored histories between 0 and twice their limits.
    const double fn = kn * pen;
    put(F::SX, 2 * u(rng) * fn * tan_mu * random_unit(rng));
    put(F::BX, 2 * u(rng) * fn * std::abs(max_roll) * random_unit(rng));
    put(F::TX, 2 * u(rng) * fn * std::abs(max_twist) * n);
    put(F::PTX, Eigen::Vector3d(u(rng), u(rng), u(rng)));
    // Every other lane a sphere pair whose geometry the batch computes from the centres, about
    // the same contact (lane 5: centres apart; lane 7: coincident centres).
    b.v[F::GEOM][j] = j % 2;
    const Eigen::Vector3d x1 = 0.01 * random_unit(rng);
    const double gap = j == 5 ? 1e-5 : j == 7 ? -(r1 + r2) : -pen;
    put(F::X1X, x1);
    put(F::X2X, x1 + (r1 + r2 + gap) * n);
  }
  return b;
}

/// The fields the law writes (history and outputs), lanes [0, count).
/// (The results of a lane that does not touch are not used: they count as 0 here.)
std::vector<double> law_outputs(const ContactBatch& b, int count) {
  std::vector<double> out;
  auto field = [&](int f) {
    for (int j = 0; j < count; ++j)
      out.push_back(b.v[ContactBatch::TOUCH][j] != 0 || f == ContactBatch::TOUCH ? b.v[f][j] : 0);
  };
  for (int f = ContactBatch::NX; f <= ContactBatch::PEN; ++f) field(f);  // (GEOM lanes write them)
  for (int f = ContactBatch::SX; f < ContactBatch::kFields; ++f) field(f);
  return out;
}

/// Random particles for the integrator: some fixed, some with blocked rotation, some spinning
/// fast enough for the large-angle path, one whose orientation is not a unit quaternion.
ParticleState random_particles(std::mt19937_64& rng, std::size_t n) {
  std::uniform_real_distribution<double> u(0, 1);
  ParticleState p;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = 1e-3 * (0.5 + u(rng));
    const double m = 2600 * 4.0 / 3.0 * M_PI * r * r * r;
    p.id.push_back(static_cast<std::int64_t>(i));
    p.radius.push_back(r);
    p.mass.push_back(m);
    p.inertia.push_back(0.4 * m * r * r);
    p.pos.push_back(0.01 * random_unit(rng));
    p.vel.push_back(0.1 * u(rng) * random_unit(rng));
    p.angvel.push_back((i % 7 == 3 ? 2e3 : 20.0) * u(rng) * random_unit(rng));
    p.rot.push_back(random_unit(rng));
    p.force.push_back(1e-4 * u(rng) * random_unit(rng));
    p.torque.push_back(1e-8 * u(rng) * random_unit(rng));
    const Eigen::Vector3d axis = random_unit(rng);
    Eigen::Quaterniond q(Eigen::AngleAxisd(6 * u(rng), axis));
    if (i == 5) q.coeffs() *= 1.001;
    p.ori.push_back(q);
    p.fixed.push_back(i % 11 == 0);
    p.rot_blocked.push_back(i % 13 == 4);
    p.external_force.push_back(i % 5 == 0 ? Eigen::Vector3d(1e-5 * random_unit(rng))
                                          : Eigen::Vector3d::Zero());
  }
  return p;
}

/// nx·ny·nz spheres of radius 1 mm ± 3 % on a lattice of 2 mm from `first`, jittered by
/// ±0.05 mm (many overlapping from the start), with random velocities (±0.2 m/s) and spins
/// (±`spin` rad/s).
std::vector<Particle> jittered_lattice(std::mt19937_64& rng, const Eigen::Vector3i& n,
                                       const Eigen::Vector3d& first, double spin) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Particle> ps;
  const double a = 2.0e-3;
  for (int z = 0; z < n.z(); ++z)
    for (int y = 0; y < n.y(); ++y)
      for (int x = 0; x < n.x(); ++x) {
        Particle p;
        p.id = static_cast<std::int64_t>(ps.size());
        p.radius = 1e-3 * (1 + 0.03 * u(rng));
        p.position = first + a * Eigen::Vector3d(x, y, z) +
                     0.05e-3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
        p.velocity = 0.2 * Eigen::Vector3d(u(rng), u(rng), u(rng));
        p.angular_velocity = spin * Eigen::Vector3d(u(rng), u(rng), u(rng));
        ps.push_back(p);
      }
  return ps;
}

/// A dense jittered lattice of 288 spheres (radii ±3 %, many overlapping from the start), with
/// random velocities and spins, in a box: bottom box (contact-point form), plane sides, a plane
/// lid moving down and a box side moving in; a few particles fixed, a few with blocked spin.
Simulation dense_run(bool twisting) {
  std::mt19937_64 rng(17);
  const double a = 2.0e-3;
  const std::vector<Particle> ps =
      jittered_lattice(rng, {6, 6, 8}, Eigen::Vector3d(0.5 * a, 0.5 * a, 0.5 * a), 300);
  SimulationConfig c;
  c.material = engine_material();
  c.damping = 0.1;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.dt = 0.3 * pwave_timestep({0.9e-3}, c.material.density, c.material.young_ec);
  c.max_overlap_ratio = 0.5;
  if (twisting) {
    c.twist_beta = 0.5;
    c.twist_eta = 0.02;
  }
  const double L = 6 * a, H = 8 * a;
  std::vector<WallSpec> walls = {
      box_wall({L / 2, L / 2, -1e-3}, {L, L, 1e-3}),
      plane_wall({0, 0, 0}, {1, 0, 0}),
      box_wall({L + 1e-3, L / 2, H / 2}, {1e-3, L, H}, {-0.05, 0, 0}),
      plane_wall({0, 0, 0}, {0, 1, 0}),
      plane_wall({0, L, 0}, {0, -1, 0}),
      plane_wall({0, 0, H}, {0, 0, -1}, {0, 0, -0.2}),
  };
  walls[1].friction_deg = 25;
  Simulation sim(c, ps, walls);
  for (std::size_t i = 0; i < ps.size(); i += 37) {
    sim.particles().fixed[i] = 1;  // held in place, spinning
    sim.particles().vel[i].setZero();
  }
  for (std::size_t i = 5; i < ps.size(); i += 41) sim.particles().rot_blocked[i] = 1;
  sim.run(400);
  return sim;
}

/// What compare_runs counted in the runs' last frame.
struct RunCounts {
  std::size_t contacts = 0, wall_contacts = 0, twisted = 0;
};

/// Asserts that two runs hold the same bits: the particles' motion, the contacts (ids, forces
/// and moments) and the walls' forces.
void compare_runs(const Simulation& plain, const Simulation& simd, RunCounts& n) {
  const auto& p = plain.particles();
  const auto& q = simd.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_TRUE(same_bits(p.pos[i], q.pos[i])) << i;
    ASSERT_TRUE(same_bits(p.vel[i], q.vel[i])) << i;
    ASSERT_TRUE(same_bits(p.angvel[i], q.angvel[i])) << i;
    ASSERT_TRUE(same_bits(p.ori[i], q.ori[i])) << i;
  }
  const Frame fp = plain.frame(), fq = simd.frame();
  ASSERT_EQ(fp.contacts.size(), fq.contacts.size());
  n.contacts = fp.contacts.size();
  for (std::size_t k = 0; k < fp.contacts.size(); ++k) {
    const Contact &a = fp.contacts[k], &b = fq.contacts[k];
    ASSERT_EQ(a.id1, b.id1);
    ASSERT_EQ(a.id2, b.id2);
    ASSERT_TRUE(same_bits(a.normal_force, b.normal_force)) << k;
    ASSERT_TRUE(same_bits(a.shear_force, b.shear_force)) << k;
    ASSERT_TRUE(same_bits(a.bending_moment, b.bending_moment)) << k;
    ASSERT_TRUE(same_bits(a.twisting_moment, b.twisting_moment)) << k;
    n.wall_contacts += a.id1 >= static_cast<std::int64_t>(p.size());
    n.twisted += a.twisting_moment.norm() > 0;
  }
  for (std::size_t w = 0; w < plain.walls().size(); ++w)
    EXPECT_TRUE(same_bits(plain.walls()[w].force, simd.walls()[w].force)) << w;
}

class SimdVariant : public ::testing::TestWithParam<SimdLevel> {};

// Exact answer: the plain x86-64 kernels. The AVX2 and AVX-512 variants must give the same bits
// (no fused multiply-adds, the same operations in the same order per lane) on random contact
// batches (full and partial, twisting on and off), random particles, and two dense runs of 288
// spheres over 400 steps in which contacts open, close, slide and roll.
TEST_P(SimdVariant, SameBitsAsThePlainKernels) {
  const SimdLevel level = GetParam();
  if (!simd_level_supported(level))
    GTEST_SKIP() << "this CPU cannot run the " << simd_level_name(level) << " kernels";
  SimdLevelGuard guard;

  // The law on random batches, every lane count that splits the vector loops differently.
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const ContactBatch input = random_contact_batch(rng);
    for (const int count : {32, 31, 17, 8, 5, 1}) {
      for (const bool twist : {false, true}) {
        auto plain = std::make_unique<ContactBatch>(input);
        auto simd = std::make_unique<ContactBatch>(input);
        set_simd_level(SimdLevel::Generic);
        cohesive_frictional_batch(*plain, count, 2e-6, twist);
        set_simd_level(level);
        ASSERT_EQ(simd_level(), level);
        cohesive_frictional_batch(*simd, count, 2e-6, twist);
        const auto a = law_outputs(*plain, count), b = law_outputs(*simd, count);
        for (std::size_t k = 0; k < a.size(); ++k)
          ASSERT_TRUE(same_bits(a[k], b[k]))
              << "output " << static_cast<int>(k) / count << " lane "
              << k % static_cast<std::size_t>(count) << ": " << a[k] << " vs " << b[k];
      }
    }
  }
  {
    // The batches did reach the limits: some lanes slid and some rolled at their caps.
    auto b = std::make_unique<ContactBatch>(random_contact_batch(rng));
    cohesive_frictional_batch(*b, 32, 2e-6, true);
    int slid = 0, rolled = 0;
    for (int j = 0; j < 32; ++j) {
      slid += b->v[ContactBatch::FRICTION_DISSIPATION][j] > 0;
      rolled += b->v[ContactBatch::ROLLING_DISSIPATION][j] > 0;
    }
    EXPECT_GT(slid, 3);
    EXPECT_GT(rolled, 3);
  }

  // The integrator on random particles (150: full batches of 32 and a partial one).
  for (const double damping : {0.0, 0.2}) {
    std::mt19937_64 r1(11);
    ParticleState plain = random_particles(r1, 150), simd = plain;
    set_simd_level(SimdLevel::Generic);
    const auto sp = integrate_particles(plain, 0, plain.size(), {0, 0, -9.81}, damping, 2e-6);
    set_simd_level(level);
    const auto ss = integrate_particles(simd, 0, simd.size(), {0, 0, -9.81}, damping, 2e-6);
    for (std::size_t i = 0; i < plain.size(); ++i) {
      ASSERT_TRUE(same_bits(plain.pos[i], simd.pos[i])) << i;
      ASSERT_TRUE(same_bits(plain.vel[i], simd.vel[i])) << i;
      ASSERT_TRUE(same_bits(plain.angvel[i], simd.angvel[i])) << i;
      ASSERT_TRUE(same_bits(plain.rot[i], simd.rot[i])) << i;
      ASSERT_TRUE(same_bits(plain.ori[i], simd.ori[i])) << i;
    }
    EXPECT_TRUE(same_bits(sp.gravity_power, ss.gravity_power));
    EXPECT_TRUE(same_bits(sp.external_power, ss.external_power));
    EXPECT_TRUE(same_bits(sp.damping, ss.damping));
    EXPECT_TRUE(sp.finite);
    EXPECT_TRUE(ss.finite);
  }
  // A particle whose velocity overflows: the finite check fails the same way in each variant
  // (here in a lane of an eight-particle block of the AVX-512 gather, and in the scalar tail).
  for (const std::size_t bad : {std::size_t{9}, std::size_t{148}}) {
    std::mt19937_64 r1(12);
    ParticleState plain = random_particles(r1, 150);
    plain.force[bad] = Eigen::Vector3d(HUGE_VAL, 0, 0);
    ParticleState simd = plain;
    set_simd_level(SimdLevel::Generic);
    const auto sp = integrate_particles(plain, 0, plain.size(), {0, 0, -9.81}, 0.0, 2e-6);
    set_simd_level(level);
    const auto ss = integrate_particles(simd, 0, simd.size(), {0, 0, -9.81}, 0.0, 2e-6);
    EXPECT_FALSE(sp.finite) << bad;
    EXPECT_FALSE(ss.finite) << bad;
  }

  // Whole runs.
  for (const bool twisting : {false, true}) {
    set_simd_level(SimdLevel::Generic);
    Simulation plain = dense_run(twisting);
    set_simd_level(level);
    Simulation simd = dense_run(twisting);
    RunCounts n;
    compare_runs(plain, simd, n);
    if (HasFatalFailure()) return;
    // Every branch was exercised: contacts slid and rolled at their caps, walls were touched.
    const EnergyLedger ep = plain.energy(), eq = simd.energy();
    EXPECT_GT(ep.friction_dissipation, 0);
    EXPECT_GT(ep.rolling_dissipation, 0);
    EXPECT_GT(n.wall_contacts, 20u);
    EXPECT_GT(n.contacts, 300u);
    EXPECT_EQ(n.twisted > 0, twisting);
    EXPECT_TRUE(same_bits(ep.friction_dissipation, eq.friction_dissipation));
    EXPECT_TRUE(same_bits(ep.rolling_dissipation, eq.rolling_dissipation));
    EXPECT_TRUE(same_bits(ep.damping_dissipation, eq.damping_dissipation));
  }
}

// Exact answer: sphere_sphere_geometry, the scalar geometry of a sphere pair. The batch computes
// it on GEOM lanes (touching, apart by 1e-12 m, just touching, coincident centres) with the
// same bits, at every SIMD level, and says which lanes touch.
TEST(ContactBatchGeometry, SpherePairLanesAreTheScalarGeometryBitForBit) {
  using F = ContactBatch::Field;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  ContactBatch input{};
  std::vector<ContactGeometry> expect(ContactBatch::kLanes);
  std::vector<bool> touches(ContactBatch::kLanes);
  for (int j = 0; j < ContactBatch::kLanes; ++j) {
    const double r1 = 1e-3 * (0.5 + u(rng)), r2 = 1e-3 * (0.5 + u(rng));
    const Eigen::Vector3d x1 = 0.01 * random_unit(rng), n = random_unit(rng);
    const double gap = j == 3 ? 1e-12 : j == 4 ? 0.0 : j == 9 ? -(r1 + r2) : -0.05 * r1 * u(rng);
    const Eigen::Vector3d x2 = x1 + (r1 + r2 + gap) * n;
    input.v[F::GEOM][j] = 1;
    input.v[F::R1][j] = r1;
    input.v[F::R2][j] = r2;
    for (int c = 0; c < 3; ++c) {
      input.v[F::X1X + c][j] = x1[c];
      input.v[F::X2X + c][j] = x2[c];
    }
    ContactGeometry g;
    touches[static_cast<std::size_t>(j)] =
        sphere_sphere_geometry(V3(x1), r1, V3(x2), r2, g) && !(g.penetration < 0);
    expect[static_cast<std::size_t>(j)] = g;
  }
  int touching = 0;
  const SimdLevel before = simd_level();
  for (const SimdLevel level : {SimdLevel::Generic, SimdLevel::Avx2, SimdLevel::Avx512}) {
    if (!simd_level_supported(level)) continue;
    set_simd_level(level);
    auto b = std::make_unique<ContactBatch>(input);
    cohesive_frictional_batch(*b, ContactBatch::kLanes, 1e-6, false);
    for (int j = 0; j < ContactBatch::kLanes; ++j) {
      const auto& g = expect[static_cast<std::size_t>(j)];
      const bool touch = touches[static_cast<std::size_t>(j)];
      ASSERT_EQ(b->v[F::TOUCH][j] == 1, touch) << simd_level_name(level) << " lane " << j;
      touching += touch;
      if (!touch) continue;
      const Eigen::Vector3d x1(b->v[F::X1X][j], b->v[F::X1Y][j], b->v[F::X1Z][j]);
      const Eigen::Vector3d x2(b->v[F::X2X][j], b->v[F::X2Y][j], b->v[F::X2Z][j]);
      auto field = [&](F f) { return Eigen::Vector3d(b->v[f][j], b->v[f + 1][j], b->v[f + 2][j]); };
      EXPECT_TRUE(same_bits(field(F::NX), g.normal.eigen())) << "lane " << j;
      EXPECT_TRUE(same_bits(b->v[F::PEN][j], g.penetration)) << "lane " << j;
      EXPECT_TRUE(same_bits(field(F::PTX), g.point.eigen())) << "lane " << j;
      // The arms the loads are computed from: the contact point less each centre.
      const Eigen::Vector3d f1 = field(F::F1X);
      EXPECT_TRUE(same_bits(field(F::A1X), cross(g.point - V3(x1), V3(f1)).eigen()))
          << "lane " << j;
    }
  }
  set_simd_level(before);
  EXPECT_GT(touching, 28);
}

/// 150 spheres in a V-shaped mesh trough (two tilted flanks and a flat floor, two
/// triangles each), with the given law and mesh convention.
Simulation mesh_trough_run(ContactLaw law, MeshContact mode, int threads) {
  std::mt19937_64 rng(17);
  const double a = 2.0e-3;  // (a packing in contact from the start, boxed in)
  const std::vector<Particle> ps =
      jittered_lattice(rng, {5, 5, 6}, Eigen::Vector3d(-2 * a, -2 * a, 1e-3), 200);
  SimulationConfig c;
  c.law = law;
  c.material = engine_material();
  c.material.poisson = 0.25;
  c.material.restitution = 0.5;
  c.damping = law == ContactLaw::HertzMindlin ? 0.0 : 0.1;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.dt = 0.2 * pwave_timestep({0.98e-3}, c.material.density, c.material.young_ec);
  c.max_overlap_ratio = 0.5;
  c.threads = threads;
  // The floor |x| ≤ 5.2 mm at z = 0 (the outer columns' spheres reach 5.0 mm), the flanks
  // rising from its edges at 45° to |x| = 12 mm.
  const double h = 5.2e-3, w = 12e-3, d = 8e-3;
  auto quad = [](MeshTriangles& m, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                 const Eigen::Vector3d& p2, const Eigen::Vector3d& p3, const char* group) {
    m.triangles.push_back({p0, p1, p2});
    m.triangles.push_back({p0, p2, p3});
    m.group.insert(m.group.end(), 2, group);
  };
  MeshTriangles m;
  quad(m, {-h, -d, 0}, {h, -d, 0}, {h, d, 0}, {-h, d, 0}, "floor");
  quad(m, {h, -d, 0}, {w, -d, w - h}, {w, d, w - h}, {h, d, 0}, "right");
  quad(m, {-w, -d, w - h}, {-h, -d, 0}, {-h, d, 0}, {-w, d, w - h}, "left");
  // Held in by planes in front, behind and above (plane lanes too).
  std::vector<WallSpec> walls = mesh_walls(m, mode);
  walls.push_back(plane_wall({0, -5e-3, 0}, {0, 1, 0}));
  walls.push_back(plane_wall({0, 5e-3, 0}, {0, -1, 0}));
  walls.push_back(plane_wall({0, 0, 6 * a}, {0, 0, -1}, {0, 0, -0.2}));
  return Simulation(c, ps, walls);
}

// The contact pass's gather (lane_gather.hpp: the pairs' histories and parameters and the sphere
// pairs' bodies by AVX-512 gathers, the wall lanes' geometry one by one among them) fills the
// law's batch with the same values as the plain copies: whole runs on a mesh trough (facet lanes
// among sphere lanes) give the same bits, with both laws, both mesh conventions, and the threads'
// pass.
TEST_P(SimdVariant, MeshRunsAreTheSameBitsAsThePlainGather) {
  const SimdLevel level = GetParam();
  if (!simd_level_supported(level))
    GTEST_SKIP() << "this CPU cannot run the " << simd_level_name(level) << " kernels";
  SimdLevelGuard guard;
  struct Case {
    ContactLaw law;
    MeshContact mode;
    int threads;
  };
  for (const auto& [law, mode, threads] :
       {Case{ContactLaw::CohesiveFrictional, MeshContact::Merged, 1},
        Case{ContactLaw::CohesiveFrictional, MeshContact::YadeParity, 1},
        Case{ContactLaw::HertzMindlin, MeshContact::Merged, 1},
        Case{ContactLaw::HertzMindlin, MeshContact::YadeParity, 1},
        Case{ContactLaw::HertzMindlin, MeshContact::Merged, 2}}) {
    SCOPED_TRACE(::testing::Message() << "law " << static_cast<int>(law) << " mode "
                                      << static_cast<int>(mode) << " threads " << threads);
    set_simd_level(SimdLevel::Generic);
    Simulation plain = mesh_trough_run(law, mode, threads);
    plain.run(500);
    set_simd_level(level);
    Simulation simd = mesh_trough_run(law, mode, threads);
    simd.run(500);
    RunCounts n;
    compare_runs(plain, simd, n);
    if (HasFatalFailure()) return;
    // The runs had both kinds of lanes, mixed in batches.
    EXPECT_GT(n.wall_contacts, 20u);
    EXPECT_GT(n.contacts, 150u);
  }
}

INSTANTIATE_TEST_SUITE_P(Engine, SimdVariant, ::testing::Values(SimdLevel::Avx2, SimdLevel::Avx512),
                         [](const auto& info) { return std::string(simd_level_name(info.param)); });

// Exact answer: the names round-trip, the plain level is always available, the best level is
// supported, and asking for a level the CPU lacks is an error that leaves the level unchanged.
TEST(SimdLevelApi, NamesSupportAndOverride) {
  SimdLevelGuard guard;
  for (const SimdLevel l : {SimdLevel::Generic, SimdLevel::Avx2, SimdLevel::Avx512})
    EXPECT_EQ(parse_simd_level(simd_level_name(l)), l);
  EXPECT_FALSE(parse_simd_level("sse9"));
  EXPECT_TRUE(simd_level_supported(SimdLevel::Generic));
  EXPECT_TRUE(simd_level_supported(best_simd_level()));
  set_simd_level(SimdLevel::Generic);
  EXPECT_EQ(simd_level(), SimdLevel::Generic);
  if (!simd_level_supported(SimdLevel::Avx512)) {
    EXPECT_THROW(set_simd_level(SimdLevel::Avx512), std::invalid_argument);
    EXPECT_EQ(simd_level(), SimdLevel::Generic);
  }
}

// ------------------------------------------------------------------ Verlet list

using PairSet = std::set<std::pair<std::int64_t, std::int64_t>>;

/// Every overlapping pair (penetration ≥ 0) by an all-pairs search: sphere–sphere as
/// (i, j), i < j; sphere–wall as (i, wall id).
PairSet brute_force_contacts(const std::vector<Eigen::Vector3d>& x, const std::vector<double>& r,
                             const std::vector<WallState>& walls, std::int64_t wall_id0) {
  PairSet s;
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (std::size_t j = i + 1; j < x.size(); ++j)
      if (r[i] + r[j] - (x[j] - x[i]).norm() >= 0)
        s.emplace(static_cast<std::int64_t>(i), static_cast<std::int64_t>(j));
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const auto& wall = walls[w];
      double dist;
      if (wall.spec.shape == WallShape::Box) {
        const Eigen::Vector3d out =
            ((x[i] - wall.pos).cwiseAbs() - wall.spec.half_extents).cwiseMax(0.0);
        dist = out.norm();  // 0 with the centre inside
      } else {
        dist = (x[i] - wall.pos).dot(wall.normal);
      }
      if (r[i] - dist >= 0)
        s.emplace(static_cast<std::int64_t>(i), wall_id0 + static_cast<std::int64_t>(w));
    }
  }
  return s;
}

/// What a run checked against the all-pairs search saw.
struct ContactRunStats {
  std::size_t most = 0, most_on_walls = 0;
  std::vector<std::size_t> wall_touches;  // contact-steps per wall
};

/// Steps `sim` and, after each step, asserts that its contacts (geometry evaluated at the
/// positions the step started from) are exactly the pairs an all-pairs search finds there.
void expect_all_pair_contacts(Simulation& sim, int steps, ContactRunStats& st) {
  st.wall_touches.assign(sim.walls().size(), 0);
  const std::int64_t w0 = sim.wall_id(0);
  for (int s = 0; s < steps; ++s) {
    const std::vector<WallState> walls_before = sim.walls();
    const std::vector<Eigen::Vector3d> x_before = sim.particles().pos;
    sim.step();
    const PairSet expected =
        brute_force_contacts(x_before, sim.particles().radius, walls_before, w0);
    PairSet found;
    for (const auto& k : sim.frame().contacts) {
      if (k.id1 >= w0)
        found.emplace(k.id2, k.id1);
      else
        found.emplace(k.id1, k.id2);
    }
    ASSERT_EQ(found, expected) << "step " << s + 1 << ": " << found.size() << " contacts, "
                               << expected.size() << " overlapping pairs";
    st.most = std::max(st.most, found.size());
    std::size_t on_walls = 0;
    for (const auto& [a, b] : found)
      if (b >= w0) {
        ++on_walls;
        ++st.wall_touches[static_cast<std::size_t>(b - w0)];
      }
    st.most_on_walls = std::max(st.most_on_walls, on_walls);
  }
}

/// Jittered lattice nx × ny × nz of spacing a: radii r·(1 ± 10 %), centres moved up to `jitter`
/// per coordinate, velocities of magnitude v and spins of magnitude w in random directions.
std::vector<Particle> jittered_lattice(std::mt19937_64& rng, int nx, int ny, int nz, double a,
                                       double r, double jitter, double v, double w) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Particle> ps;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        Particle p;
        p.id = static_cast<std::int64_t>(ps.size());
        p.radius = r * (1 + 0.1 * u(rng));
        p.position = Eigen::Vector3d((x + 0.5) * a, (y + 0.5) * a, (z + 0.5) * a) +
                     jitter * Eigen::Vector3d(u(rng), u(rng), u(rng));
        p.velocity = v * random_unit(rng);
        p.angular_velocity = w * random_unit(rng);
        ps.push_back(p);
      }
  return ps;
}

// Exact answer: an all-pairs O(N²) search, at every step of two runs. (1) A dense random packing
// of 294 spheres (overlapping at the start) with random velocities springs apart, falls and is
// squeezed by a plane lid and a box side moving in, for 3000 steps: the list is rebuilt many
// times for the particles' displacements. (2) A loose packing at rest, no gravity, is struck by
// a plane lid and a box side moving fast: rebuilds are driven by the walls' displacement.
TEST(VerletList, FindsEveryPairAnAllPairsSearchFinds) {
  std::mt19937_64 rng(29);
  SimulationConfig c;
  c.material = engine_material(0.5, 0.3);
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.damping = 0.05;
  c.dt = 0.3 * pwave_timestep({0.45e-3}, c.material.density, c.material.young_ec);
  c.max_overlap_ratio = 0.5;
  {
    const double a = 1.05e-3, L = 7 * a, H = 6 * a;
    const auto ps = jittered_lattice(rng, 7, 7, 6, a, 0.5e-3, 0.035e-3, 0.3, 100);
    const std::vector<WallSpec> walls = {
        box_wall({L / 2, L / 2, -1e-3}, {L, L, 1e-3}),                    // floor
        plane_wall({0, 0, 0}, {1, 0, 0}),                                 // x = 0
        box_wall({L + 1e-3, L / 2, H}, {1e-3, L, 2 * H}, {-0.05, 0, 0}),  // x = L, moving in
        box_wall({L / 2, -1e-3, H}, {L, 1e-3, 2 * H}),                    // y = 0
        plane_wall({0, L, 0}, {0, -1, 0}),                                // y = L
        plane_wall({0, 0, H}, {0, 0, -1}, {0, 0, -0.1}),                  // lid, moving down
    };
    Simulation sim(c, ps, walls);
    ContactRunStats st;
    expect_all_pair_contacts(sim, 3000, st);
    EXPECT_GT(st.most, 500u);
    EXPECT_GT(st.most_on_walls, 100u);
    for (std::size_t w = 0; w < walls.size(); ++w)
      EXPECT_GT(st.wall_touches[w], 0u) << "wall " << w;
    EXPECT_GT(sim.neighbor_list_builds(), 20);
  }
  {
    // Centres at most 0.04 mm off the lattice: no sphere touches another, and every sphere is
    // at least 0.3 mm from the lid and the moving side (nearer than the default skin of about
    // 0.23 mm only after those walls have moved), so rebuilds come from the walls' displacement
    // until they strike the packing.
    const double a = 1.2e-3, L = 7 * a, H = 4 * a, reach = 0.5e-3 * 1.1 + 0.04e-3;
    const auto ps = jittered_lattice(rng, 7, 7, 4, a, 0.5e-3, 0.04e-3, 0, 0);
    c.gravity.setZero();
    const double lid = (H - 0.5 * a) + reach + 0.3e-3, side = (L - 0.5 * a) + reach + 0.3e-3;
    const std::vector<WallSpec> walls = {
        box_wall({L / 2, L / 2, -1e-3}, {L, L, 1e-3}),                      // floor
        box_wall({side + 1e-3, L / 2, H}, {1e-3, L, 2 * H}, {-1.0, 0, 0}),  // side, moving in
        plane_wall({0, 0, lid}, {0, 0, -1}, {0, 0, -1.0}),                  // lid, moving down
    };
    Simulation sim(c, ps, walls);
    ContactRunStats st;
    expect_all_pair_contacts(sim, 500, st);
    EXPECT_GT(st.most_on_walls, 40u);
    EXPECT_GT(st.wall_touches[2], 0u);
    EXPECT_GT(sim.neighbor_list_builds(), 3);
  }
}

// ------------------------------------------------------------------ box–sphere geometry

void expect_vec_near(const V3& got, const Eigen::Vector3d& want, const char* what) {
  const double scale = std::max(1.0, want.norm());
  EXPECT_LE((got.eigen() - want).norm(), 1e-12 * scale)
      << what << ": got (" << got.x << ", " << got.y << ", " << got.z << "), want ("
      << want.transpose() << ")";
}
void expect_rel(double got, double want, const char* what) {
  EXPECT_LE(std::abs(got - want), 1e-12 * std::abs(want)) << what << ": " << got << " vs " << want;
}

// Exact answers, by hand, for the box with centre (1, 2, 3) and half-extents (0.5, 1, 1.5) and
// a sphere of radius 0.2 (normal from the box to the sphere; contact point half-way between the
// box point and the sphere surface outside; centre inside: along the nearest face's outward
// normal, overlap = R + depth of the centre).
TEST(BoxSphereGeometry, FaceEdgeCornerAndCentreInside) {
  const V3 c(1, 2, 3), h(0.5, 1, 1.5);
  const double r = 0.2;
  ContactGeometry g;
  // Face z = 4.5, centre 0.15 above it: overlap 0.05, n = +z, point z = (4.5 + 4.45)/2.
  box_sphere_geometry(c, h, V3(1.2, 2.5, 4.65), r, g);
  expect_rel(g.penetration, 0.05, "face overlap");
  expect_vec_near(g.normal, {0, 0, 1}, "face normal");
  expect_vec_near(g.point, {1.2, 2.5, 4.475}, "face point");
  EXPECT_FALSE(g.ratchet_free);
  EXPECT_EQ(g.radius1, r);
  EXPECT_EQ(g.radius2, r);
  // Face x = 0.5 (the −x face), centre 0.1 outside: overlap 0.1, n = −x, point x = (0.5 + 0.6)/2.
  box_sphere_geometry(c, h, V3(0.4, 1.5, 2), r, g);
  expect_rel(g.penetration, 0.1, "-x face overlap");
  expect_vec_near(g.normal, {-1, 0, 0}, "-x face normal");
  expect_vec_near(g.point, {0.55, 1.5, 2}, "-x face point");
  // Edge x = 1.5, z = 4.5, centre offset d = (0.1, 0, 0.1): distance 0.1·√2, overlap
  // 0.2 − 0.1·√2, n = (1, 0, 1)/√2, point half-way between the edge and the sphere surface
  // (edge + d − r·n): edge + ½(d − r·n).
  {
    const Eigen::Vector3d edge(1.5, 2.3, 4.5), d(0.1, 0, 0.1);
    const Eigen::Vector3d n = d / std::sqrt(0.02);
    box_sphere_geometry(c, h, V3(edge + d), r, g);
    expect_rel(g.penetration, 0.2 - 0.1 * std::sqrt(2.0), "edge overlap");
    expect_vec_near(g.normal, n, "edge normal");
    expect_vec_near(g.point, edge + 0.5 * (d - r * n), "edge point");
  }
  // Corner (1.5, 3, 4.5), centre offset (0.04, 0.08, 0.08): distance 0.12, overlap 0.08,
  // n = (1, 2, 2)/3, point = corner − 0.04·n.
  {
    const Eigen::Vector3d corner(1.5, 3, 4.5), n(1.0 / 3, 2.0 / 3, 2.0 / 3);
    box_sphere_geometry(c, h, V3(corner + Eigen::Vector3d(0.04, 0.08, 0.08)), r, g);
    expect_rel(g.penetration, 0.08, "corner overlap");
    expect_vec_near(g.normal, n, "corner normal");
    expect_vec_near(g.point, corner - 0.04 * n, "corner point");
  }
  // Corner (0.5, 1, 4.5) (−x, −y, +z), centre offset (−0.08, −0.04, 0.08): n = (−2, −1, 2)/3.
  {
    const Eigen::Vector3d corner(0.5, 1, 4.5), n(-2.0 / 3, -1.0 / 3, 2.0 / 3);
    box_sphere_geometry(c, h, V3(corner + Eigen::Vector3d(-0.08, -0.04, 0.08)), r, g);
    expect_rel(g.penetration, 0.08, "-x-y+z corner overlap");
    expect_vec_near(g.normal, n, "-x-y+z corner normal");
    expect_vec_near(g.point, corner - 0.04 * n, "-x-y+z corner point");
  }
  // Apart from the corner by 0.3: overlap −0.1 (no contact).
  box_sphere_geometry(c, h, V3(1.5 + 0.1, 3 + 0.2, 4.5 + 0.2), r, g);
  expect_rel(g.penetration, -0.1, "separated overlap");
  // Centre inside, 0.05 below the +z face (0.5 from ±x, 1 from ±y): n = +z, overlap
  // 0.2 + 0.05, point half-way between the face (4.5) and the far sphere surface (4.25).
  box_sphere_geometry(c, h, V3(1, 2, 4.45), r, g);
  expect_rel(g.penetration, 0.25, "inside overlap");
  expect_vec_near(g.normal, {0, 0, 1}, "inside normal");
  expect_vec_near(g.point, {1, 2, 4.375}, "inside point");
  EXPECT_TRUE(g.ratchet_free);
  // Centre inside, 0.03 from the −x face: n = −x, overlap 0.23, point x = (0.5 + 0.73)/2.
  box_sphere_geometry(c, h, V3(0.53, 2.1, 3.2), r, g);
  expect_rel(g.penetration, 0.23, "inside -x overlap");
  expect_vec_near(g.normal, {-1, 0, 0}, "inside -x normal");
  expect_vec_near(g.point, {0.615, 2.1, 3.2}, "inside -x point");
}

// ------------------------------------------------------------------ dt = "auto"

// Exact answer: docs/scenes.md, dt = dt_safety × min R·sqrt(ρ/E) (YADE's PWaveTimeStep). With
// E = 1e8 Pa and ρ = 2500 kg/m³, sqrt(ρ/E) = 0.005 s/m; the smallest radius is 0.5 mm, so the
// critical step is 2.5e-6 s: dt = 1.25e-6 s with dt_safety = 0.5 and 7.5e-7 s with the default
// 0.3.
TEST(SceneFile, AutoTimeStepIsSafetyTimesPWaveStep) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("gs_engine_dt_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream p(dir / "packing.csv");
    p << "id,x,y,z,r\n0,0.001,0.001,0.001,0.001\n1,0.004,0.001,0.001,0.0005\n"
         "2,0.001,0.004,0.001,0.0008\n";
  }
  auto write_scene = [&](const std::string& dt_lines) {
    std::ofstream s(dir / "scene.toml");
    s << "[scene]\nname = \"dt\"\npacking = \"packing.csv\"\n"
         "[material]\nyoung_Pa = 1.0e8\nstiffness_ratio = 0.3\nfriction_deg = 20.0\n"
         "density_kg_m3 = 2500.0\n"
         "[solver]\n"
      << dt_lines << "steps = 10\n";
  };
  write_scene("dt_s = \"auto\"\ndt_safety = 0.5\n");
  Scene a = load_scene(dir / "scene.toml");
  EXPECT_DOUBLE_EQ(a.dt_pwave, 2.5e-6);
  EXPECT_DOUBLE_EQ(a.config.dt, 1.25e-6);
  write_scene("dt_s = \"auto\"\n");
  EXPECT_DOUBLE_EQ(load_scene(dir / "scene.toml").config.dt, 7.5e-7);
  write_scene("dt_s = 2.0e-7\n");  // a number is taken as it is
  EXPECT_EQ(load_scene(dir / "scene.toml").config.dt, 2.0e-7);
  write_scene("dt_s = \"fast\"\n");
  EXPECT_THROW(load_scene(dir / "scene.toml"), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace

// `threads = "auto"`: one thread below kAutoThreadsFrom particles (two were slower than one on
// 883 and 2 000 spheres here, docs/scale.md), the machine's cores from there.
TEST(AutoThreads, OneBelowTheThresholdTheCoresFromIt) {
  EXPECT_EQ(auto_threads(0), 1);
  EXPECT_EQ(auto_threads(kAutoThreadsFrom - 1), 1);
  EXPECT_EQ(auto_threads(kAutoThreadsFrom), std::clamp(omp_get_num_procs(), 1, kMaxThreads));
  EXPECT_EQ(auto_threads(1000000), auto_threads(kAutoThreadsFrom));
}
