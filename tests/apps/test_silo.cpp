// `simulate` of the model silo (seed 004 §5.2) on a small silo, end to end: the filling in
// layers, then the bottom moving down (quasi-static mode) or an outlet opening (gravitational
// mode), with the curve of the wall forces of §5.3.1 normalised by the weight; and the silo's
// bad inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "../dic/h5_read.hpp"
#include "../io/test_util.hpp"
#include "cli_util.hpp"

#include "hdf5_trajectory.hpp"
#include "sphere_box_volume.hpp"

namespace {

using gs::test::read_csv_table;
using gs::test::replaced;
using gs::test::run_cli;

// 120 grains of 1.5–2.5 mm in a 20 × 30 × 7.5 mm silo with R_n = 1 teeth (2 mm: d50 by mass
// of the straight grading), two layers; the seed's material (Table 5.1).
std::string scene(const std::string& silo, const std::string& extra = "") {
  return "[scene]\nname = \"silo\"\ntest = \"silo\"\n"
         "[material]\nyoung_Pa = 1.0e7\nstiffness_ratio = 0.3\nfriction_deg = 25.0\n"
         "density_kg_m3 = 2600.0\nrolling_stiffness = 0.2\nrolling_limit = 0.4\n"
         "[solver]\ndt_s = \"auto\"\ndt_safety = 0.5\ndamping = 0.3\n"
         "gravity_m_s2 = [0.0, 0.0, -9.81]\n"
         "[output]\nevery = 5000\nhistory_every = 1000\ncurve_every = 200\n"
         "checkpoint_every = 20000\n"
         "[fill]\nregion_lo_m = [0.0021, 0.0, 0.012]\nregion_hi_m = [0.0179, 0.0075, 0.03]\n"
         "layers = 2\ncount = 120\ndmin_m = 0.0015\ndmax_m = 0.0025\ndistribution = \"linear\"\n"
         "seed = 1\n" +
         extra + "[silo]\nwidth_m = 0.02\nheight_m = 0.03\ndepth_m = 0.0075\nroughness = 1.0\n" +
         silo;
}

const std::string kQuasi =
    "mode = \"quasi_static\"\nbottom_velocity_m_s = 0.005\nbottom_travel_m = 0.001\n"
    "frame_every_m = 0.00025\n";
const std::string kGravity =
    "mode = \"gravitational\"\noutlet = \"centre\"\noutlet_width_m = 0.008\nsettle_s = 0.02\n"
    "max_discharge_s = 1.0\nend_fraction = 0.9\nframe_every_s = 0.05\n";

}  // namespace

