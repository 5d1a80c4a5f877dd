// The periodic cell against YADE 2023.02a on the shared cases (label: slow):
// ../shared/reference/yade/periodic (1000 spheres, simple shear at constant volume, L_xz = 2/s)
// and ../shared/reference/yade/periodic2d (600 spheres in the plane, blockedDOFs 'zXY',
// constant-area biaxial strain L = diag(2, −2, 0)/s). READMEs there.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "periodic_case.hpp"
#include "yade_reference.hpp"

using namespace gs;

namespace {

struct PeriodicCase {
  const char* name;
  double dt;
  Eigen::Matrix3d hsize, vel_grad;
  bool planar;
};

PeriodicCase periodic_case(bool planar) {
  PeriodicCase c;
  c.name = planar ? "periodic2d" : "periodic";
  c.planar = planar;
  c.hsize.setZero();
  c.vel_grad.setZero();
  if (planar) {  // case.json of periodic2d
    c.dt = 2.95e-06;
    c.hsize.diagonal() << 0.04783235800060865, 0.04783235800060865, 0.008;
    c.vel_grad(0, 0) = 2.0;
    c.vel_grad(1, 1) = -2.0;
  } else {  // case.json of periodic
    c.dt = 2.58e-06;
    c.hsize.diagonal().setConstant(0.019384323656096786);
    c.vel_grad(0, 2) = 2.0;
  }
  return c;
}

solver::SimulationConfig periodic_config(double dt) {
  solver::SimulationConfig c;
  c.material = test::periodic_material();
  c.damping = 0.05;
  c.dt = dt;
  c.max_overlap_ratio = 0.5;
  return c;
}

Eigen::Matrix3d row_major(const test::CsvTable& t, std::size_t r, const char* prefix) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = t.num(r, prefix + std::to_string(i) + std::to_string(j));
  return m;
}

double max_position_deviation(const solver::ParticleState& p,
                              const std::map<long, std::vector<double>>& ref) {
  double d = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const auto& r = ref.at(p.id[i]);
    d = std::max(d, (p.pos[i] - Eigen::Vector3d(r[0], r[1], r[2])).norm());
  }
  return d;
}

void run_case(bool planar) {
  const PeriodicCase pc = periodic_case(planar);
  const auto dir = test::reference_case_dir(pc.name);
  ASSERT_TRUE(std::filesystem::exists(dir / "packing.csv")) << dir;
  const Frame packing = read_packing_csv(dir / "packing.csv");
  const auto cfg = periodic_config(pc.dt);
  solver::Simulation sim(cfg, packing.particles, {});
  sim.set_periodic(pc.hsize, pc.planar);
  sim.set_velocity_gradient(pc.vel_grad);
  auto perturbed = packing.particles;
  perturbed[100].position.x() = std::nextafter(perturbed[100].position.x(), 1.0);
  solver::Simulation twin(cfg, perturbed, {});
  twin.set_periodic(pc.hsize, pc.planar);
  twin.set_velocity_gradient(pc.vel_grad);
  const auto cell = test::read_csv_table(dir / "out" / "cell.csv");
  const auto stress = test::read_csv_table(dir / "out" / "stress.csv");
  std::map<long, std::size_t> cell_row, stress_row;
  for (std::size_t r = 0; r < cell.rows.size(); ++r) cell_row[std::lround(cell.num(r, "step"))] = r;
  for (std::size_t r = 0; r < stress.rows.size(); ++r)
    stress_row[std::lround(stress.num(r, "step"))] = r;
  double worst_cell = 0, worst_stress = 0, worst_stress_twin = 0;
  long last_strict = 0;
  int compared = 0;
  for (long s = 1; s <= 2000; ++s) {
    sim.step();
    twin.step();
    if (cell_row.count(s)) {
      const auto h = row_major(cell, cell_row[s], "h");
      worst_cell = std::max(worst_cell, (sim.cell().hsize - h).norm() / h.norm());
      const auto f = row_major(cell, cell_row[s], "F");
      worst_cell = std::max(worst_cell, (sim.cell().trsf - f).norm() / f.norm());
    }
    if (stress_row.count(s)) {
      const std::size_t r = stress_row[s];
      const auto ref = row_major(stress, r, "s");
      const Eigen::Matrix3d ours = sim.cell_stress();
      const double rel = (ours - ref).norm() / ref.norm();
      const double rel_twin = (twin.cell_stress() - ours).norm() / ours.norm();
      worst_stress = std::max(worst_stress, rel);
      worst_stress_twin = std::max(worst_stress_twin, rel_twin);
      // While the case's own round-off chaos (the twin) is far below the 1e-6 target, ours must
      // be within it; past that no code that sums its forces in another order than YADE's
      // container can be (README of the test).
      if (worst_stress_twin < 1e-7) {
        EXPECT_LT(rel, 1e-6) << pc.name << ": stress at step " << s;
        last_strict = s;
      }
      EXPECT_NEAR(sim.cell().volume(), stress.num(r, "volume"), 1e-12 * stress.num(r, "volume"));
      EXPECT_EQ(static_cast<long>(sim.contact_count()), std::lround(stress.num(r, "contacts")))
          << "step " << s;
      ++compared;
    }
    if (s % 1000 == 0) {
      char name[64];
      std::snprintf(name, sizeof name, "step_%07ld.csv", s);
      const auto ref = test::read_yade_state(dir / "out" / "states" / name);
      const double d = max_position_deviation(sim.particles(), ref);
      double dtwin = 0;
      for (std::size_t i = 0; i < sim.particles().size(); ++i)
        dtwin = std::max(dtwin, (sim.particles().pos[i] - twin.particles().pos[i]).norm());
      std::printf(
          "%s step %ld: max |x - x_yade| = %.3e m (1-ulp twin %.3e m); cell within %.3e, "
          "stress within %.3e relative (twin %.3e) so far; %zu contacts\n",
          pc.name, s, d, dtwin, worst_cell, worst_stress, worst_stress_twin, sim.contact_count());
      if (s == 1000) {
        EXPECT_LT(d, 1e-9) << pc.name << ": positions after 1000 steps";
      }
    }
  }
  EXPECT_GT(compared, 20);
  EXPECT_LT(worst_cell, 1e-12) << pc.name << ": cell matrix and deformation gradient";
  std::printf(
      "%s: stress within 1e-6 of YADE's asserted up to step %ld (the twin's own deviation "
      "below 1e-7 until then); over 2000 steps from YADE %.3e, twin %.3e\n",
      pc.name, last_strict, worst_stress, worst_stress_twin);
  EXPECT_GE(last_strict, 1500) << pc.name;
  EXPECT_LT(worst_stress, 2 * worst_stress_twin) << pc.name << ": beyond round-off chaos";
}

}  // namespace

TEST(YadePeriodic, SimpleShearMatchesYade) {
  run_case(false);
}

TEST(YadePeriodic, PlanarBiaxialMatchesYade) {
  run_case(true);
}
