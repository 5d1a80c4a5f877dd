// End-to-end tests of `granoscope analyze rev | shearzone | invariants | fabric | rose | chains
// | walls` on synthetic snapshots: the HDF5, CSV and VTK outputs are read back and compared with
// exact answers (lattice values, or sums computed here from the input frame's contacts), a
// periodic frame with particles crossing the boundary, their figures (a uniform field drawn in
// one colour), and bad input (exit 2, one line, no output file).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <tuple>

#include "cli_util.hpp"
#include "hdf5_trajectory.hpp"
#include "packing_util.hpp"
#include "rev_cells.hpp"
#include "shear_zone.hpp"

namespace fs = std::filesystem;
namespace ga = gs::analysis;
using gs::test::read_attr;
using gs::test::read_doubles;
using gs::test::read_format;
using gs::test::run;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kCsv = 5e-12;  // relative rounding of the CSV outputs (12 significant digits)

std::string q(const fs::path& p) {
  return p.string();
}

std::size_t lines(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string l; std::getline(in, l);) ++n;
  return n;
}

/// A CSV table as columns by header name (nan parsed as NaN).
std::map<std::string, std::vector<double>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line, cell;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream h(line); std::getline(h, cell, ',');) names.push_back(cell);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::stringstream r(line);
    for (const auto& n : names) {
      EXPECT_TRUE(std::getline(r, cell, ',')) << p << ": short row";
      cols[n].push_back(std::stod(cell));
    }
  }
  return cols;
}

/// Largest connected region of the pixels within `tol` of colour (r, g, b) per channel: its
/// bounding box and area, in pixels.
struct Region {
  int width = 0, height = 0, area = 0;
};
Region largest_region(const fs::path& png, double r, double g, double b, double tol) {
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);  // BGR
  EXPECT_FALSE(img.empty()) << png;
  if (img.empty()) return {};
  cv::Mat mask, labels, stats, centroids;
  cv::inRange(img, cv::Scalar(b - tol, g - tol, r - tol), cv::Scalar(b + tol, g + tol, r + tol),
              mask);
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 4);
  Region best;
  for (int k = 1; k < n; ++k)
    if (stats.at<int>(k, cv::CC_STAT_AREA) > best.area)
      best = {stats.at<int>(k, cv::CC_STAT_WIDTH), stats.at<int>(k, cv::CC_STAT_HEIGHT),
              stats.at<int>(k, cv::CC_STAT_AREA)};
  return best;
}

/// With GS_KEEP_TEST_OUTPUT=DIR the HDF5 outputs are copied there (e.g. to try the figures).
void keep_outputs(const fs::path& dir) {
  const char* keep = std::getenv("GS_KEEP_TEST_OUTPUT");
  if (!keep) return;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".h5")
      fs::copy_file(e.path(), fs::path(keep) / ("rev_cli_" + e.path().filename().string()),
                    fs::copy_options::overwrite_existing);
}

