// Wall surface generators: saw-tooth asperities (seed 004 §4.3, §5.2), sinusoidal corrugation
// (seed 004 §4.4) and the box, checked against their analytic geometry.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "errors.hpp"
#include "surface_generators.hpp"
#include "triangle_mesh.hpp"

using namespace gs;
using namespace gs::solver;
namespace fs = std::filesystem;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

double total_area(const TriangleMesh& m) {
  double a = 0;
  for (std::size_t t = 0; t < m.triangles.size(); ++t) a += triangle_area(m, t);
  return a;
}

// Area of the projection onto the plane z = const (x, y components only).
double projected_area_xy(const TriangleMesh& m) {
  double a = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d& p = m.vertices[t[0]];
    const Eigen::Vector3d& q = m.vertices[t[1]];
    const Eigen::Vector3d& r = m.vertices[t[2]];
    a += 0.5 * std::abs((q.x() - p.x()) * (r.y() - q.y()) - (q.y() - p.y()) * (r.x() - q.x()));
  }
  return a;
}

Eigen::Vector3d centroid(const TriangleMesh& m, std::size_t t) {
  const auto& tr = m.triangles[t];
  return (m.vertices[tr[0]] + m.vertices[tr[1]] + m.vertices[tr[2]]) / 3.0;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

// The saw-tooth profile written out independently of the generator: teeth of ramp base
// a = h/tan α at pitch s starting at u = 0, vertical back faces, land at 0. Returns the interval
// of heights at u (a single value except on a back face).
std::pair<double, double> tooth_heights(double u, double h, double s, double alpha_deg) {
  const double a = h / std::tan(alpha_deg * kDeg);
  const double k = std::floor(u / s + 1e-12);
  const double r = u - k * s;
  const double eps = 1e-12 * s;
  if (r < a - eps) return {r * std::tan(alpha_deg * kDeg), r * std::tan(alpha_deg * kDeg)};
  if (r <= a + eps) return {0.0, h};
  return {0.0, 0.0};
}

struct SawCase {
  double rn, d50, sg_over_d50;
};

}  // namespace

// Seed 004 §5.2 silo walls (d50 = 1.5 mm, α_g = 45°): R_n = 1, 0.25, 0.01 with s_g = 4, 1,
// 0.04 × d50, over L = 100·s_g. Exactly 100 teeth (= L/s_g); every vertex and every triangle
// centroid on the analytic profile to 1e-15·h_g; v ∈ {0, W} exactly; tips exactly at h_g, nothing
// above h_g or below 0; every ramp slope = tan α_g to 1e-12; back faces normal to e_u exactly;
// every normal on the material side; area = W·(L + n·(√(a²+h²) − a + h)) to 1e-14 relative,
// projected area L·W to 1e-15; the mesh passes validate_mesh.
TEST(SurfaceGenerators, SawToothSeedSiloWalls) {
  for (const SawCase sc :
       {SawCase{1.0, 1.5e-3, 4.0}, SawCase{0.25, 1.5e-3, 1.0}, SawCase{0.01, 1.5e-3, 0.04}}) {
    SawToothSpec s;
    s.height_m = sc.rn * sc.d50;
    s.spacing_m = sc.sg_over_d50 * sc.d50;
    s.slope_deg = 45;
    s.length_m = 100 * s.spacing_m;
    s.width_m = 5 * sc.d50;
    const TriangleMesh m = saw_tooth_wall(s);
    EXPECT_NO_THROW(validate_mesh(m, "saw_tooth"));
    ASSERT_EQ(m.group_names, std::vector<std::string>{"saw_tooth"});
    const double hg = s.height_m, W = s.width_m, L = s.length_m;
    const double a = hg / std::tan(45 * kDeg);
    int tips = 0;
    for (const auto& v : m.vertices) {
      EXPECT_TRUE(v.y() == 0 || v.y() == W);
      EXPECT_GE(v.z(), 0.0);
      EXPECT_LE(v.z(), hg);
      if (v.z() == hg && v.y() == 0) ++tips;
      const auto [lo, hi] = tooth_heights(v.x(), hg, s.spacing_m, 45);
      EXPECT_GE(v.z(), lo - 1e-15 * hg) << "u = " << v.x();
      EXPECT_LE(v.z(), hi + 1e-15 * hg) << "u = " << v.x();
      if (lo != hi) {
        EXPECT_TRUE(v.z() == 0 || v.z() == hg);
      }
    }
    EXPECT_EQ(tips, 100) << "R_n = " << sc.rn;
    int ramps = 0, backs = 0;
    double worst_slope = 0;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const Eigen::Vector3d n = triangle_normal(m, t);
      EXPECT_GE(n.z(), 0.0);
      EXPECT_EQ(n.y(), 0.0);
      const Eigen::Vector3d c = centroid(m, t);
      const auto [lo, hi] = tooth_heights(c.x(), hg, s.spacing_m, 45);
      EXPECT_GE(c.z(), lo - 1e-15 * L);
      EXPECT_LE(c.z(), hi + 1e-15 * L);
      if (n.x() < 0 && n.z() > 0) {
        ++ramps;
        worst_slope = std::max(worst_slope, std::abs(-n.x() / n.z() / std::tan(45 * kDeg) - 1));
      } else if (n.z() == 0) {
        ++backs;
        EXPECT_EQ(n, Eigen::Vector3d::UnitX());
      }
    }
    EXPECT_EQ(ramps, 200);
    EXPECT_EQ(backs, 200);
    EXPECT_LE(worst_slope, 1e-12);
    const double want = W * (L + 100 * (std::hypot(a, hg) - a + hg));
    EXPECT_NEAR(total_area(m), want, 1e-14 * want);
    EXPECT_NEAR(projected_area_xy(m), L * W, 1e-14 * L * W);
    std::printf("R_n = %g: %zu triangles, worst relative slope error %.2e, area error %.2e\n",
                sc.rn, m.triangles.size(), worst_slope, total_area(m) / want - 1);
  }
}

