// REV cells: exact void ratios of lattices, Love–Weber stress of an isotropically loaded lattice
// (compression positive), binned = brute force, thread-count independence, 2D and slab grids.
#include <gtest/gtest.h>
#include <omp.h>

#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "love_weber_stress.hpp"
#include "packing_util.hpp"
#include "rev_cells.hpp"

namespace ga = gs::analysis;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();

bool inside(const ga::RevGrid& g, std::size_t c, const Eigen::Vector3d& lo,
            const Eigen::Vector3d& hi) {
  Eigen::Vector3d blo, bhi;
  g.box(c, blo, bhi);
  return (blo.array() >= lo.array()).all() && (bhi.array() <= hi.array()).all();
}

TEST(RevCells, SimpleCubicVoidRatioIsSixOverPiMinusOne) {
  // Spheres of r = 0.5 mm at spacing d = 1 mm; cells L = 5 d moved by d over a region shifted by
  // 0.37 d so that the cell faces cut spheres: every cell holds exactly 5^3 lattice periods.
  const double r = 0.5e-3, d = 1e-3;
  const gs::Frame f = gs::test::cubic_lattice(12, r, 1.0, false);
  ga::RevGridSpec spec;
  spec.cell = 5 * d;
  spec.step = d;
  spec.region = {Eigen::Vector3d::Constant(1.37 * d), Eigen::Vector3d::Constant(10.37 * d)};
  const auto g = ga::make_rev_grid(f, spec);
  ASSERT_EQ(g.count(), 5u * 5u * 5u);
  const auto b = ga::contact_branches(f);
  const auto rf = ga::rev_average(f, b, g);
  const double e = 6.0 / kPi - 1.0;
  for (std::size_t c = 0; c < g.count(); ++c) {
    EXPECT_NEAR(rf.void_ratio[c], e, 1e-12) << c;
    EXPECT_NEAR(rf.solid_fraction[c], kPi / 6.0, 1e-12) << c;
    EXPECT_EQ(rf.particles[c], 125.0);
    EXPECT_NEAR(rf.coordination[c], 6.0, 1e-12);  // interior: 6 contacts per sphere
  }
}

TEST(RevCells, CellFacesTangentToTheSpheres) {
  // The default grid of a simple-cubic lattice (r = 0.5 mm, spacing d = 2r, cells L = 5 d moved
  // by d from the spheres' outer faces): every cell plane is tangent to spheres (up to one
  // rounding of c +- r), every cell holds exactly 5^3 spheres whole: e = 6/pi - 1 in all cells
  // (the binned sum once read a table slot of the next row there: e from 1.1 to 2.3 in 511 of
  // the 512 cells). Same for discs on a square lattice in 2D: e = 4/pi - 1, 5 x 5 discs a cell
  // (once wrong in 63 of 64 cells).
  const double r = 0.5e-3, d = 1e-3;
  gs::Frame f = gs::test::cubic_lattice(12, r, 1.0, false);
  ga::RevGridSpec spec;
  spec.cell = 5 * d;
  spec.step = d;
  const auto g = ga::make_rev_grid(f, spec);
  ASSERT_EQ(g.count(), 8u * 8u * 8u);
  const auto b = ga::contact_branches(f);
  const auto rf = ga::rev_average(f, b, g);
  const auto bf = ga::rev_average_brute_force(f, b, g);
  for (std::size_t c = 0; c < g.count(); ++c) {
    EXPECT_NEAR(rf.void_ratio[c], 6.0 / kPi - 1.0, 1e-12) << c;
    EXPECT_NEAR(bf.void_ratio[c], 6.0 / kPi - 1.0, 1e-12) << c;
    EXPECT_EQ(rf.particles[c], 125.0) << c;
  }
  std::erase_if(f.particles, [](const gs::Particle& p) { return p.position.z() != 0.0; });
  f.contacts.clear();
  f.two_d = true;
  const auto g2 = ga::make_rev_grid(f, spec);
  ASSERT_EQ(g2.count(), 8u * 8u);
  const auto r2 = ga::rev_average(f, ga::contact_branches(f), g2);
  for (std::size_t c = 0; c < g2.count(); ++c) {
    EXPECT_NEAR(r2.void_ratio[c], 4.0 / kPi - 1.0, 1e-12) << c;
    EXPECT_EQ(r2.particles[c], 25.0) << c;
  }
}

