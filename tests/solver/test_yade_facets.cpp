// Triangle-mesh walls against YADE 2023.02a on the shared facet silo (1 000 spheres draining
// through the orifice of a 48-facet silo with a saw-tooth wall;
// ../shared/reference/yade/facets/README.md), in YADE-parity mode. Label: slow.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "mesh_walls.hpp"
#include "reference_case.hpp"
#include "simulation.hpp"

using namespace gs;

namespace {

using Table = test::CsvTable;

Table read_table(const std::filesystem::path& p) {
  return test::read_csv_table(p);
}

std::filesystem::path reference_dir() {
  return test::reference_case_dir("facets");
}

solver::MeshTriangles read_mesh_csv(const std::filesystem::path& p) {
  const Table t = read_table(p);
  solver::MeshTriangles m;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    std::array<Eigen::Vector3d, 3> tri;
    static const char* const cols[3][3] = {
        {"v0x", "v0y", "v0z"}, {"v1x", "v1y", "v1z"}, {"v2x", "v2y", "v2z"}};
    for (std::size_t v = 0; v < 3; ++v)
      tri[v] = {t.num(r, cols[v][0]), t.num(r, cols[v][1]), t.num(r, cols[v][2])};
    m.triangles.push_back(tri);
    m.group.push_back(t.str(r, "group"));
  }
  return m;
}

/// case.json: CohFrictMat, NewtonIntegrator(damping 0.1), dt 1.43e-5 s.
solver::SimulationConfig facet_config() {
  solver::SimulationConfig c;
  c.material.young_ec = 2e6;
  c.material.stiffness_ratio = 0.3;
  c.material.friction_deg = 18;
  c.material.density = 2550;
  c.material.rolling_beta = 0.5;
  c.material.rolling_eta = 0.2;
  c.material.rolling_radius = solver::RollingRadius::Min;
  c.damping = 0.1;
  c.gravity = Eigen::Vector3d(0, 0, -9.81);
  c.dt = 1.43e-5;
  c.threads = 1;
  c.max_overlap_ratio = 1.0;  // (spheres that left fall freely; none is squeezed)
  return c;
}

std::vector<Particle> read_packing(const std::filesystem::path& p) {
  const Table t = read_table(p);
  std::vector<Particle> ps;
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    Particle q;
    q.id = std::lround(t.num(r, "id"));
    q.position = {t.num(r, "x"), t.num(r, "y"), t.num(r, "z")};
    q.radius = t.num(r, "r");
    ps.push_back(q);
  }
  return ps;
}

std::size_t spheres_out(const solver::ParticleState& p) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < p.size(); ++i) n += p.pos[i].z() < -p.radius[i];
  return n;
}

}  // namespace

// Exact answer: YADE's own facets (utils.facet: the body at the incircle centre, the unit
// normal), out/facets_yade.csv, to the bit.
TEST(YadeFacets, FacetCentresAndNormalsAreYades) {
  const auto dir = reference_dir();
  ASSERT_TRUE(std::filesystem::exists(dir / "mesh.csv")) << dir;
  const auto walls =
      solver::mesh_walls(read_mesh_csv(dir / "mesh.csv"), solver::MeshContact::YadeParity);
  const Table y = read_table(dir / "out" / "facets_yade.csv");
  ASSERT_EQ(walls.size(), y.rows.size());
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const auto& w = walls[k];
    EXPECT_EQ(w.center, Eigen::Vector3d(y.num(k, "cx"), y.num(k, "cy"), y.num(k, "cz"))) << k;
    const auto n = w.facets[0].normal;
    EXPECT_EQ(Eigen::Vector3d(n.x, n.y, n.z),
              Eigen::Vector3d(y.num(k, "nx"), y.num(k, "ny"), y.num(k, "nz")))
        << k;
    EXPECT_NEAR(w.facets[0].area, y.num(k, "area"), 1e-15 * y.num(k, "area")) << k;
    EXPECT_EQ(w.group, y.str(k, "group"));
  }
}

// Exact answer: YADE's run of the same silo. Facet-group forces within 1 % of the largest group
// force over the first 2 000 steps; the number of spheres out of the silo (centre below −r)
// within 5 % (or 10 spheres) of YADE's at every 100 steps over the 20 000 steps; the one-ulp
// twin measures how fast the discharge diverges by itself.
TEST(YadeFacets, GroupForcesAndDischargeMatchYade) {
  const auto dir = reference_dir();
  ASSERT_TRUE(std::filesystem::exists(dir / "packing.csv")) << dir;
  const auto particles = read_packing(dir / "packing.csv");
  const auto walls =
      solver::mesh_walls(read_mesh_csv(dir / "mesh.csv"), solver::MeshContact::YadeParity);
  solver::Simulation sim(facet_config(), particles, walls);
  auto twin_particles = particles;
  twin_particles[100].position.x() = std::nextafter(twin_particles[100].position.x(), 1.0);
  solver::Simulation twin(facet_config(), twin_particles, walls);
  const Table wt = read_table(dir / "out" / "walls.csv");
  std::map<std::pair<long, std::string>, Eigen::Vector3d> ref;
  for (std::size_t r = 0; r < wt.rows.size(); ++r)
    ref[{std::lround(wt.num(r, "step")), wt.str(r, "group")}] =
        Eigen::Vector3d(wt.num(r, "fx"), wt.num(r, "fy"), wt.num(r, "fz"));
  const Table of = read_table(dir / "out" / "outflow.csv");
  std::map<long, double> ref_out;
  for (std::size_t r = 0; r < of.rows.size(); ++r)
    ref_out[std::lround(of.num(r, "step"))] = of.num(r, "n_out");
  double worst_force = 0, worst_twin = 0;
  double worst_out = 0, worst_out_twin = 0;
  bool out_ok = true;
  for (long step = 100; step <= 20000; step += 100) {
    sim.run(100);
    twin.run(100);
    if (step <= 2000) {
      double fmax = 0, dev = 0, dtw = 0;
      const auto ours = solver::group_forces(sim), theirs = solver::group_forces(twin);
      for (std::size_t g = 0; g < ours.size(); ++g) {
        const Eigen::Vector3d f = ref.at({step, ours[g].group});
        fmax = std::max(fmax, f.norm());
        dev = std::max(dev, (ours[g].force - f).norm());
        dtw = std::max(dtw, (ours[g].force - theirs[g].force).norm());
      }
      worst_force = std::max(worst_force, dev / fmax);
      worst_twin = std::max(worst_twin, dtw / fmax);
    }
    const double n = static_cast<double>(spheres_out(sim.particles())), y = ref_out.at(step);
    const double tol = std::max(10.0, 0.05 * y);
    worst_out = std::max(worst_out, std::abs(n - y));
    worst_out_twin =
        std::max(worst_out_twin, std::abs(n - static_cast<double>(spheres_out(twin.particles()))));
    if (std::abs(n - y) > tol) out_ok = false;
    if (step % 5000 == 0)
      std::printf("step %5ld: %3.0f out (YADE %3.0f), contacts %zu\n", step, n, y,
                  sim.contact_count());
  }
  std::printf(
      "group forces, steps 100-2000: largest deviation %.2e of the largest (twin %.2e); "
      "spheres out: largest difference %.0f (twin %.0f)\n",
      worst_force, worst_twin, worst_out, worst_out_twin);
  EXPECT_LT(worst_force, 0.01);
  EXPECT_TRUE(out_ok);
}