// Plain saw-tooth (s_g = a, no land) and symmetric teeth (back slope = α_g = 30°, s_g = 2a):
// tips exactly at (k·s_g + a, h_g); tooth count L/s_g = 7; plain: 2 strips per tooth, the last
// back face at u = L; symmetric: back faces slope −tan 30° to 1e-12.
TEST(SurfaceGenerators, SawToothPlainAndSymmetric) {
  SawToothSpec s;
  s.height_m = 0.002;
  s.slope_deg = 30;
  const double a = s.height_m / std::tan(30 * kDeg);
  s.spacing_m = a;
  s.length_m = 7 * a;
  s.width_m = 0.01;
  const TriangleMesh plain = saw_tooth_wall(s);
  EXPECT_EQ(plain.triangles.size(), 7u * 2 * 2);
  EXPECT_EQ(plain.vertices.size(), 2u * (1 + 2 * 7));
  EXPECT_EQ(plain.vertices[plain.vertices.size() - 4].x(), s.length_m);  // last tip on the end
  EXPECT_NO_THROW(validate_mesh(plain, "plain"));

  s.back_slope_deg = 30;
  s.spacing_m = 2 * a;
  s.length_m = 7 * s.spacing_m;
  const TriangleMesh sym = saw_tooth_wall(s);
  EXPECT_EQ(sym.triangles.size(), 7u * 2 * 2);
  int tips = 0;
  for (const auto& v : sym.vertices)
    if (v.z() == s.height_m) {
      ++tips;
      const double k = std::round((v.x() - a) / s.spacing_m);
      EXPECT_NEAR(v.x(), k * s.spacing_m + a, 1e-15 * s.length_m);
    }
  EXPECT_EQ(tips, 14);
  double worst = 0;
  for (std::size_t t = 0; t < sym.triangles.size(); ++t) {
    const Eigen::Vector3d n = triangle_normal(sym, t);
    worst = std::max(worst, std::abs(std::abs(n.x() / n.z()) / std::tan(30 * kDeg) - 1));
  }
  EXPECT_LE(worst, 1e-12);
}

