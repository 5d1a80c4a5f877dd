// Per-material counts in zones and centres of mass (the DEM8 drum's mixing monitor,
// analysis/material_zones.hpp), against hand-computed values; `granoscope analyze materials` on a
// two-frame trajectory with the drum's quadrants; bad zone specifications as one-line errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "material_zones.hpp"

namespace ga = gs::analysis;

namespace {

gs::Particle particle(std::int64_t id, std::int32_t material, Eigen::Vector3d x, double mass,
                      double r = 0.001) {
  gs::Particle p;
  p.id = id;
  p.material_id = material;
  p.position = x;
  p.mass = mass;
  p.radius = r;
  return p;
}

std::vector<gs::Particle> four() {
  return {particle(0, 0, {1, 0, -1}, 1), particle(1, 0, {-1, 0, 1}, 3),
          particle(2, 1, {2, 0, -2}, 2), particle(3, 1, {0.5, 0, 0}, 2)};
}

}  // namespace

// Hand-computed: M0 centre (1·(1,0,−1) + 3·(−1,0,1))/4 = (−0.5, 0, 0.5); M1 ((4,0,−4) + (1,0,0))/4
// = (1.25, 0, −1). Quadrant x > 0, z < 0: M0 1, M1 1 (the particle at z = 0 is on the boundary,
// outside the open box); x < 0, z > 0: M0 1, M1 0.
TEST(MaterialZones, CountsAndCentresOfMass) {
  const double inf = HUGE_VAL;
  const std::vector<ga::Zone> zones = {{"a", {0, -inf, -inf}, {inf, inf, 0}},
                                       {"b", {-inf, -inf, 0}, {0, inf, inf}}};
  const auto s = ga::material_zone_stats(four(), zones);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].material, 0);
  EXPECT_EQ(s[0].count, 2u);
  EXPECT_EQ(s[0].mass_kg, 4.0);
  EXPECT_EQ(s[0].centre_m, Eigen::Vector3d(-0.5, 0, 0.5));
  EXPECT_EQ(s[0].in_zone, (std::vector<std::size_t>{1, 1}));
  EXPECT_EQ(s[1].material, 1);
  EXPECT_EQ(s[1].centre_m, Eigen::Vector3d(1.25, 0, -1));
  EXPECT_EQ(s[1].in_zone, (std::vector<std::size_t>{1, 0}));
  // Without recorded masses the centre is by volume (r³): M1 with radii 1 and 2 mm →
  // (1·(2,0,−2) + 8·(0.5,0,0))/9 = (6/9, 0, −2/9).
  auto p = four();
  for (auto& q : p) q.mass = 0;
  p[3].radius = 0.002;
  const auto v = ga::material_zone_stats(p, {});
  EXPECT_NEAR((v[1].centre_m - Eigen::Vector3d(6.0 / 9, 0, -2.0 / 9)).norm(), 0, 1e-15);
  EXPECT_EQ(v[1].mass_kg, 0.0);
  EXPECT_TRUE(v[1].in_zone.empty());
  EXPECT_THROW(ga::material_zone_stats(p, {{"c", {0, 0, 0}, {1, 0, 1}}}), std::invalid_argument);
}

TEST(MaterialZones, ParseZone) {
  const auto z = ga::parse_zone("left:-inf,-1,0,0,1e-3,inf");
  EXPECT_EQ(z.name, "left");
  EXPECT_EQ(z.lo, Eigen::Vector3d(-HUGE_VAL, -1, 0));
  EXPECT_EQ(z.hi, Eigen::Vector3d(0, 1e-3, HUGE_VAL));
  for (const char* bad : {"left", ":0,0,0,1,1,1", "a:0,0,0,1,1", "a:0,0,0,1,1,x", "a:0,0,0,1,1,1,2",
                          "a:0,0,1,1,1,1", "a:0,0,0,1,1,nan", "a:0,0,0,1,1,1x"})
    EXPECT_THROW(ga::parse_zone(bad), std::invalid_argument) << bad;
}

TEST(MaterialZones, CliWritesARowPerFrameWithTheDrumZones) {
  const auto dir = gs::test::temp_dir("gs_materials");
  gs::Trajectory t;
  t.metadata.parameters = {{"material_names", "M1,M2"}};
  for (int k = 0; k < 2; ++k) {
    gs::Frame f;
    f.step = 1000 * k;
    f.time = 0.01 * k;
    f.dt = 1e-5;
    f.particles = four();
    if (k == 1) f.particles[0].position = Eigen::Vector3d(-1, 0, 2);  // into x < 0, z > 0
    f.domain.lo = Eigen::Vector3d(-3, -3, -3);
    f.domain.hi = Eigen::Vector3d(3, 3, 3);
    t.frames.push_back(f);
  }
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  ASSERT_EQ(gs::test::run("analyze materials " + (dir / "run.h5").string() + " --drum -o " +
                              (dir / "m.csv").string(),
                          dir / "log.txt"),
            0);
  std::ifstream in(dir / "m.csv");
  std::string header, row0, row1;
  std::getline(in, header);
  std::getline(in, row0);
  std::getline(in, row1);
  EXPECT_EQ(header,
            "step,time_s,M1_count,M1_com_x_m,M1_com_y_m,M1_com_z_m,x+z-_M1_count,x-z+_M1_count,"
            "M2_count,M2_com_x_m,M2_com_y_m,M2_com_z_m,x+z-_M2_count,x-z+_M2_count");
  auto values = [](const std::string& row) {
    std::vector<double> v;
    std::stringstream s(row);
    std::string c;
    while (std::getline(s, c, ',')) v.push_back(std::stod(c));
    return v;
  };
  EXPECT_EQ(values(row0), (std::vector<double>{0, 0, 2, -0.5, 0, 0.5, 1, 1, 2, 1.25, 0, -1, 1, 0}));
  // Frame 1: M1's first particle moved from (1,0,−1) to (−1,0,2): centre (−1, 0, 1.25).
  EXPECT_EQ(values(row1),
            (std::vector<double>{1000, 0.01, 2, -1, 0, 1.25, 0, 2, 2, 1.25, 0, -1, 1, 0}));
  // Bad zones: one line, exit 2, no output.
  for (const auto& [arg, msg] : std::vector<std::pair<std::string, std::string>>{
           {"--zone a:0,0,0,1,1",
            "--zone: expected 6 bounds xlo,ylo,zlo,xhi,yhi,zhi (a:0,0,0,1,1)"},
           {"--zone a:0,0,0,1,1,1 --zone a:1,1,1,2,2,2", "--zone: name used twice (a)"},
           {"--every 0", "--every: must be at least 1 (0)"}}) {
    EXPECT_EQ(gs::test::run("analyze materials " + (dir / "run.h5").string() + " " + arg + " -o " +
                                (dir / "bad.csv").string(),
                            dir / "err.txt"),
              2)
        << arg;
    std::ifstream e(dir / "err.txt");
    std::string line, more;
    std::getline(e, line);
    EXPECT_FALSE(std::getline(e, more)) << more;
    EXPECT_EQ(line, "error: " + (dir / "run.h5").string() + ": " + msg) << arg;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.csv"));
  }
  std::filesystem::remove_all(dir);
}
