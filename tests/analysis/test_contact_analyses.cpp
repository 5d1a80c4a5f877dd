// Rose diagrams (counts sum to the contacts, exact bins, uniform density), force chains (hand
// example) and wall loads (hand-built silo: P, T, N, G, phi_w and the stress distribution).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "contact_rose.hpp"
#include "force_chains.hpp"
#include "love_weber_stress.hpp"
#include "wall_stress.hpp"

namespace ga = gs::analysis;

namespace {

constexpr double kPi = std::numbers::pi;

std::vector<ga::RoseContact> random_contacts(int n, unsigned seed, bool planar) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 3.0);
  std::vector<ga::RoseContact> c;
  for (int k = 0; k < n; ++k)
    c.push_back({Eigen::Vector3d(g(rng), g(rng), planar ? 0.0 : g(rng)).normalized(), u(rng),
                 0.3 * u(rng)});
  return c;
}

TEST(ContactRose, CountsSumToTheContactsAndBinsAreExact) {
  const auto c = random_contacts(5000, 1, false);
  const Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  const auto r2 = ga::contact_rose_2d(c, axes, 36);
  double sum = 0.0, dens = 0.0, fn = 0.0, all_fn = 0.0;
  for (std::size_t k = 0; k < r2.count.size(); ++k) {
    sum += r2.count[k];
    dens += r2.density[k] * r2.bin_size;
    fn += r2.mean_fn[k] * r2.count[k];
  }
  for (const auto& x : c) all_fn += x.fn;
  EXPECT_EQ(r2.contacts, 5000u);
  EXPECT_DOUBLE_EQ(sum, 5000.0);
  EXPECT_NEAR(dens, 1.0, 1e-12);
  EXPECT_NEAR(fn, all_fn, 1e-9 * all_fn);  // mean force x count restores the total
  EXPECT_NEAR(r2.angle_deg[0], 5.0, 1e-12);
  // Central symmetry: bin k and k + 18 hold the same contacts.
  for (std::size_t k = 0; k < 18; ++k) EXPECT_DOUBLE_EQ(r2.count[k], r2.count[k + 18]);
  const auto r3 = ga::contact_rose_3d(c, axes, 18, 36);
  sum = dens = 0.0;
  for (std::size_t k = 0; k < r3.count.size(); ++k) {
    sum += r3.count[k];
    dens += r3.density[k] * r3.bin_size;
  }
  EXPECT_DOUBLE_EQ(sum, 5000.0);
  EXPECT_NEAR(dens, 1.0, 1e-12);
  EXPECT_NEAR(r3.bin_size, 4 * kPi / (18 * 36), 1e-15);
  // Known directions: contacts at 30 deg in the x-y plane with Fn = 2 fall in the 30–40 and
  // 210–220 deg bins, half each.
  std::vector<ga::RoseContact> k30(
      8, {Eigen::Vector3d(std::cos(kPi / 6 + 1e-9), std::sin(kPi / 6 + 1e-9), 0.0), 2.0, 0.5});
  k30.push_back({Eigen::Vector3d::UnitZ(), 9.0, 9.0});  // perpendicular to the plane: skipped
  const auto rk = ga::contact_rose_2d(k30, axes, 36);
  EXPECT_EQ(rk.skipped, 1u);
  EXPECT_DOUBLE_EQ(rk.count[3], 4.0);
  EXPECT_DOUBLE_EQ(rk.count[21], 4.0);
  EXPECT_DOUBLE_EQ(rk.mean_fn[3], 2.0);
  EXPECT_DOUBLE_EQ(rk.mean_fs[21], 0.5);
  EXPECT_TRUE(std::isnan(rk.mean_fn[0]));
  EXPECT_THROW(ga::contact_rose_2d(c, axes, 1), std::invalid_argument);
  EXPECT_THROW(ga::contact_rose_3d(c, axes, 0, 4), std::invalid_argument);
}