TEST(RevCells, FccVoidRatio) {
  // FCC, cube side a = 2 sqrt(2) r: solid fraction pi / (3 sqrt 2), e = 3 sqrt(2) / pi - 1
  // = 0.3505 in every cell of whole periods (L = 3 a), wherever it lies inside the lattice.
  const double r = 0.5e-3, a = 2.0 * std::sqrt(2.0) * r;
  const gs::Frame f = gs::test::fcc_lattice(8, r);
  ga::RevGridSpec spec;
  spec.cell = 3 * a;
  spec.step = 0.41 * a;
  spec.region = {Eigen::Vector3d::Constant(0.6 * a), Eigen::Vector3d::Constant(6.9 * a)};
  const auto g = ga::make_rev_grid(f, spec);
  const auto rf = ga::rev_average(f, ga::contact_branches(f), g);
  const double e = 3.0 * std::sqrt(2.0) / kPi - 1.0;
  EXPECT_NEAR(e, 0.3505, 5e-5);
  std::size_t n = 0;
  for (std::size_t c = 0; c < g.count(); ++c) {
    ASSERT_TRUE(inside(g, c, Eigen::Vector3d::Constant(0.0), Eigen::Vector3d::Constant(7.5 * a)));
    EXPECT_NEAR(rf.void_ratio[c], e, 1e-12) << c;
    ++n;
  }
  EXPECT_GT(n, 100u);
}