// A saw-tooth in a rotated frame (along (1,1,0)/√2, normal z, origin (1, 2, 3)) is the
// axis-aligned one moved rigidly: every vertex origin + u·e_u + v·e_v + h·e_z to 1e-15·|origin|,
// same area to 1e-14, normals rotated likewise to 1e-12; the patch ends (L not a multiple of s_g)
// are land.
TEST(SurfaceGenerators, SawToothRotatedFrame) {
  SawToothSpec s;
  s.height_m = 1e-3;
  s.spacing_m = 3e-3;
  s.slope_deg = 40;
  s.length_m = 0.0205;  // 7 teeth (6·s_g + base ≤ L < 7·s_g + base), then land to L
  s.width_m = 4e-3;
  const TriangleMesh ref = saw_tooth_wall(s);
  s.origin = {1, 2, 3};
  s.along = {1, 1, 0};
  const TriangleMesh rot = saw_tooth_wall(s);
  ASSERT_EQ(rot.vertices.size(), ref.vertices.size());
  const Eigen::Vector3d eu = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d ev = Eigen::Vector3d::UnitZ().cross(eu);
  for (std::size_t i = 0; i < ref.vertices.size(); ++i) {
    const Eigen::Vector3d& p = ref.vertices[i];
    EXPECT_LE(
        (rot.vertices[i] - (s.origin + p.x() * eu + p.y() * ev + p.z() * Eigen::Vector3d::UnitZ()))
            .norm(),
        1e-15 * s.origin.norm());
  }
  int tips = 0;
  for (const auto& v : ref.vertices) tips += v.z() == s.height_m && v.y() == 0;
  EXPECT_EQ(tips, 7);
  EXPECT_EQ(ref.vertices.back().x(), s.length_m);
  EXPECT_EQ(ref.vertices.back().z(), 0.0);
  EXPECT_NEAR(total_area(rot), total_area(ref), 1e-14 * total_area(ref));
  for (std::size_t t = 0; t < ref.triangles.size(); ++t) {
    const Eigen::Vector3d n = triangle_normal(ref, t);
    EXPECT_LE(
        (triangle_normal(rot, t) - (n.x() * eu + n.y() * ev + n.z() * Eigen::Vector3d::UnitZ()))
            .norm(),
        1e-12);  // coordinates rounded at |origin| ≈ 3.7 m over edges of about 1 mm
  }
}

// The saw-tooth wall of the YADE facets reference silo (x = 0 wall: 9 teeth, h = 1.5 mm,
// p = 5 mm, ramp slope h/p = 0.3, so α_g = atan 0.3, s_g = p; along −z from z = 0.045, normal
// +x, width 0.032 m along y; end_face = false since the bottom covers the step at z = 0) is
// saw_tooth_wall's: 34 triangles as in group "sawtooth", the same set of vertices to 1e-15 m,
// normals with n_x ≥ 0 (into the silo, as the reference's), the same area to 1e-15 relative.
TEST(SurfaceGenerators, SawToothMatchesYadeFacetsSilo) {
  const fs::path csv =
      fs::path(GS_SOURCE_DIR) / ".." / "shared" / "reference" / "yade" / "facets" / "mesh.csv";
  if (!fs::exists(csv)) GTEST_SKIP() << "reference mesh absent: " << csv.string();
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<Eigen::Vector3d> ref;
  double ref_area = 0;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) f.push_back(c);
    if (f.size() != 11 || f[1] != "sawtooth") continue;
    Eigen::Vector3d c[3];
    for (int k = 0; k < 3; ++k) {
      for (int d = 0; d < 3; ++d) c[k][d] = std::strtod(f[2 + 3 * k + d].c_str(), nullptr);
      ref.push_back(c[k]);
    }
    ref_area += triangle_area(c[0], c[1], c[2]);
  }
  ASSERT_EQ(ref.size(), 34u * 3);
  SawToothSpec s;
  s.origin = {0, 0, 0.045};
  s.along = -Eigen::Vector3d::UnitZ();
  s.normal = Eigen::Vector3d::UnitX();
  s.height_m = 0.0015;
  s.spacing_m = 0.005;
  s.slope_deg = std::atan(0.3) / kDeg;
  s.length_m = 0.045;
  s.end_face = false;
  s.width_m = 0.032;
  const TriangleMesh m = saw_tooth_wall(s);
  auto near_any = [](const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& set) {
    for (const auto& q : set)
      if ((p - q).norm() <= 1e-15) return true;
    return false;
  };
  for (const auto& p : ref) EXPECT_TRUE(near_any(p, m.vertices)) << p.transpose();
  for (const auto& p : m.vertices) EXPECT_TRUE(near_any(p, ref)) << p.transpose();
  EXPECT_EQ(m.triangles.size(), 34u);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) EXPECT_GE(triangle_normal(m, t).x(), 0.0);
  EXPECT_NEAR(total_area(m), ref_area, 1e-15 * ref_area);
  s.end_face = true;  // the default closes the profile at z = 0 with the step's h × 0.032 m
  const TriangleMesh closed = saw_tooth_wall(s);
  EXPECT_EQ(closed.triangles.size(), 36u);
  EXPECT_NEAR(total_area(closed), ref_area + 0.0015 * 0.032, 1e-15 * ref_area);
}