TEST(ContactRose, UniformNormalsGiveUniformDensityOnEqualAreaBins) {
  // 40 000 uniform normals into 8 x 16 equal-area bins: each count is Poisson-like about
  // 312.5 (two half-counts per contact make it sum of pairs), density 1 / (4 pi); all bins
  // within 5 standard deviations.
  const auto c = random_contacts(40000, 2, false);
  const auto r = ga::contact_rose_3d(c, Eigen::Matrix3d::Identity(), 8, 16);
  const double expect = 40000.0 / (8 * 16);
  for (std::size_t k = 0; k < r.count.size(); ++k) {
    EXPECT_NEAR(r.count[k], expect, 5 * std::sqrt(expect)) << k;
    EXPECT_NEAR(r.direction[k].norm(), 1.0, 1e-14);
  }
}

gs::Contact contact(std::int64_t a, std::int64_t b, const Eigen::Vector3d& n, double fn) {
  gs::Contact c;
  c.id1 = a;
  c.id2 = b;
  c.normal = n;
  c.normal_force = fn * n;
  return c;
}

TEST(ForceChains, StrongNetworkAndChains) {
  // Six spheres in a row along x: contacts 0-1, 1-2 strong (10 N), 2-3 weak (1 N), 3-4, 4-5
  // strong (10 N): mean 41/5 = 8.2 N, so two chains of 3 particles; plus a weak wall contact.
  gs::Frame f;
  for (int i = 0; i < 6; ++i) {
    gs::Particle p;
    p.id = i;
    p.radius = 0.5;
    p.position = Eigen::Vector3d(i, 0, 0);
    f.particles.push_back(p);
  }
  const double fn[5] = {10, 10, 1, 10, 10};
  for (int i = 0; i < 5; ++i)
    f.contacts.push_back(contact(i, i + 1, Eigen::Vector3d::UnitX(), fn[i]));
  gs::Contact w = contact(0, 6, -Eigen::Vector3d::UnitX(), 2.0);  // body 6: a wall
  w.point = Eigen::Vector3d(-0.5, 0, 0);
  f.contacts.push_back(w);
  const auto b = ga::contact_branches(f);
  const auto fc = ga::force_chains(f, b, {});
  EXPECT_EQ(fc.fn.size(), 5u);  // wall contact left out by default
  EXPECT_NEAR(fc.mean_fn, 8.2, 1e-14);
  EXPECT_EQ(fc.strong_count, 4u);
  EXPECT_EQ(fc.chains, 2u);
  EXPECT_EQ(fc.largest_chain, 3u);
  EXPECT_EQ(fc.chain[0], fc.chain[1]);
  EXPECT_NE(fc.chain[0], fc.chain[3]);
  EXPECT_EQ(fc.chain[2], -1);
  EXPECT_EQ(fc.b[0], Eigen::Vector3d(1, 0, 0));
  ga::ChainOptions o;
  o.threshold_n = 0.5;  // everything strong: one chain of 6
  o.walls = true;
  const auto all = ga::force_chains(f, b, o);
  EXPECT_EQ(all.fn.size(), 6u);
  EXPECT_EQ(all.strong_count, 6u);
  EXPECT_EQ(all.chains, 1u);
  EXPECT_EQ(all.largest_chain, 6u);
  EXPECT_EQ(all.b[5], Eigen::Vector3d(-0.5, 0, 0));
  o.threshold_n = std::nan("");
  EXPECT_THROW(ga::force_chains(f, b, o), std::invalid_argument);
}