/// `granoscope figures FILE` writes these PNGs, and they are not blank.
void expect_figures(const fs::path& dir, const fs::path& h5, const std::vector<std::string>& png,
                    const std::string& extra = "") {
  const auto out = dir / "figs";
  ASSERT_EQ(run("figures " + q(h5) + " -o " + q(out) + " " + extra, dir / "fig.log"), 0)
      << std::ifstream(dir / "fig.log").rdbuf();
  for (const auto& name : png) {
    const cv::Mat img = cv::imread((out / name).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(img.empty()) << name;
    cv::Scalar mean, sd;
    cv::meanStdDev(img, mean, sd);
    EXPECT_GT(sd[0], 10.0) << name << " is blank";
  }
}

TEST(CmdRev, LatticeVoidRatioStressDisplacementAndFigures) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  // Simple-cubic lattice d = 1 mm under isotropic contact forces 3 N (p = 3 MPa) with walls;
  // the second frame is translated by u0.
  const gs::Frame a = gs::test::cubic_lattice(12, 0.5e-3, 3.0, true);
  gs::Frame b = a;
  const Eigen::Vector3d u0(2e-5, -1e-5, 3e-5);
  for (auto& p : b.particles) p.position += u0;
  gs::Trajectory t;
  t.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  ASSERT_EQ(
      run("analyze rev " + q(dir / "run.h5") +
              " --frame 0 --to 1 --region 1.37e-3 1.37e-3 1.37e-3 10.37e-3 10.37e-3 "
              "10.37e-3 -o " +
              q(dir / "rev.h5") + " --vti " + q(dir / "rev.vti") + " --csv " + q(dir / "rev.csv"),
          dir / "log"),
      0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_EQ(read_format(dir / "rev.h5"), "granoscope-rev");
  const auto e = read_doubles(dir / "rev.h5", "/cells/void_ratio");
  ASSERT_EQ(e.size(), 125u);
  for (double x : e) EXPECT_NEAR(x, 6 / kPi - 1, 1e-12);
  const auto p = read_doubles(dir / "rev.h5", "/cells/p");
  for (double x : p) EXPECT_NEAR(x, 3e6, 1e-12 * 3e6);
  const auto s = read_doubles(dir / "rev.h5", "/cells/stress");
  ASSERT_EQ(s.size(), 9 * 125u);
  EXPECT_NEAR(s[8], 3e6, 1e-6);  // sigma_zz of cell 0, compression positive
  const auto u = read_doubles(dir / "rev.h5", "/cells/displacement");
  ASSERT_EQ(u.size(), 3 * 125u);
  for (std::size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(u[k], u0[k % 3], 1e-15);
  // The VTI: a 5 x 5 x 5 image (extent 0..4 per axis) with the same uniform fields; VTK records
  // each array's range (of the magnitude for vectors: |u0|).
  EXPECT_NE(gs::test::xml_tag(dir / "rev.vti", "Piece").find("Extent=\"0 4 0 4 0 4\""),
            std::string::npos);
  for (const auto& [name, value, tol] : {std::tuple{"void_ratio", 6 / kPi - 1, 1e-12},
                                         {"p", 3e6, 1e-12 * 3e6},
                                         {"displacement", u0.norm(), 1e-15}}) {
    const auto [lo, hi] = gs::test::vtk_range(dir / "rev.vti", "PointData", name);
    EXPECT_NEAR(lo, value, tol) << name;
    EXPECT_NEAR(hi, value, tol) << name;
  }
  // The CSV: one row per cell, the same values (to its 12 significant digits).
  EXPECT_EQ(lines(dir / "rev.csv"), 126u);
  auto csv = read_csv(dir / "rev.csv");
  ASSERT_EQ(csv["void_ratio"].size(), 125u);
  for (std::size_t c = 0; c < 125; ++c) {
    EXPECT_NEAR(csv["void_ratio"][c], 6 / kPi - 1, 1e-12 + kCsv) << c;
    EXPECT_NEAR(csv["p"][c], 3e6, (1e-12 + kCsv) * 3e6) << c;
    EXPECT_NEAR(csv["stress_zz"][c], 3e6, (1e-12 + kCsv) * 3e6) << c;
    EXPECT_NEAR(csv["displacement_x"][c], u0.x(), 1e-15) << c;
    EXPECT_NEAR(csv["displacement_z"][c], u0.z(), 1e-15) << c;
    EXPECT_EQ(csv["particles"][c], 125.0) << c;  // 5^3 lattice periods in every cell
  }
  // A profile along z through the middle of frame 0, 7 points 0.5 mm apart: on the default grid
  // (cells of 5 mm from the lattice's outer faces, walls included) every cell holds whole periods
  // and whole lines of branches, so the interpolated p = 3 MPa and e = 6/pi - 1 at every point.
  ASSERT_EQ(run("analyze rev " + q(dir / "run.h5") +
                    " --frame 0 --to 1 --profile 5e-3 5e-3 4e-3 5e-3 5e-3 7e-3 --profile-points 7 "
                    "--csv " +
                    q(dir / "prof.csv") + " -o " + q(dir / "rev2.h5"),
                dir / "log"),
            0);
  EXPECT_EQ(lines(dir / "prof.csv"), 8u);
  std::ifstream prof(dir / "prof.csv");
  std::string header;
  std::getline(prof, header);
  EXPECT_EQ(header.rfind("distance,point_x,point_y,point_z,void_ratio", 0), 0u) << header;
  csv = read_csv(dir / "prof.csv");
  ASSERT_EQ(csv["p"].size(), 7u);
  for (std::size_t k = 0; k < 7; ++k) {
    EXPECT_NEAR(csv["distance"][k], 0.5e-3 * double(k), 1e-18 + kCsv * 3e-3) << k;
    EXPECT_NEAR(csv["point_z"][k], 4e-3 + 0.5e-3 * double(k), 1e-18 + kCsv * 7e-3) << k;
    EXPECT_EQ(csv["point_x"][k], 5e-3) << k;
    EXPECT_NEAR(csv["p"][k], 3e6, (1e-12 + kCsv) * 3e6) << k;
    EXPECT_NEAR(csv["void_ratio"][k], 6 / kPi - 1, 1e-12 + kCsv) << k;
    EXPECT_NEAR(csv["displacement_y"][k], u0.y(), 1e-15) << k;
  }
  // Gaussian coarse-graining on the same region: uniform density and contact stress.
  ASSERT_EQ(run("analyze rev " + q(dir / "run.h5") +
                    " --method gaussian --width-d50 1 --step-d50 0.7 --region 5e-3 5e-3 5e-3 "
                    "6.5e-3 6.5e-3 6.5e-3 -o " +
                    q(dir / "cg.h5"),
                dir / "log"),
            0);
  const auto cp = read_doubles(dir / "cg.h5", "/cells/p");
  for (double x : cp) EXPECT_NEAR(x, 3e6, 2e-4 * 3e6);  // kernel cut-off ripple, see unit test
  // The map of the uniform sigma_zz is one colour, the middle of viridis (matplotlib widens the
  // limits of a constant field around it), filling the square section of 5 x 5 cells.
  expect_figures(dir, dir / "rev.h5", {"rev_stress_zz.png"}, "--field stress_zz");
  const Region map = largest_region(dir / "figs" / "rev_stress_zz.png", 32.5, 144.6, 140.4, 2.0);
  EXPECT_GT(map.width, 300);
  EXPECT_NEAR(map.height, map.width, 2);
  EXPECT_GE(map.area, map.width * map.height - 2 * (map.width + map.height));
  // Whole-specimen invariants: Love–Weber and seed 003 eq 14 both give p = 3 MPa, q = 0.
  ASSERT_EQ(run("analyze invariants " + q(dir / "run.h5") + " --frame 0 -o " + q(dir / "i.h5") +
                    " --csv " + q(dir / "i.csv"),
                dir / "log"),
            0);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "p"), 3e6, 1e-6);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "q"), 0.0, 1e-6);
  const auto b14 = read_doubles(dir / "i.h5", "/stress/boundary_eq14");
  EXPECT_NEAR(b14[0], 3e6, 1e-6);
  expect_figures(dir, dir / "i.h5", {"invariants.png"});
  keep_outputs(dir);
  fs::remove_all(dir);
}