// Sinusoid h = d/2·sin(2πu/l) (seed 004 §4.4: l = 15 mm, d = 3.6 mm, d/l = 0.24, shear box
// b = 60 mm, depth 7 mm): nodes at u_i = i·l/32, every vertex height on the curve at its u_i to
// 1e-15·d/2 (the curve in long double), each wavelength's heights identical, height
// exactly 0 at whole wavelengths; dyadic sizes (l = 0.5, L = 2, W = 0.25, N = 16) give a
// projected area of exactly L·W, the seed sizes L·W to 1e-14; normals on the material side.
TEST(SurfaceGenerators, SinusoidOnTheCurve) {
  SinusoidSpec s;
  s.wavelength_m = 0.015;
  s.depth_m = 0.0036;
  s.length_m = 0.06;
  s.width_m = 0.007;
  s.segments_per_wavelength = 32;
  const TriangleMesh m = sinusoidal_wall(s);
  EXPECT_NO_THROW(validate_mesh(m, "sinusoid"));
  EXPECT_EQ(m.vertices.size(), 2u * (4 * 32 + 1));
  EXPECT_EQ(m.triangles.size(), 2u * 4 * 32);
  double worst = 0;
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    const Eigen::Vector3d& v = m.vertices[k];
    const long i = static_cast<long>(k / 2);  // node i at u_i = i·l/32 (vertices 2i, 2i + 1)
    EXPECT_EQ(v.x(), static_cast<double>(i) * s.wavelength_m / 32);
    // The curve at u_i, in long double (64-bit mantissa) from the exact phase i/32.
    const long double h = 0.5L * s.depth_m * std::sin(2 * std::numbers::pi_v<long double> * i / 32);
    worst = std::max(worst, static_cast<double>(std::abs(v.z() - h)));
    EXPECT_TRUE(v.y() == 0 || v.y() == s.width_m);
  }
  EXPECT_LE(worst, 1e-15 * 0.5 * s.depth_m);
  std::printf("sinusoid: worst height error %.3g m (%.3g of d/2)\n", worst,
              worst / (0.5 * s.depth_m));
  for (std::size_t i = 0; i + 2 * 32 < m.vertices.size(); ++i)  // every wavelength the same
    EXPECT_EQ(m.vertices[i].z(), m.vertices[i + 2 * 32].z());
  for (std::size_t i = 0; i < m.vertices.size(); i += 2 * 32) EXPECT_EQ(m.vertices[i].z(), 0.0);
  EXPECT_NEAR(m.vertices.back().z(), 0.0, 1e-15 * s.depth_m);
  EXPECT_EQ(m.vertices.back().x(), s.length_m);
  EXPECT_NEAR(projected_area_xy(m), s.length_m * s.width_m, 1e-14 * s.length_m * s.width_m);
  for (std::size_t t = 0; t < m.triangles.size(); ++t) EXPECT_GT(triangle_normal(m, t).z(), 0.0);

  SinusoidSpec d;
  d.wavelength_m = 0.5;
  d.depth_m = 0.1;
  d.length_m = 2;
  d.width_m = 0.25;
  d.segments_per_wavelength = 16;
  EXPECT_EQ(projected_area_xy(sinusoidal_wall(d)), 2 * 0.25);

  // L not a whole number of segments: nodes i·l/N up to L, then L itself.
  d.length_m = 1.234 * d.wavelength_m;
  const TriangleMesh part = sinusoidal_wall(d);
  EXPECT_EQ(part.vertices.size(), 2u * (19 + 1 + 1));  // i = 0 … 19, then L
  EXPECT_EQ(part.vertices.back().x(), d.length_m);
  EXPECT_NEAR(projected_area_xy(part), d.length_m * d.width_m, 1e-15);
}