TEST(RevCells, LoveWeberStressOfIsotropicLatticeIsThePressure) {
  // Contacts push neighbours apart with F: pressure p = F / (2r)^2 on every face. In every cell
  // inside the lattice the Love–Weber stress is p I, compression positive.
  const double r = 0.5e-3, force = 3.0;
  const double p = force / (4 * r * r);
  const gs::Frame f = gs::test::cubic_lattice(12, r, force, true);
  ga::RevGridSpec spec;
  spec.cell = 10 * r;
  spec.step = 2 * r;
  spec.region = {Eigen::Vector3d::Constant(0.37 * r), Eigen::Vector3d::Constant(21.0 * r)};
  const auto g = ga::make_rev_grid(f, spec);
  const auto b = ga::contact_branches(f);
  EXPECT_EQ(b.wall_contacts, 6u * 144u);
  EXPECT_EQ(b.particle_contacts, 3u * 11u * 144u);
  const auto rf = ga::rev_average(f, b, g);
  ASSERT_GT(g.count(), 10u);
  for (std::size_t c = 0; c < g.count(); ++c) {
    EXPECT_NEAR((rf.stress[c] - p * Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12 * p) << c;
  }
  // The whole specimen (walls included) by Love–Weber and by the boundary form (seed 003 eq 14).
  const Eigen::Vector3d lo = Eigen::Vector3d::Constant(-r), hi = Eigen::Vector3d::Constant(23 * r);
  const Eigen::Matrix3d s = ga::love_weber_stress(b.branches, lo, hi);
  EXPECT_NEAR((s - p * Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12 * p);
  const Eigen::Matrix3d s14 = ga::boundary_stress(f, b, (hi - lo).prod());
  EXPECT_NEAR((s14 - p * Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12 * p);
  // Tension (forces pulling neighbours together) gives a negative stress.
  gs::Frame t = f;
  for (auto& c : t.contacts) c.normal_force = -c.normal_force;
  const auto rt = ga::rev_average(t, ga::contact_branches(t), g);
  EXPECT_NEAR(rt.stress[0](0, 0), -p, 1e-12 * p);
}

/// Simple-cubic lattice of nx x ny x nz spheres (spacing d, radius d/2) in a periodic cell of
/// side n d per axis (origin 0), shifted by `shift` and wrapped into the cell: the neighbour
/// pairs whose centres the wrap puts on opposite sides cross the boundary. Every neighbour
/// pair (the wrap-around ones included) is a contact with a random force (compressive normal
/// part, random shear); id = lattice index.
gs::Frame periodic_lattice(const std::array<int, 3>& n, double d, const Eigen::Vector3d& shift) {
  gs::Frame f;
  f.domain.periodic = true;
  f.domain.lo = Eigen::Vector3d::Zero();
  f.domain.hi = d * Eigen::Vector3d(n[0], n[1], n[2]);
  f.domain.cell = f.domain.hi.asDiagonal();
  const auto id = [&](int i, int j, int k) {
    return static_cast<std::int64_t>(((i % n[0]) + n[0] * ((j % n[1]) + n[1] * (k % n[2]))));
  };
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        gs::Particle p;
        p.id = id(i, j, k);
        p.radius = 0.5 * d;
        const Eigen::Vector3d x = d * Eigen::Vector3d(i, j, k) + shift;
        for (int a = 0; a < 3; ++a) p.position[a] = std::fmod(x[a], f.domain.hi[a]);
        f.particles.push_back(p);
      }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (int a = 0; a < 3; ++a) {
          const int q[3] = {i + (a == 0), j + (a == 1), k + (a == 2)};
          gs::Contact c;
          c.id1 = id(i, j, k);
          c.id2 = id(q[0], q[1], q[2]);
          c.normal = Eigen::Vector3d::Unit(a);
          c.normal_force = (2.0 + u(rng)) * c.normal;  // by id1 on id2: compressive
          c.shear_force = 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
          c.shear_force[a] = 0.0;
          f.contacts.push_back(c);
        }
  return f;
}

TEST(RevCells, PeriodicLoveWeberStressUsesTheMinimumImage) {
  // A periodic 4 x 5 x 6 lattice (d = 1 mm) shifted by (2.5, 1.5, 3.5) d and wrapped: in each
  // lattice line exactly one neighbour pair lies across the boundary (raw centre difference
  // -(n - 1) d), 4*5 + 4*6 + 5*6 = 74 pairs. Exact answers: every minimum-image branch is d e_a,
  // and the stress of the cell is sigma = sum_c (d e_a) f_c^T / V, V = 4*5*6 d^3, summed here
  // from the contacts themselves; the same tensor comes from the non-periodic equivalent, the
  // 3 x 3 x 3 replicas of the cell with every contact, by love_weber_stress over the central
  // cell (the pieces of the branches crossing its faces add up to whole branches).
  const double d = 1e-3;
  const std::array<int, 3> n{4, 5, 6};
  const gs::Frame f = periodic_lattice(n, d, d * Eigen::Vector3d(2.5, 1.5, 3.5));
  const auto b = ga::contact_branches(f);
  ASSERT_EQ(b.particle_contacts, 3u * 120u);
  std::size_t crossing = 0;
  Eigen::Matrix3d hand = Eigen::Matrix3d::Zero();
  for (const auto& br : b.branches) {
    const gs::Contact& c = f.contacts[static_cast<std::size_t>(br.contact)];
    const Eigen::Vector3d l = d * c.normal;  // the lattice neighbour direction e_a
    EXPECT_NEAR((br.branch - l).norm(), 0.0, 1e-18) << br.contact;
    const Eigen::Vector3d raw = f.particles[static_cast<std::size_t>(br.p2)].position -
                                f.particles[static_cast<std::size_t>(br.p1)].position;
    crossing += (raw - l).norm() > 0.5 * d;
    hand += l * (c.normal_force + c.shear_force).transpose();
  }
  EXPECT_EQ(crossing, 74u);
  const double volume = 120.0 * d * d * d;
  hand /= volume;
  const double scale = hand.norm();  // ~ 2 N / d^2
  const Eigen::Matrix3d s = ga::periodic_cell_stress(f, b);
  EXPECT_NEAR((s - hand).norm(), 0.0, 1e-14 * scale);
  // Non-periodic equivalent: 27 replicas, contacts between the replicated particles.
  gs::Frame r;
  const auto n_p = static_cast<std::int64_t>(f.particles.size());
  std::vector<Eigen::Vector3i> shifts;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) shifts.emplace_back(x, y, z);
  for (std::size_t m = 0; m < shifts.size(); ++m)
    for (gs::Particle p : f.particles) {
      p.position += f.domain.cell * shifts[m].cast<double>();
      p.id += static_cast<std::int64_t>(m) * n_p;
      r.particles.push_back(p);
    }
  for (std::size_t m = 0; m < shifts.size(); ++m)
    for (const auto& br : b.branches) {
      // the end particle's replica is the one whose centre is start + l
      const Eigen::Vector3d end =
          r.particles[m * 120 + static_cast<std::size_t>(br.p1)].position + br.branch;
      const Eigen::Vector3d img =
          (end - f.particles[static_cast<std::size_t>(br.p2)].position).cwiseQuotient(f.domain.hi);
      const Eigen::Vector3i k(static_cast<int>(std::lround(img.x())),
                              static_cast<int>(std::lround(img.y())),
                              static_cast<int>(std::lround(img.z())));
      if ((k.array().abs() > 1).any()) continue;  // outside the replicas: no piece in the centre
      const auto mk = static_cast<std::size_t>((k.x() + 1) + 3 * ((k.y() + 1) + 3 * (k.z() + 1)));
      gs::Contact c = f.contacts[static_cast<std::size_t>(br.contact)];
      c.id1 = r.particles[m * 120 + static_cast<std::size_t>(br.p1)].id;
      c.id2 = r.particles[mk * 120 + static_cast<std::size_t>(br.p2)].id;
      r.contacts.push_back(c);
    }
  const auto rb = ga::contact_branches(r);
  const Eigen::Matrix3d sr = ga::love_weber_stress(rb.branches, f.domain.lo, f.domain.hi);
  EXPECT_NEAR((sr - hand).norm(), 0.0, 1e-14 * scale);
  // Without the minimum image (the same frame, not periodic) the 74 crossing branches would
  // span the cell and the stress would be different: the check above is not vacuous.
  gs::Frame np = f;
  np.domain.periodic = false;
  Eigen::Matrix3d raw_sum = Eigen::Matrix3d::Zero();
  for (const auto& br : ga::contact_branches(np).branches)
    raw_sum += br.branch * br.force.transpose();
  EXPECT_GT((raw_sum / volume - hand).norm(), 0.5 * scale);
  EXPECT_THROW(ga::periodic_cell_stress(np, b), std::invalid_argument);
}

void expect_same(const ga::RevFields& a, const ga::RevFields& b, double stress_scale,
                 const std::vector<std::size_t>& cells) {
  for (const std::size_t c : cells) {
    EXPECT_NEAR(a.solid_volume[c], b.solid_volume[c], 1e-12 * b.solid_volume[c] + 1e-30) << c;
    EXPECT_EQ(a.particles[c], b.particles[c]) << c;
    if (b.solid_volume[c] > 0) {
      EXPECT_NEAR(a.coordination[c], b.coordination[c], 1e-12 * (1 + b.coordination[c])) << c;
      EXPECT_NEAR((a.rotation[c] - b.rotation[c]).norm(), 0.0, 1e-12) << c;
      if (!b.displacement.empty() && std::isfinite(b.displacement[c].x())) {
        EXPECT_NEAR((a.displacement[c] - b.displacement[c]).norm(), 0.0, 1e-15) << c;
      }
    }
    EXPECT_NEAR((a.stress[c] - b.stress[c]).norm(), 0.0, 1e-12 * stress_scale) << c;
  }
}

TEST(RevCells, BinnedEqualsBruteForce3DSlabAnd2D) {
  const double sp = 1e-3;
  const gs::Frame f = gs::test::random_packing(10, sp, 3);
  const auto b = ga::contact_branches(f);
  EXPECT_GT(b.particle_contacts, 800u);  // about one per particle
  EXPECT_GT(b.wall_contacts, 10u);
  ga::ParticleMotion m;
  for (std::size_t i = 0; i < f.particles.size(); ++i) {
    m.u.push_back(1e-6 * Eigen::Vector3d(std::sin(i), std::cos(i), 0.5));
    m.matched.push_back(i % 7 != 0);
  }
  const double scale = 1.0 / (sp * sp);  // ~ force / area
  std::vector<std::size_t> all;
  {
    ga::RevGridSpec spec;
    spec.cell = 3.1 * sp;  // not a multiple of the step
    spec.step = 0.9 * sp;
    const auto g = ga::make_rev_grid(f, spec);
    for (std::size_t c = 0; c < g.count(); ++c) all.push_back(c);
    expect_same(ga::rev_average(f, b, g, m), ga::rev_average_brute_force(f, b, g, m), scale, all);
    spec.cell = 1.05 * sp;  // step far below the sphere size: too many planes for the tables
    spec.step = 0.1 * sp;
    spec.region = {Eigen::Vector3d::Constant(3 * sp), Eigen::Vector3d::Constant(4.5 * sp)};
    const auto g2 = ga::make_rev_grid(f, spec);
    std::vector<std::size_t> cells;
    for (std::size_t c = 0; c < g2.count(); ++c) cells.push_back(c);
    expect_same(ga::rev_average(f, b, g2, m), ga::rev_average_brute_force(f, b, g2, m), scale,
                cells);
  }
  {
    ga::RevGridSpec spec;  // tilted slab through the middle, cells smaller than the spheres
    spec.cell = 0.8 * sp;
    spec.step = 0.3 * sp;
    spec.slab = ga::Slab{Eigen::Vector3d(5, 5, 5) * sp, Eigen::Vector3d(0.3, 1.0, 0.2),
                         Eigen::Vector3d(1, 0, 0.1), 2.3 * sp};
    const auto g = ga::make_rev_grid(f, spec);
    EXPECT_EQ(g.n[2], 1);
    std::vector<std::size_t> cells;
    for (std::size_t c = 0; c < g.count(); c += 3) cells.push_back(c);
    const auto fast = ga::rev_average(f, b, g, m);
    expect_same(fast, ga::rev_average_brute_force(f, b, g, m, cells), scale, cells);
    std::size_t with_solid = 0;
    for (std::size_t c : cells) with_solid += fast.solid_volume[c] > 0;
    EXPECT_GT(with_solid, cells.size() / 2);
  }
  {
    gs::Frame f2 = f;  // 2D frame: discs in the x-y plane
    f2.two_d = true;
    for (auto& p : f2.particles) p.position.z() = 0.0;
    const auto b2 = ga::contact_branches(f2);
    ga::RevGridSpec spec;
    spec.cell = 2.5 * sp;
    spec.step = 0.5 * sp;
    const auto g = ga::make_rev_grid(f2, spec);
    EXPECT_EQ(g.dim, 2);
    std::vector<std::size_t> cells;
    for (std::size_t c = 0; c < g.count(); ++c) cells.push_back(c);
    expect_same(ga::rev_average(f2, b2, g, m), ga::rev_average_brute_force(f2, b2, g, m), scale,
                cells);
  }
}

TEST(RevCells, ResultsDoNotDependOnThreadCount) {
  const gs::Frame f = gs::test::random_packing(9, 1e-3, 5);
  const auto b = ga::contact_branches(f);
  ga::RevGridSpec spec;
  spec.cell = 2.5e-3;
  spec.step = 0.5e-3;
  const auto g = ga::make_rev_grid(f, spec);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto one = ga::rev_average(f, b, g);
  omp_set_num_threads(3);
  const auto three = ga::rev_average(f, b, g);
  omp_set_num_threads(threads);
  for (std::size_t c = 0; c < g.count(); ++c) {
    EXPECT_EQ(one.solid_volume[c], three.solid_volume[c]);
    EXPECT_EQ(one.stress[c], three.stress[c]);
    EXPECT_EQ(one.rotation[c].x(), three.rotation[c].x());
  }
}

/// The message of the std::invalid_argument that `f` throws ("" when it throws none).
template <class F>
std::string invalid_argument_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(RevCells, RejectsBadGrids) {
  // Cell sizes L = 0 (no volume to divide by), negative, NaN and infinite are refused with the
  // message "REV cell size must be > 0 (L)"; a grid of points (L = 0) is for coarse-graining
  // only, and REV averages refuse it.
  const gs::Frame f = gs::test::cubic_lattice(4, 0.5e-3, 1.0, false);
  ga::RevGridSpec spec;
  spec.step = 1e-3;
  for (const double bad : {0.0, -0.0, -1.0, std::nan(""), kInf, -kInf}) {
    spec.cell = bad;
    const std::string what = invalid_argument_of([&] { ga::make_rev_grid(f, spec); });
    EXPECT_EQ(what.rfind("REV cell size must be > 0 (", 0), 0u) << bad << ": " << what;
  }
  spec.cell = 0.0;
  const auto points = ga::make_point_grid(f, spec);
  EXPECT_EQ(points.measure(), 0.0);
  const auto b = ga::contact_branches(f);
  EXPECT_NE(invalid_argument_of([&] { ga::rev_average(f, b, points); }).find("size > 0"),
            std::string::npos);
  EXPECT_NE(
      invalid_argument_of([&] { ga::rev_average_brute_force(f, b, points); }).find("size > 0"),
      std::string::npos);
  spec.cell = 1e-3;  // a grid of points has no cell size
  EXPECT_THROW(ga::make_point_grid(f, spec), std::invalid_argument);
  spec.step = 0.0;
  EXPECT_THROW(ga::make_rev_grid(f, spec), std::invalid_argument);
  spec.step = 1e-3;
  spec.cell = 1.0;  // larger than the specimen
  EXPECT_THROW(ga::make_rev_grid(f, spec), std::invalid_argument);
  spec.cell = 1e-3;
  spec.slab = ga::Slab{Eigen::Vector3d(0, 0, 1.0), Eigen::Vector3d::UnitZ(),
                       Eigen::Vector3d::UnitX(), 1e-3};  // far above the specimen
  EXPECT_THROW(ga::make_rev_grid(f, spec), std::invalid_argument);
}

TEST(RevCells, InterpolationIsExactForLinearFields) {
  const gs::Frame f = gs::test::cubic_lattice(8, 0.5e-3, 1.0, false);
  ga::RevGridSpec spec;
  spec.cell = 2e-3;
  spec.step = 1e-3;
  const auto g = ga::make_rev_grid(f, spec);
  std::vector<double> v(g.count());
  for (std::size_t c = 0; c < g.count(); ++c) v[c] = g.centre(c).dot(Eigen::Vector3d(1, -2, 3));
  const Eigen::Vector3d x(3.3e-3, 2.1e-3, 4.9e-3);
  double s = 0.0;
  for (const auto& [c, w] : ga::rev_interpolation(g, x)) s += w * v[c];
  EXPECT_NEAR(s, x.dot(Eigen::Vector3d(1, -2, 3)), 1e-15);
  EXPECT_TRUE(ga::rev_interpolation(g, Eigen::Vector3d(1, 1, 1)).empty());
}

}  // namespace