TEST(CmdRev, PeriodicCellCrossingAndStress) {
  // A periodic simple-cubic lattice, 8^3 spheres d = 1 mm in the cell [-d/2, 15d/2)^3, every
  // neighbour pair a contact with force F = 3 N along the branch, the wrap-around pairs (7 -> 0)
  // included. Exact answers: with minimum-image branches (each d e_a) the stress of the whole
  // cell is sum l f / V = 3 * 8^3 * d F e_a e_a / (8 d)^3 = F / d^2 I = 3 MPa (the box of the
  // spheres used before gave 7.5/8 of it, the wrap branches half outside); frame 1 is the
  // lattice translated by u0 (0.55 to 0.7 d per axis) with the spheres that left the cell
  // wrapped back (a jump of 8 d - u0): the minimum-image displacement is u0 in every REV cell
  // and the fitted deformation gradient is I.
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  const double r = 0.5e-3, d = 2 * r, F = 3.0;
  gs::Frame a = gs::test::cubic_lattice(8, r, F, false);
  a.domain.periodic = true;
  a.domain.lo = Eigen::Vector3d::Constant(-r);
  a.domain.hi = Eigen::Vector3d::Constant(8 * d - r);
  a.domain.cell = 8 * d * Eigen::Matrix3d::Identity();
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j)
      for (int ax = 0; ax < 3; ++ax) {
        int q0[3] = {0, 0, 0}, q7[3] = {0, 0, 0};
        const int o1 = (ax + 1) % 3, o2 = (ax + 2) % 3;
        q0[o1] = q7[o1] = j;
        q0[o2] = q7[o2] = k;
        q7[ax] = 7;
        gs::Contact c;
        c.id1 = q7[0] + 8 * (q7[1] + 8 * q7[2]);
        c.id2 = q0[0] + 8 * (q0[1] + 8 * q0[2]);
        c.normal = Eigen::Vector3d::Unit(ax);
        c.normal_force = F * c.normal;
        a.contacts.push_back(c);
      }
  ASSERT_EQ(a.contacts.size(), 3u * 512u);
  gs::Frame b = a;
  const Eigen::Vector3d u0(0.6 * d, -0.7 * d, 0.55 * d);
  std::size_t wrapped = 0;
  for (auto& p : b.particles) {
    p.position += u0;
    for (int ax = 0; ax < 3; ++ax) {
      if (p.position[ax] >= b.domain.hi[ax]) p.position[ax] -= 8 * d, ++wrapped;
      if (p.position[ax] < b.domain.lo[ax]) p.position[ax] += 8 * d, ++wrapped;
    }
  }
  EXPECT_EQ(wrapped, 3u * 64u);  // one layer of 64 spheres per axis
  gs::Trajectory t;
  t.frames = {a, b};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  ASSERT_EQ(
      run("analyze invariants " + q(dir / "run.h5") + " --frame 0 --to 1 -o " + q(dir / "i.h5"),
          dir / "log"),
      0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "p"), 3e6, 1e-12 * 3e6);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "q"), 0.0, 1e-12 * 3e6);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/stress", "volume"), std::pow(8 * d, 3), 1e-24);
  const auto sigma = read_doubles(dir / "i.h5", "/stress/tensor");
  for (std::size_t k = 0; k < 9; ++k) EXPECT_NEAR(sigma[k], k % 4 == 0 ? 3e6 : 0.0, 1e-6) << k;
  const auto Fg = read_doubles(dir / "i.h5", "/strain/F");
  for (std::size_t k = 0; k < 9; ++k) EXPECT_NEAR(Fg[k], k % 4 == 0 ? 1.0 : 0.0, 1e-13) << k;
  // REV displacement map of the same motion.
  ASSERT_EQ(run("analyze rev " + q(dir / "run.h5") + " --frame 0 --to 1 -o " + q(dir / "rev.h5"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  const auto u = read_doubles(dir / "rev.h5", "/cells/displacement");
  ASSERT_EQ(u.size(), 3u * 4u * 4u * 4u);  // L = 5 d, s = d over 8 d
  for (std::size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(u[k], u0[k % 3], 1e-15) << k;
  fs::remove_all(dir);
}

TEST(CmdRev, ShearZoneOfAPlaneStrainBand) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  // 4 x 14 cm-like section scaled to d50 = 1 mm: a band at 60 deg to the horizontal.
  const gs::Frame f = gs::test::band_lattice(40, 6, 70, 1e-3, 60.0, 2.5e-3,
                                             Eigen::Vector3d(19.5e-3, 2.5e-3, 34.5e-3));
  gs::Trajectory t;
  t.frames = {f};
  gs::write_hdf5_trajectory(dir / "band.h5", t);
  ASSERT_EQ(run("analyze shearzone " + q(dir / "band.h5") + " -o " + q(dir / "sz.h5") + " --csv " +
                    q(dir / "sz.csv"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_EQ(read_format(dir / "sz.h5"), "granoscope-shearzone");
  // The command's default map is the library's on the same input: the front-view slab (normal
  // -y, axis x) through the centre of the spheres' box, 5 d50 thick, cells 5 d50, step 1 d50,
  // |rotation about the normal|. Its map, band line, profile and thickness come back exactly;
  // the library's accuracy (inclination within 0.5 deg, thickness within 0.2 d50 of the
  // convolved Gaussian) is tested in test_shear_zone.cpp.
  const auto [lo, hi] = gs::particle_bounds(f);
  ga::RevGridSpec spec;
  spec.cell = 5e-3;
  spec.step = 1e-3;
  spec.slab = ga::Slab{0.5 * (lo + hi), -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), 5e-3};
  const auto g = ga::make_rev_grid(f, spec);
  const auto rf = ga::rev_average(f, ga::contact_branches(f), g);
  ga::ScalarMap m;
  m.nu = g.n[0];
  m.nv = g.n[1];
  m.step = g.step;
  m.u0 = g.plane_lo(0, 0) + 2.5e-3;
  m.v0 = g.plane_lo(1, 0) + 2.5e-3;
  for (std::size_t c = 0; c < g.count(); ++c)
    m.value.push_back(std::abs(rf.rotation[c].dot(g.axes.row(2).transpose())));
  const auto z = ga::shear_zone(m);
  EXPECT_EQ(read_doubles(dir / "sz.h5", "/map/value"), m.value);
  EXPECT_EQ(read_attr(dir / "sz.h5", "/map", "u0"), m.u0);
  EXPECT_EQ(read_attr(dir / "sz.h5", "/", "inclination_deg"), z.inclination_deg);
  EXPECT_EQ(read_attr(dir / "sz.h5", "/", "angle_deg"), z.angle_deg);
  EXPECT_EQ(read_attr(dir / "sz.h5", "/", "thickness_m"), z.thickness);
  EXPECT_EQ(read_attr(dir / "sz.h5", "/", "lower_m"), z.lower_d);
  EXPECT_EQ(read_attr(dir / "sz.h5", "/", "upper_m"), z.upper_d);
  EXPECT_EQ(read_doubles(dir / "sz.h5", "/profile/value"), z.profile_value);
  EXPECT_NEAR(z.inclination_deg, 60.0, 0.5);  // the band was put at 60 deg
  const double th = read_attr(dir / "sz.h5", "/", "thickness_d50");
  EXPECT_NEAR(th, z.thickness / 1e-3, 1e-12);                             // d50 = 1 mm
  EXPECT_NEAR(read_attr(dir / "sz.h5", "/", "thickness_mm"), th, 1e-12);  // d50 = 1 mm
  // The profile across the band, in the CSV to 12 significant digits.
  auto prof = read_csv(dir / "sz.csv");
  ASSERT_EQ(prof["distance"].size(), z.profile_d.size());
  for (std::size_t k = 0; k < z.profile_d.size(); ++k) {
    EXPECT_NEAR(prof["distance"][k], z.profile_d[k], kCsv * std::abs(z.profile_d[k])) << k;
    EXPECT_NEAR(prof["rotation"][k], z.profile_value[k], kCsv * z.profile_value[k]) << k;
  }
  std::ifstream log(dir / "log");
  std::string line;
  std::getline(log, line);
  EXPECT_NE(line.find("inclination 60."), std::string::npos) << line;
  expect_figures(dir, dir / "sz.h5", {"shearzone.png"});
  keep_outputs(dir);
  fs::remove_all(dir);
}

/// The random packing of the contact analyses (9^3 spheres, d = 1 mm, two walls), and frame 1
/// after the affine map h; returns the frames as written and read back (what the CLI sees).
gs::Trajectory contact_run(const fs::path& file, Eigen::Matrix3d& h) {
  const gs::Frame a = gs::test::random_packing(9, 1e-3, 17);
  gs::Frame b = a;
  h << 1.01, 0.002, 0, 0, 0.995, 0.003, 0.001, 0, 0.98;
  for (auto& p : b.particles) p.position = h * p.position;
  gs::Trajectory t;
  t.frames = {a, b};
  gs::write_hdf5_trajectory(file, t);
  return gs::read_hdf5_trajectory(file);
}

/// Index of frame.particles by id.
std::map<std::int64_t, std::size_t> by_id(const gs::Frame& f) {
  std::map<std::int64_t, std::size_t> m;
  for (std::size_t i = 0; i < f.particles.size(); ++i) m[f.particles[i].id] = i;
  return m;
}

/// 2D rose bins by the definition of docs/analysis.md: each normal n adds 1/2 to the bin of
/// the angle of (n.e1, n.e2) and 1/2 to the bin of -n, 36 bins of 10 deg from e1 towards e2;
/// sum |Fn| per bin alongside.
void rose2d(const std::vector<gs::Contact>& cs, const Eigen::Matrix3d& axes,
            std::vector<double>& count, std::vector<double>& sum_fn) {
  count.assign(36, 0.0);
  sum_fn.assign(36, 0.0);
  for (const auto& c : cs)
    for (const double sign : {1.0, -1.0}) {
      double t = std::atan2(sign * axes.row(1).dot(c.normal), sign * axes.row(0).dot(c.normal));
      if (t < 0) t += 2 * kPi;
      const auto k = std::min<std::size_t>(35, static_cast<std::size_t>(t / (2 * kPi / 36)));
      count[k] += 0.5;
      sum_fn[k] += 0.5 * c.normal_force.norm();
    }
}

/// 3D equal-area bins: band floor((1 - u.e3) / 2 n_theta), column floor(phi / 2 pi n_phi).
std::vector<double> rose3d(const std::vector<gs::Contact>& cs, const Eigen::Matrix3d& axes,
                           int n_theta, int n_phi) {
  std::vector<double> count(static_cast<std::size_t>(n_theta * n_phi), 0.0);
  for (const auto& c : cs)
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d u = sign * axes * c.normal.normalized();
      const int band = std::min(n_theta - 1, static_cast<int>((1.0 - u.z()) / 2.0 * n_theta));
      double phi = std::atan2(u.y(), u.x());
      if (phi < 0) phi += 2 * kPi;
      const int col = std::min(n_phi - 1, static_cast<int>(phi / (2 * kPi) * n_phi));
      count[static_cast<std::size_t>(band * n_phi + col)] += 0.5;
    }
  return count;
}

TEST(CmdRev, ContactAnalysesAgainstTheInputContacts) {
  // Every value below is summed here from the contacts of the input frame (random packing:
  // particle-particle contacts, and wall contacts stored particle first): fabric (seed 003
  // eq 20-21) M = (1/Np) sum over both contact points of n n, omega = tr M = 2 Nc / Np,
  // D = 15/2 (M / omega - I/3); rose bins (2D, 3D default and --bins3d 4 8, with and
  // without --walls) and their mean |Fn|; strong contacts |Fn| > mean |Fn| and their chains
  // (union-find); wall loads P = sum of the bottom wall's |Fn| (normals along -z, shear in x-y),
  // G = sum m g; the deformation gradient of the affine motion h between the frames.
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  Eigen::Matrix3d h;
  const gs::Frame f = contact_run(dir / "run.h5", h).frames[0];
  const auto index = by_id(f);
  std::vector<gs::Contact> pp, pw;  // particle-particle, particle-wall
  for (const auto& c : f.contacts) (index.count(c.id2) ? pp : pw).push_back(c);
  ASSERT_GT(pp.size(), 600u);
  ASSERT_GT(pw.size(), 50u);
  const std::string in = q(dir / "run.h5") + " --frame 0 ";
  // Fabric.
  ASSERT_EQ(run("analyze fabric " + in + "-o " + q(dir / "f.h5") + " --csv " + q(dir / "f.csv"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  EXPECT_EQ(read_attr(dir / "f.h5", "/", "contacts"), double(pp.size()));
  EXPECT_EQ(read_attr(dir / "f.h5", "/", "particles"), 729.0);
  EXPECT_NEAR(read_attr(dir / "f.h5", "/", "omega"), 2.0 * double(pp.size()) / 729.0, 1e-15);
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();  // seed 003 eq 20: both contact points
  for (const auto& c : pp) M += 2.0 * c.normal * c.normal.transpose();
  M /= 729.0;
  const double omega = 2.0 * double(pp.size()) / 729.0;
  const Eigen::Matrix3d D = 7.5 * (M / omega - Eigen::Matrix3d::Identity() / 3.0);  // eq 21
  const auto fm = read_doubles(dir / "f.h5", "/M"), fd = read_doubles(dir / "f.h5", "/D");
  for (std::size_t k = 0; k < 9; ++k) {
    EXPECT_NEAR(fm[k], M(k / 3, k % 3), 1e-15) << k;
    EXPECT_NEAR(fd[k], D(k / 3, k % 3), 1e-14) << k;
  }
  EXPECT_EQ(lines(dir / "f.csv"), 2u);
  // Rose: front view axes (e1 = x, e2 = z, e3 = -y).
  ASSERT_EQ(run("analyze rose " + in + "--3d -o " + q(dir / "r.h5") + " --csv " + q(dir / "r.csv"),
                dir / "log"),
            0);
  Eigen::Matrix3d axes;
  axes << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  const auto ra = read_doubles(dir / "r.h5", "/rose2d/axes");
  for (std::size_t k = 0; k < 9; ++k) EXPECT_EQ(ra[k], axes(k / 3, k % 3)) << k;
  std::vector<double> count, sum_fn;
  rose2d(pp, axes, count, sum_fn);
  const auto rc = read_doubles(dir / "r.h5", "/rose2d/count");
  const auto rd = read_doubles(dir / "r.h5", "/rose2d/density");
  const auto rfn = read_doubles(dir / "r.h5", "/rose2d/mean_fn");
  ASSERT_EQ(rc.size(), 36u);
  double sum = 0.0;
  for (std::size_t k = 0; k < 36; ++k) {
    EXPECT_EQ(rc[k], count[k]) << k;
    EXPECT_NEAR(rd[k], count[k] / (double(pp.size()) * 2 * kPi / 36), 1e-15) << k;
    if (count[k] > 0) {
      EXPECT_NEAR(rfn[k], sum_fn[k] / count[k], 1e-14) << k;
    }
    sum += rc[k];
  }
  EXPECT_EQ(sum, double(pp.size()));  // every contact once: n and -n half each
  const auto r3 = read_doubles(dir / "r.h5", "/rose3d/count");
  EXPECT_EQ(r3, rose3d(pp, axes, 18, 36));
  EXPECT_NEAR(read_attr(dir / "r.h5", "/rose3d", "solid_angle"), 4 * kPi / (18 * 36), 1e-16);
  EXPECT_EQ(lines(dir / "r.csv"), 37u);
  // --walls --bins3d 4 8: wall contacts too; 4 bands x 8 longitudes.
  ASSERT_EQ(
      run("analyze rose " + in + "--3d --walls --bins3d 4 8 -o " + q(dir / "rw.h5"), dir / "log"),
      0)
      << std::ifstream(dir / "log").rdbuf();
  std::vector<gs::Contact> all = pp;
  all.insert(all.end(), pw.begin(), pw.end());
  EXPECT_EQ(read_attr(dir / "rw.h5", "/", "walls"), 1.0);
  EXPECT_EQ(read_attr(dir / "rw.h5", "/rose3d", "n_theta"), 4.0);
  EXPECT_EQ(read_attr(dir / "rw.h5", "/rose3d", "n_phi"), 8.0);
  EXPECT_EQ(read_doubles(dir / "rw.h5", "/rose3d/count"), rose3d(all, axes, 4, 8));
  EXPECT_EQ(read_attr(dir / "rw.h5", "/rose2d", "contacts"), double(all.size()));
  // In 2D the wall normals (+-z) lie on the bin edges at 90 and 270 deg: half of each wall
  // contact goes to the bins at 90 deg (8 or 9), half to those at 270 deg (26 or 27).
  const auto rwc = read_doubles(dir / "rw.h5", "/rose2d/count");
  double up = 0.0, down = 0.0;
  for (std::size_t k = 0; k < 36; ++k) {
    const double extra = rwc[k] - rc[k];
    if (k == 8 || k == 9)
      up += extra;
    else if (k == 26 || k == 27)
      down += extra;
    else
      EXPECT_EQ(extra, 0.0) << k;
  }
  EXPECT_EQ(up, 0.5 * double(pw.size()));
  EXPECT_EQ(down, 0.5 * double(pw.size()));
  // Chains: strong = |Fn| above the mean of the particle contacts; chains by union-find.
  ASSERT_EQ(run("analyze chains " + in + "-o " + q(dir / "c.h5") + " --vtp " + q(dir / "c.vtp"),
                dir / "log"),
            0);
  double mean_fn = 0.0, max_fn = 0.0;
  for (const auto& c : pp) {
    mean_fn += c.normal_force.norm() / double(pp.size());
    max_fn = std::max(max_fn, c.normal_force.norm());
  }
  std::vector<std::size_t> parent(f.particles.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  const auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i];
    return i;
  };
  std::size_t strong = 0;
  double strong_min = 1e300, strong_max = 0.0;
  for (const auto& c : pp) {
    const double fn = c.normal_force.norm();
    if (!(fn > mean_fn)) continue;
    ++strong;
    strong_min = std::min(strong_min, fn);
    strong_max = std::max(strong_max, fn);
    parent[root(index.at(c.id1))] = root(index.at(c.id2));
  }
  std::map<std::size_t, std::size_t> size;
  for (const auto& c : pp)
    if (c.normal_force.norm() > mean_fn) size[root(index.at(c.id1))] = 0;
  for (std::size_t i = 0; i < parent.size(); ++i)
    if (size.count(root(i))) ++size[root(i)];
  std::size_t largest = 0;
  for (const auto& [r, n] : size) largest = std::max(largest, n);
  EXPECT_NEAR(read_attr(dir / "c.h5", "/", "mean_fn"), mean_fn, 1e-14);
  EXPECT_EQ(read_attr(dir / "c.h5", "/", "max_fn"), max_fn);
  EXPECT_EQ(read_attr(dir / "c.h5", "/", "strong"), double(strong));
  EXPECT_EQ(read_attr(dir / "c.h5", "/", "chains"), double(size.size()));
  EXPECT_EQ(read_attr(dir / "c.h5", "/", "largest_chain"), double(largest));
  // The VTP: one line per strong contact, normal_force over exactly their range.
  const std::string piece = gs::test::xml_tag(dir / "c.vtp", "Piece");
  EXPECT_EQ(gs::test::xml_number(piece, "NumberOfLines"), double(strong));
  EXPECT_EQ(gs::test::xml_number(piece, "NumberOfPoints"), 2.0 * double(strong));
  const auto [fn_lo, fn_hi] = gs::test::vtk_range(dir / "c.vtp", "CellData", "normal_force");
  EXPECT_EQ(fn_lo, strong_min);
  EXPECT_EQ(fn_hi, strong_max);
  // Walls: the bottom wall (z = 0, normal +z) carries P; G = sum m g.
  ASSERT_EQ(run("analyze walls " + in + "-o " + q(dir / "w.h5") + " --csv " + q(dir / "w.csv"),
                dir / "log"),
            0)
      << std::ifstream(dir / "log").rdbuf();
  double P = 0.0, G = 0.0;
  std::size_t bottom = 0;
  for (const auto& c : pw)
    if (c.normal.z() < 0) P += c.normal_force.norm(), ++bottom;
  for (const auto& p : f.particles) G += p.mass * 9.81;
  EXPECT_NEAR(read_attr(dir / "w.h5", "/", "P"), P, 1e-13 * P);
  EXPECT_NEAR(read_attr(dir / "w.h5", "/", "G"), G, 1e-13 * G);
  EXPECT_EQ(read_attr(dir / "w.h5", "/", "T"), 0.0);  // no side wall
  EXPECT_NEAR(read_attr(dir / "w.h5", "/", "balance"), P / G, 1e-13 * P / G);
  double bottom_contacts = 0.0;
  for (int k = 0; k < 2; ++k) {
    const std::string g = "/walls/" + std::to_string(k);
    if (read_attr(dir / "w.h5", g.c_str(), "id") == double(f.walls[0].id))
      bottom_contacts = read_attr(dir / "w.h5", g.c_str(), "contacts");
  }
  EXPECT_EQ(bottom_contacts, double(bottom));
  // Deformation gradient of the affine motion between the frames, exactly.
  ASSERT_EQ(run("analyze invariants " + in + "--to 1 -o " + q(dir / "i.h5"), dir / "log"), 0);
  const auto F = read_doubles(dir / "i.h5", "/strain/F");
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(F[static_cast<std::size_t>(k)], h(k / 3, k % 3), 1e-12);
  EXPECT_NEAR(read_attr(dir / "i.h5", "/strain", "eps_v"), 1 - h.determinant(), 1e-12);
  keep_outputs(dir);
  fs::remove_all(dir);
}

/// Runs `analyze CMD` on the contact run for each (CMD, output) and `figures` on the outputs.
void contact_figures(const std::string& test,
                     const std::vector<std::pair<std::string, std::string>>& runs,
                     const std::vector<std::vector<std::string>>& png) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  Eigen::Matrix3d h;
  contact_run(dir / "run.h5", h);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const auto& [cmd, out] = runs[k];
    ASSERT_EQ(run("analyze " + cmd + " " + q(dir / "run.h5") + " --frame 0 -o " + q(dir / out),
                  dir / "log"),
              0)
        << test << ": " << cmd;
    fs::remove_all(dir / "figs");
    expect_figures(dir, dir / out, png[k]);
    for (const auto& e : fs::directory_iterator(dir / "figs"))  // nothing else is drawn
      EXPECT_NE(std::find(png[k].begin(), png[k].end(), e.path().filename().string()), png[k].end())
          << e.path();
  }
  fs::remove_all(dir);
}

// The figures exist and are not blank, and nothing else is drawn: the Hammer map of the 3D
// rose only when the data has a 3D histogram (--3d). Two tests to keep each under 10 s.
TEST(CmdRev, FabricAndRose3dFigures) {
  contact_figures("fabric", {{"fabric", "f.h5"}, {"rose --3d", "r.h5"}},
                  {{"fabric.png"}, {"rose.png", "rose_3d.png"}});
}

TEST(CmdRev, RoseChainsAndWallsFigures) {
  contact_figures("chains", {{"rose", "r2.h5"}, {"chains", "c.h5"}, {"walls", "w.h5"}},
                  {{"rose.png"}, {"chains.png"}, {"walls.png"}});
}

TEST(CmdRev, BadInputExitsTwoWithOneLine) {
  const auto dir = gs::test::temp_dir("gs_rev_cli");
  gs::Trajectory t;
  t.frames = {gs::test::cubic_lattice(6, 0.5e-3, 1.0, false)};
  gs::write_hdf5_trajectory(dir / "run.h5", t);
  const std::string in = q(dir / "run.h5");
  const std::string out = " -o " + q(dir / "o.h5");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"analyze rev " + q(dir / "missing.h5") + out, "missing.h5"},
      {"analyze rev " + in + " --cell-d50 0" + out, "--cell"},
      {"analyze rev " + in + " --cell -1e-3" + out, "--cell"},
      {"analyze rev " + in + " --step nan" + out, "--step"},
      {"analyze rev " + in + " --cell 1" + out, "smaller than one cell"},
      {"analyze rev " + in + " --method voronoi" + out, "--method"},
      {"analyze rev " + in + " --method gaussian --width-d50 -2" + out, "--width"},
      {"analyze rev " + in + " --frame 5" + out, "frame"},
      {"analyze rev " + in + " --slab-origin 0 1 0" + out, "no particle cuts the slab"},
      {"analyze rev " + in + " --profile 0 0 0 1 1 1" + out, "--csv"},
      {"analyze shearzone " + in + " --field shear" + out, "--to"},
      {"analyze fabric " + in + " --region 1 1 1 2 2 2" + out, "empty selection"},
      {"analyze fabric " + in + " --region 0 0 0 -1 1 1" + out, "--region"},
      {"analyze rose " + in + " --bin-deg 7" + out, "--bin-deg"},
      {"analyze chains " + in + " --threshold -3" + out, "--threshold"},
      {"analyze walls " + in + out, "no particle-wall contact"},
      {"analyze walls " + in + " --up 0 0 0" + out, "up"},
      {"analyze invariants --gradient 1 0 0 0 1 0 0 0 -1" + out, "det F"},
      {"analyze invariants --stress 1 0 0 0 nan 0 0 0 1" + out, "--stress"},
  };
  for (const auto& [args, what] : cases) {
    EXPECT_EQ(run(args, dir / "log"), 2) << args;
    std::ifstream log(dir / "log");
    std::string line, rest;
    std::getline(log, line);
    EXPECT_EQ(line.rfind("error: ", 0), 0u) << args << ": " << line;
    EXPECT_NE(line.find(what), std::string::npos) << args << ": " << line;
    EXPECT_FALSE(std::getline(log, rest)) << args << ": " << rest;
    EXPECT_FALSE(fs::exists(dir / "o.h5")) << args;
    fs::remove(dir / "o.h5");
  }
  fs::remove_all(dir);
}

}  // namespace