// Surface area of the triangulated sinusoid → W·∫₀ᴸ √(1 + (πd/l·cos 2πu/l)²) du. The reference
// is the periodic trapezoidal rule (4096 nodes per wavelength, exponentially convergent for
// this smooth periodic integrand), equal to the closed form W·(L/l)·(2l/π)·√(1+A²)·E(k),
// A = πd/l, k² = A²/(1+A²), to 1e-14. The polyline (chord) error falls at second order:
// log2(e_N / e_2N) in [1.98, 2.02] for N = 16 … 256 segments per wavelength.
TEST(SurfaceGenerators, SinusoidAreaConvergesAtSecondOrder) {
  const double l = 0.015, d = 0.0036, L = 2 * l, W = 0.007;
  const double A = std::numbers::pi * d / l;
  auto integrand = [&](double u) {
    const double c = A * std::cos(2 * std::numbers::pi * u / l);
    return std::sqrt(1 + c * c);
  };
  const int M = 4096;
  double sum = 0;
  for (int i = 0; i < M; ++i) sum += integrand(l * i / M);
  const double exact = W * (L / l) * l * sum / M;
  const double k = A / std::sqrt(1 + A * A);
  const double closed =
      W * (L / l) * (2 * l / std::numbers::pi) * std::sqrt(1 + A * A) * std::comp_ellint_2(k);
  EXPECT_NEAR(exact, closed, 1e-14 * closed);
  std::vector<double> err;
  for (int N : {16, 32, 64, 128, 256}) {
    SinusoidSpec s;
    s.wavelength_m = l;
    s.depth_m = d;
    s.length_m = L;
    s.width_m = W;
    s.segments_per_wavelength = N;
    const double a = total_area(sinusoidal_wall(s));
    err.push_back(exact - a);
    EXPECT_GT(exact - a, 0.0);  // chords are shorter than the arc
  }
  for (std::size_t i = 0; i + 1 < err.size(); ++i) {
    const double order = std::log2(err[i] / err[i + 1]);
    std::printf("N = %d: relative area error %.3e, observed order %.4f\n", 16 << i, err[i] / exact,
                order);
    EXPECT_GE(order, 1.98);
    EXPECT_LE(order, 2.02);
  }
}

// Box [(-1, 0.5, 2), (2, 1.25, 6)] (a, b, c = 3, 0.75, 4): 8 vertices, 12 triangles, area
// 2(ab+bc+ca) = 34.5 exactly; inward: every normal is an axis (exactly) pointing from its
// triangle towards the box centre, divergence-theorem volume −abc = −9 (+9 outward) to 1e-15
// relative; closed and consistently oriented (every directed edge once, its reverse once);
// each face group holds its two triangles on its plane.
TEST(SurfaceGenerators, BoxMesh) {
  const Eigen::Vector3d lo(-1, 0.5, 2), hi(2, 1.25, 6);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  for (const BoxFacing facing : {BoxFacing::Inward, BoxFacing::Outward}) {
    const TriangleMesh m = box_mesh(lo, hi, facing);
    EXPECT_NO_THROW(validate_mesh(m, "box"));
    EXPECT_EQ(m.vertices.size(), 8u);
    ASSERT_EQ(m.triangles.size(), 12u);
    EXPECT_EQ(total_area(m), 34.5);
    const double sign = facing == BoxFacing::Inward ? 1 : -1;
    double volume = 0;
    std::map<std::pair<int, int>, int> directed;
    for (std::size_t t = 0; t < 12; ++t) {
      const auto& tr = m.triangles[t];
      volume += m.vertices[tr[0]].dot(m.vertices[tr[1]].cross(m.vertices[tr[2]])) / 6;
      const Eigen::Vector3d n = triangle_normal(m, t);
      EXPECT_EQ(n.cwiseAbs().sum(), 1.0);
      EXPECT_EQ(n.cwiseAbs().maxCoeff(), 1.0);
      EXPECT_GT(sign * n.dot(centre - centroid(m, t)), 0.0);
      for (int e = 0; e < 3; ++e) ++directed[{tr[e], tr[(e + 1) % 3]}];
      const std::string& g = m.group_names[m.group[t]];
      const int axis = g[0] - 'x';
      const double plane = g.substr(2) == "min" ? lo[axis] : hi[axis];
      for (int k = 0; k < 3; ++k) EXPECT_EQ(m.vertices[tr[k]][axis], plane) << g;
    }
    EXPECT_NEAR(volume, -sign * 9, 1e-15 * 9);
    EXPECT_EQ(directed.size(), 36u);
    for (const auto& [e, n] : directed) {
      EXPECT_EQ(n, 1);
      EXPECT_EQ(directed.count({e.second, e.first}), 1u);
    }
    std::map<int, int> per_group;
    for (int g : m.group) ++per_group[g];
    EXPECT_EQ(per_group.size(), 6u);
    for (const auto& [g, n] : per_group) EXPECT_EQ(n, 2);
  }
}