TEST(WallLoads, SiloResultantsAndDistribution) {
  // A 2 m deep silo section: bottom wall (normal +z) and left / right side walls (normals +x,
  // -x). Particles of 1 kg. Bottom contacts push down with 5 N each; each side contact pushes
  // outwards with 3 N and drags down with 1 N; one side contact is stored wall-first.
  gs::Frame f;
  const std::int64_t bottom = 100, left = 101, right = 102;
  for (int i = 0; i < 6; ++i) {
    gs::Particle p;
    p.id = i;
    p.radius = 0.5;
    p.mass = 1.0;
    p.position = Eigen::Vector3d(i % 2 ? 3.5 : 0.5, 0.0, 0.5 + i / 2);
    f.particles.push_back(p);
  }
  auto wall = [&](std::int64_t id, const Eigen::Vector3d& a, const Eigen::Vector3d& n) {
    gs::Wall w;
    w.id = id;
    w.a = a;
    w.b = n;
    f.walls.push_back(w);
  };
  wall(bottom, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ());
  wall(left, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  wall(right, Eigen::Vector3d(4, 0, 0), -Eigen::Vector3d::UnitX());
  for (int i = 0; i < 2; ++i) {  // spheres 0 and 1 sit on the bottom
    gs::Contact c = contact(i, bottom, -Eigen::Vector3d::UnitZ(), 5.0);
    c.point = f.particles[static_cast<std::size_t>(i)].position - Eigen::Vector3d(0, 0, 0.5);
    f.contacts.push_back(c);
  }
  for (int i = 0; i < 6; ++i) {
    const bool l = i % 2 == 0;
    const Eigen::Vector3d out(l ? -1.0 : 1.0, 0.0, 0.0);
    gs::Contact c;
    if (i == 2) {  // stored as wall on particle: the opposite forces
      c = contact(left, i, -out, 3.0);
      c.shear_force = Eigen::Vector3d(0, 0, 1.0);
    } else {
      c = contact(i, l ? left : right, out, 3.0);
      c.shear_force = Eigen::Vector3d(0, 0, -1.0);
    }
    c.point = f.particles[static_cast<std::size_t>(i)].position + 0.5 * out;
    f.contacts.push_back(c);
  }
  ga::WallOptions o;
  o.bin = 1.0;
  o.width = 2.0;
  o.gravity = 10.0;
  const auto w = ga::wall_loads(f, ga::contact_branches(f), o);
  ASSERT_EQ(w.walls.size(), 3u);
  EXPECT_EQ(w.walls[0].role, "bottom");
  EXPECT_EQ(w.walls[1].role, "side");
  EXPECT_NEAR(w.P, 10.0, 1e-14);
  EXPECT_NEAR(w.walls[1].N, 9.0, 1e-14);
  EXPECT_NEAR(w.walls[1].T, 3.0, 1e-14);
  EXPECT_NEAR(w.walls[2].T, 3.0, 1e-14);
  EXPECT_NEAR(w.walls[1].phi_deg, std::atan(1.0 / 3.0) * 180 / kPi, 1e-12);
  EXPECT_NEAR(w.T, 6.0, 1e-14);
  EXPECT_NEAR(w.N, 18.0, 1e-14);
  EXPECT_NEAR(w.G, 60.0, 1e-14);
  // Distribution along the left wall: one contact per 1 m bin at heights 0.5, 1.5, 2.5:
  // sigma_n = 3 N / (1 m x 2 m), tau = 1 N / 2 m^2 (downward drag positive).
  const auto& lw = w.walls[1];
  ASSERT_EQ(lw.sigma_n.size(), 3u);  // contact heights 0.5..2.5: bins centred on them
  double sn = 0.0, tau = 0.0, cnt = 0.0;
  for (std::size_t k = 0; k < lw.sigma_n.size(); ++k) {
    sn += lw.sigma_n[k] * 2.0;
    tau += lw.tau[k] * 2.0;
    cnt += lw.count[k];
  }
  EXPECT_NEAR(lw.position[0], 0.5, 1e-14);
  EXPECT_NEAR(lw.sigma_n[1], 1.5, 1e-14);
  EXPECT_NEAR(lw.tau[2], 0.5, 1e-14);
  EXPECT_NEAR(sn, 9.0, 1e-14);
  EXPECT_NEAR(tau, 3.0, 1e-14);
  EXPECT_EQ(cnt, 3.0);
  o.bin = 0.0;
  EXPECT_THROW(ga::wall_loads(f, ga::contact_branches(f), o), std::invalid_argument);
}

}  // namespace