TEST(Silo, QuasiStaticBottomMovesAndTheForcesBalanceTheWeight) {
  gs::test::ScratchDir dir("silo_quasi");
  std::ofstream(dir / "silo.toml") << scene(kQuasi);
  const auto r = run_cli(
      "simulate " + (dir / "silo.toml").string() + " -q -o " + (dir / "out").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto c = read_csv_table(dir / "out" / "curve.csv");
  ASSERT_GE(c.rows.size(), 3u);
  // G is the weight of all 120 grains (all in the silo), exactly.
  const auto t = gs::read_hdf5_trajectory(dir / "out" / "trajectory.h5");
  const auto& last = t.frames.back();
  ASSERT_EQ(last.particles.size(), 120u);
  double weight = 0;
  for (const auto& p : last.particles) weight += p.mass * 9.81;
  EXPECT_NEAR(c.num(0, "G_N"), weight, 1e-12 * weight);
  // At the end of the filling the grains are at rest: the bottom and the two walls carry the
  // weight, G = P + T_left + T_right (seed 004 §5.3.1: G = 2T + P).
  EXPECT_EQ(c.num(0, "u_m"), 0.0);
  EXPECT_NEAR(c.num(0, "balance_G"), 1.0, 0.03);
  EXPECT_NEAR(c.num(0, "balance_G"), c.num(0, "P_G") + c.num(0, "T_left_G") + c.num(0, "T_right_G"),
              1e-5);
  // The void ratio in the gauge box, recomputed from the frame that ends the filling: the box
  // one largest grain (2.5 mm) clear of the teeth's tips (h_g = R_n·d50, d50 = 2 mm by mass for
  // the straight grading 1.5–2.5 mm), of the bottom (z = 0) and of the surface (the mean top of
  // the highest 5 % of grains), over the whole depth.
  const gs::Frame* filled = nullptr;
  for (const auto& f : t.frames)
    if (std::abs(f.time - c.num(0, "time_s")) < 1e-12) filled = &f;
  ASSERT_NE(filled, nullptr);
  std::vector<double> tops;
  for (const auto& p : filled->particles) tops.push_back(p.position.z() + p.radius);
  std::sort(tops.begin(), tops.end());
  const std::size_t n_top = tops.size() / 20;
  double surface = 0;
  for (std::size_t k = tops.size() - n_top; k < tops.size(); ++k) surface += tops[k] / n_top;
  const Eigen::Vector3d lo(0.002 + 0.0025, 0, 0.0025), hi(0.02 - 0.0045, 0.0075, surface - 0.0025);
  double solid = 0;
  for (const auto& p : filled->particles)
    solid += gs::sphere_box_volume(p.position, p.radius, lo, hi);
  EXPECT_NEAR(c.num(0, "void_ratio"), (hi - lo).prod() / solid - 1, 1e-5);
  EXPECT_NE(r.out.find("e0 = "), std::string::npos) << r.out;
  // The bottom moves down at its speed until it has travelled u = 1 mm.
  double u = 0;
  for (std::size_t i = 1; i < c.rows.size(); ++i) {
    EXPECT_GE(c.num(i, "u_m"), u);
    u = c.num(i, "u_m");
    EXPECT_NEAR(c.num(i, "u_m"), 0.005 * c.num(i, "flow_time_s"), 1e-12);
  }
  EXPECT_GE(u, 0.001);
  EXPECT_LT(u, 0.001 + 0.005 * 1e-5);
  // Frames at u = 0.25, 0.5, 0.75 and 1 mm after the one that ends the filling.
  int after = 0;
  for (const auto& f : t.frames) after += f.time > c.num(0, "time_s") + 1e-12;
  EXPECT_EQ(after, 4);
  // `analyze silo` on the frames gives the curve's forces again (the last frame and the last
  // row are the final step), and refuses a frame index it does not have.
  const auto rep =
      run_cli("analyze silo " + (dir / "out" / "trajectory.h5").string() + " -o " +
                  (dir / "silo_report.h5").string() + " --csv " + (dir / "series.csv").string(),
              dir.path);
  ASSERT_EQ(rep.rc, 0) << rep.err;
  const auto s = read_csv_table(dir / "series.csv");
  const std::size_t m = s.rows.size() - 1, e = c.rows.size() - 1;
  // (the report's CSV has 12 significant digits)
  EXPECT_NEAR(s.num(m, "time_s"), c.num(e, "time_s"), 1e-11);
  for (const char* col : {"G_N", "P_N", "T_left_N", "T_right_N", "N_left_N", "N_right_N"})
    EXPECT_NEAR(s.num(m, col), c.num(e, col), 1e-10 * c.num(e, "G_N")) << col;
  EXPECT_NE(rep.out.find("residual"), std::string::npos);
  // The wall zones per frame, the last the residual state's.
  const auto zone = gs::test::h5::read(dir / "silo_report.h5", "/series/zone_extent_left_m");
  ASSERT_EQ(zone.size(), s.rows.size());
  for (const char* col :
       {"zone_left_m", "zone_right_m", "zone_extent_left_m", "zone_extent_right_m"})
    (void)s.num(m, col);
  // The report's lengths in d50 are in the d50 the scene made its teeth by (R_n = h_g/d50),
  // which the run recorded: here the straight grading's median by mass.
  std::string recorded;
  for (const auto& [key, value] : t.metadata.parameters)
    if (key == "scene.d50_m") recorded = value;
  ASSERT_FALSE(recorded.empty());
  EXPECT_NEAR(std::stod(recorded), 0.002, 1e-15);
  const auto at = rep.out.find("d50 ");
  ASSERT_NE(at, std::string::npos) << rep.out;
  EXPECT_NEAR(std::stod(rep.out.substr(at + 4)), std::stod(recorded), 1e-5 * std::stod(recorded))
      << rep.out;
  EXPECT_NE(rep.out.find("(the scene's)"), std::string::npos) << rep.out;
  const auto bad = run_cli("analyze silo " + (dir / "out" / "trajectory.h5").string() + " -o " +
                               (dir / "x.h5").string() + " --from 999",
                           dir.path);
  EXPECT_EQ(bad.rc, 2);
  EXPECT_NE(bad.err.find("--from: no such frame"), std::string::npos) << bad.err;
  // The void-ratio layers, the left half's fabric and the slice method are in the report: the
  // grains' solid volume over the boxes of a layer is at most the boxes' (e ≥ 0).
  EXPECT_NE(rep.out.find("void ratio at"), std::string::npos) << rep.out;
  EXPECT_NE(rep.out.find("left half:"), std::string::npos) << rep.out;
  EXPECT_NE(rep.out.find("slice method"), std::string::npos) << rep.out;
  EXPECT_NE(rep.out.find("flow: "), std::string::npos) << rep.out;
  // The bottom moving down carries the grains down: the last frame is not at rest.
  const auto pattern = gs::test::h5::read(dir / "silo_report.h5", "/series/flow_pattern");
  ASSERT_GT(pattern.size(), 2u);
  EXPECT_NE(pattern.v.back(), 0.0);
  const auto voids =
      gs::test::h5::read(dir / "silo_report.h5", "/profiles/residual/layer_void_ratio");
  ASSERT_GT(voids.size(), 6u);
  int finite = 0;
  for (const double v : voids.v) {
    EXPECT_FALSE(v < 0);
    finite += std::isfinite(v);
  }
  EXPECT_GT(finite, 6);
  EXPECT_TRUE(gs::test::h5::has(dir / "silo_report.h5", "/profiles/residual/rose_left_density"));
  for (const auto& [option, value] :
       std::vector<std::pair<std::string, std::string>>{{"--layers", "1.5"},
                                                        {"--rose-bins", "2"},
                                                        {"--phi-i", "95"},
                                                        {"--en-k", "-1"},
                                                        {"--flow-threshold", "1.5"},
                                                        {"--flow-wall-d50", "0"},
                                                        {"--zone-extent-factor", "1"},
                                                        {"--zone-window-d50", "-5"}}) {
    const auto b = run_cli("analyze silo " + (dir / "out" / "trajectory.h5").string() + " -o " +
                               (dir / "x.h5").string() + " " + option + " " + value,
                           dir.path);
    EXPECT_EQ(b.rc, 2) << option;
    EXPECT_NE(b.err.find("error: "), std::string::npos) << b.err;
    EXPECT_NE(b.err.find(option), std::string::npos) << b.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.h5")) << option;
  }
  // The wall forces are in the history too, per side wall (the meshes' groups).
  const auto h = read_csv_table(dir / "out" / "history.csv");
  for (const char* col : {"left_fz_N", "right_fx_N", "bottom_fz_N"}) (void)h.num(0, col);
}

TEST(Silo, GravitationalOutletDischargesAndWeighsWhatLeaves) {
  gs::test::ScratchDir dir("silo_gravity");
  std::ofstream(dir / "silo.toml") << scene(kGravity);
  const auto r = run_cli(
      "simulate " + (dir / "silo.toml").string() + " -q -o " + (dir / "out").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  const auto c = read_csv_table(dir / "out" / "curve.csv");
  ASSERT_GE(c.rows.size(), 3u);
  EXPECT_NEAR(c.num(0, "balance_G"), 1.0, 0.03);
  double out = 0;
  for (std::size_t i = 0; i < c.rows.size(); ++i) {
    if (c.num(i, "flow_time_s") < 0.02) {
      EXPECT_EQ(c.num(i, "discharged_kg"), 0.0) << i;
    }
    EXPECT_GE(c.num(i, "discharged_kg"), out);
    out = c.num(i, "discharged_kg");
  }
  // The last row: at least 90 % of the mass has left (or the time ran out), and what left is
  // what the outlet removed (the history's count of the engine's removals).
  const std::size_t n = c.rows.size() - 1;
  EXPECT_TRUE(c.num(n, "discharged_fraction") >= 0.9 || c.num(n, "flow_time_s") >= 1.02);
  const auto h = read_csv_table(dir / "out" / "history.csv");
  EXPECT_NEAR(h.num(h.rows.size() - 1, "removed_mass_kg"), out, 1e-9 * out);
  EXPECT_NE(r.out.find("discharged"), std::string::npos) << r.out;
}

// An outlet 1.8 largest grains wide (4.5 mm, grains of 1.5–2.5 mm): about a tenth of the grains
// leave, then an arch closes it. The run ends stop_after_s after the last grain left (0.1 s:
// longer than a grain takes to fall from the outlet to where it is removed, two largest grains
// below the bottom), long before its time limit and the end fraction, and says why; with
// stop_after_s = 0 it runs to the limit.
TEST(Silo, GravitationalRunEndsWhenTheFlowStops) {
  gs::test::ScratchDir dir("silo_stall");
  const std::string narrow =
      replaced(kGravity, "outlet_width_m = 0.008", "outlet_width_m = 0.0045");
  std::ofstream(dir / "silo.toml") << scene(
      replaced(narrow, "end_fraction = 0.9\n", "end_fraction = 0.9\nstop_after_s = 0.1\n"));
  const auto r = run_cli(
      "simulate " + (dir / "silo.toml").string() + " -q -o " + (dir / "out").string(), dir.path);
  ASSERT_EQ(r.rc, 0) << r.err;
  EXPECT_NE(r.out.find("the flow stopped: nothing left in the last 0.1 s"), std::string::npos)
      << r.out;
  const auto c = read_csv_table(dir / "out" / "curve.csv");
  const std::size_t n = c.rows.size() - 1;
  const double end = c.num(n, "flow_time_s"), out = c.num(n, "discharged_kg");
  EXPECT_LT(end, 0.5);  // (the limit: settle_s 0.02 + max_discharge_s 1.0)
  EXPECT_LT(c.num(n, "discharged_fraction"), 0.9);
  // The last grain left 0.1 s before the end (the opening at 0.02 s if none had): the curve's
  // rows, 200 steps (2 ms) apart, reach the final mass within a row of that.
  std::size_t first = n;
  while (first > 0 && c.num(first - 1, "discharged_kg") == out) --first;
  const double t_out = out > 0 ? c.num(first, "flow_time_s") : 0.02;
  EXPECT_NEAR(end - t_out, 0.1, 0.0025) << "last grain out at " << t_out << ", end " << end;
  // stop_after_s = 0 never stops on the flow: the run goes on to its time limit (here 0.1 s).
  std::ofstream(dir / "silo0.toml") << scene(
      replaced(replaced(narrow, "end_fraction = 0.9\n", "end_fraction = 0.9\nstop_after_s = 0\n"),
               "max_discharge_s = 1.0", "max_discharge_s = 0.08"));
  const auto r0 = run_cli(
      "simulate " + (dir / "silo0.toml").string() + " -q -o " + (dir / "out0").string(), dir.path);
  ASSERT_EQ(r0.rc, 0) << r0.err;
  const auto c0 = read_csv_table(dir / "out0" / "curve.csv");
  EXPECT_GE(c0.num(c0.rows.size() - 1, "flow_time_s"), 0.1);
  EXPECT_EQ(r0.out.find("the flow stopped"), std::string::npos) << r0.out;
}

TEST(Silo, BadInputsFailWithOneLine) {
  gs::test::ScratchDir dir("silo_bad");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {replaced(scene(kGravity), "outlet_width_m = 0.008", "outlet_width_m = 0.05"),
       "silo.outlet_width_m: outside the bottom (0.05"},
      {replaced(scene(kQuasi), "roughness = 1.0", "roughness = 0.0001"),
       "silo.roughness: gives teeth below 1e-3·d50 (0.0001"},
      {replaced(scene(kQuasi), "mode = \"quasi_static\"", "mode = \"fast\""),
       "silo.mode: expected \"quasi_static\" or \"gravitational\" (fast)"},
      {scene(kGravity + "bottom_travel_m = 0.01\n"),
       "silo.bottom_travel_m: is for mode = \"quasi_static\""},
      {scene(kQuasi, "[outlet]\nkeep_lo_m = [-1.0, -1.0, -1.0]\nkeep_hi_m = [1.0, 1.0, 1.0]\n"),
       "[outlet]: the silo removes what leaves through its outlet; remove [outlet]"},
      {replaced(scene(kQuasi), "[fill]", "[nofill]"), "[nofill]: unknown section"},
      {replaced(replaced(scene(kQuasi), "[fill]", "[unused]"), "[unused]", "[walls_x]"),
       "[walls_x]: unknown section"},
      {replaced(scene(kGravity), "end_fraction = 0.9", "stop_after_s = -1.0\nend_fraction = 0.9"),
       "silo.stop_after_s: must not be negative (-1"},
      {scene(kQuasi + "stop_after_s = 1.0\n"),
       "silo.stop_after_s: is for mode = \"gravitational\""},
      {replaced(scene(kGravity), "outlet = \"centre\"", "outlet = \"middle\""),
       "silo.outlet: expected \"centre\" or \"right\" (middle)"},
      {scene(kQuasi,
             "[[walls]]\nshape = \"plane\"\npoint_m = [0.0, 0.0, 0.0]\n"
             "normal = [0.0, 0.0, 1.0]\n"),
       "[[walls]]: a laboratory test builds its own walls"},
  };
  gs::test::expect_bad_scenes(dir.path, cases);
  // A report on a run that has no silo walls: one line naming the frame.
  std::ofstream(dir / "free.csv") << "id,x,y,z,r\n0,0,0,0,0.001\n1,0.01,0,0,0.001\n";
  std::ofstream(dir / "free.toml")
      << "[scene]\nname = \"free\"\npacking = \"free.csv\"\n[material]\nyoung_Pa = 1e7\n"
         "stiffness_ratio = 0.3\nfriction_deg = 25.0\ndensity_kg_m3 = 2600.0\n"
         "[solver]\ndt_s = 1e-6\nsteps = 10\n[output]\nevery = 5\n";
  ASSERT_EQ(
      run_cli("simulate " + (dir / "free.toml").string() + " -q -o " + (dir / "free").string(),
              dir.path)
          .rc,
      0);
  const auto r = run_cli("analyze silo " + (dir / "free" / "trajectory.h5").string() + " -o " +
                             (dir / "x.h5").string(),
                         dir.path);
  EXPECT_EQ(r.rc, 2);
  EXPECT_NE(r.err.find("frame 0: no left and right side walls"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.h5"));
}

// Killed once while filling and once while the outlet discharges, resumed: every output equals
// the uninterrupted run's (the programmes' states, the removals and the insertions come from
// the checkpoint).
TEST(Silo, ResumeIsBitForBitWhileFillingAndDischarging) {
  gs::test::ScratchDir dir("silo_resume");
  std::ofstream(dir / "silo.toml") << scene(kGravity);
  // (the filling ends near step 71 000)
  gs::test::expect_resume_bit_for_bit(dir.path, (dir / "silo.toml").string(), {45000, 100000},
                                      {"history.csv", "curve.csv"}, "trajectory.h5");
}