// Bad parameters: std::invalid_argument with the exact message "FUNCTION: parameter … (value)".
TEST(SurfaceGenerators, BadParameters) {
  auto saw = [](auto edit) {
    SawToothSpec s;
    s.height_m = 1e-3;
    s.spacing_m = 4e-3;
    s.slope_deg = 45;
    s.length_m = 0.04;
    s.width_m = 0.01;
    edit(s);
    return message_of([&] { (void)saw_tooth_wall(s); });
  };
  EXPECT_EQ(saw([](SawToothSpec& s) { s.height_m = 0; }),
            "saw_tooth_wall: height_m must be finite and > 0 (0)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.height_m = -0.001; }),
            "saw_tooth_wall: height_m must be finite and > 0 (-0.001)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.spacing_m = 0; }),
            "saw_tooth_wall: spacing_m must be finite and > 0 (0)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.spacing_m = -2; }),
            "saw_tooth_wall: spacing_m must be finite and > 0 (-2)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.slope_deg = 0; }),
            "saw_tooth_wall: slope_deg must be in (0, 90) (0)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.slope_deg = 90; }),
            "saw_tooth_wall: slope_deg must be in (0, 90) (90)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.slope_deg = -10; }),
            "saw_tooth_wall: slope_deg must be in (0, 90) (-10)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.slope_deg = std::nan(""); }),
            "saw_tooth_wall: slope_deg must be in (0, 90) (nan)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.back_slope_deg = 30; }),
            "saw_tooth_wall: back_slope_deg must be in [slope_deg, 90] (30)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.width_m = 0; }),
            "saw_tooth_wall: width_m must be finite and > 0 (0)");
  const std::string narrow = saw([](SawToothSpec& s) { s.spacing_m = 5e-4; });
  EXPECT_EQ(narrow.rfind("saw_tooth_wall: spacing_m is narrower than the tooth base", 0), 0u)
      << narrow;
  EXPECT_EQ(narrow.substr(narrow.size() - 25), " (0.00050000000000000001)");
  const std::string shorter = saw([](SawToothSpec& s) { s.length_m = 5e-4; });
  EXPECT_EQ(shorter.rfind("saw_tooth_wall: length_m is shorter than one tooth base", 0), 0u)
      << shorter;
  EXPECT_EQ(saw([](SawToothSpec& s) {
              s.normal = {1, 0, 1};
            }),
            "saw_tooth_wall: along and normal must be perpendicular, cos (0.70710678118654746)");
  EXPECT_EQ(saw([](SawToothSpec& s) { s.along = Eigen::Vector3d::Zero(); }),
            "saw_tooth_wall: along must be a nonzero vector, |along| (0)");

  auto sine = [](auto edit) {
    SinusoidSpec s;
    s.wavelength_m = 0.015;
    s.depth_m = 0.0036;
    s.length_m = 0.06;
    s.width_m = 0.007;
    edit(s);
    return message_of([&] { (void)sinusoidal_wall(s); });
  };
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.wavelength_m = 0; }),
            "sinusoidal_wall: wavelength_m must be finite and > 0 (0)");
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.wavelength_m = -0.015; }),
            "sinusoidal_wall: wavelength_m must be finite and > 0 (-0.014999999999999999)");
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.segments_per_wavelength = 1; }),
            "sinusoidal_wall: segments_per_wavelength must be >= 2 (1)");
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.segments_per_wavelength = -4; }),
            "sinusoidal_wall: segments_per_wavelength must be >= 2 (-4)");
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.depth_m = -1e-3; }),
            "sinusoidal_wall: depth_m must be finite and >= 0 (-0.001)");
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.length_m = 0; }),
            "sinusoidal_wall: length_m must be finite and > 0 (0)");
  EXPECT_EQ(sine([](SinusoidSpec&) {}), "no error");
  EXPECT_EQ(sine([](SinusoidSpec& s) { s.segments_per_wavelength = 2; }), "no error");

  EXPECT_EQ(message_of([] {
              (void)box_mesh({0, 0, 0}, {1, 0, 1});
            }),
            "box_mesh: lo must be below hi in y, hi - lo (0)");
  EXPECT_EQ(message_of([] {
              (void)box_mesh({0, 0, 2}, {1, 1, 1});
            }),
            "box_mesh: lo must be below hi in z, hi - lo (-1)");
}
