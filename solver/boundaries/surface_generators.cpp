#include "surface_generators.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace gs::solver {

namespace {

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

[[noreturn]] void bad(const char* fn, const std::string& what, double value) {
  throw std::invalid_argument(std::string(fn) + ": " + what + " (" + num(value) + ")");
}

void need_positive(const char* fn, const char* name, double v) {
  if (!(std::isfinite(v) && v > 0)) bad(fn, std::string(name) + " must be finite and > 0", v);
}

struct Frame {
  Eigen::Vector3d o, eu, ev, en;
};

Frame patch_frame(const char* fn, const Eigen::Vector3d& origin, const Eigen::Vector3d& along,
                  const Eigen::Vector3d& normal) {
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(origin[d])) bad(fn, "origin must be finite", origin[d]);
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(along[d]) || !std::isfinite(normal[d]))
      bad(fn, "along and normal must be finite", std::isfinite(along[d]) ? normal[d] : along[d]);
  if (!(along.norm() > 0)) bad(fn, "along must be a nonzero vector, |along|", along.norm());
  if (!(normal.norm() > 0)) bad(fn, "normal must be a nonzero vector, |normal|", normal.norm());
  Frame f;
  f.o = origin;
  f.eu = along.normalized();
  f.en = normal.normalized();
  const double c = f.eu.dot(f.en);
  if (std::abs(c) > 1e-12) bad(fn, "along and normal must be perpendicular, cos", c);
  f.ev = f.en.cross(f.eu);
  return f;
}

// The patch over the profile nodes (u_i, h_i): vertices 2i at v = 0 and 2i+1 at v = W; strip
// i → i+1 is the quad (2i, 2i+2, 2i+3, 2i+1), split along (2i, 2i+3). Its facet normal is
// W·(Δu·e_n − Δh·e_u) / |…|: towards the material side.
TriangleMesh extrude_profile(const Frame& f, const std::vector<std::pair<double, double>>& nodes,
                             double width, const std::string& group) {
  TriangleMesh m;
  m.group_names = {group.empty() ? std::string("mesh") : group};
  m.vertices.reserve(2 * nodes.size());
  for (const auto& [u, h] : nodes) {
    m.vertices.push_back(f.o + u * f.eu + h * f.en);
    m.vertices.push_back(f.o + u * f.eu + width * f.ev + h * f.en);
  }
  for (int i = 0; i + 1 < static_cast<int>(nodes.size()); ++i) {
    m.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 3});
    m.triangles.push_back({2 * i, 2 * i + 3, 2 * i + 1});
  }
  m.group.assign(m.triangles.size(), 0);
  return m;
}

}  // namespace

TriangleMesh saw_tooth_wall(const SawToothSpec& s) {
  const char* fn = "saw_tooth_wall";
  need_positive(fn, "height_m", s.height_m);
  need_positive(fn, "spacing_m", s.spacing_m);
  if (!(s.slope_deg > 0 && s.slope_deg < 90)) bad(fn, "slope_deg must be in (0, 90)", s.slope_deg);
  if (!(s.back_slope_deg >= s.slope_deg && s.back_slope_deg <= 90))
    bad(fn, "back_slope_deg must be in [slope_deg, 90]", s.back_slope_deg);
  need_positive(fn, "length_m", s.length_m);
  need_positive(fn, "width_m", s.width_m);
  const Frame f = patch_frame(fn, s.origin, s.along, s.normal);

  const double deg = std::numbers::pi / 180;
  const double hg = s.height_m, sg = s.spacing_m, L = s.length_m;
  const double a = hg / std::tan(s.slope_deg * deg);
  const double c = s.back_slope_deg == 90 ? 0.0 : hg / std::tan(s.back_slope_deg * deg);
  const double base = a + c;
  const double tol = 1e-9 * sg;
  if (base > sg + tol)
    bad(fn,
        "spacing_m is narrower than the tooth base h_g/tan(slope) + h_g/tan(back slope) = " +
            num(base) + " m",
        sg);
  if (base > L + tol) bad(fn, "length_m is shorter than one tooth base " + num(base) + " m", L);
  const bool no_land = base >= sg - tol;  // plain saw-tooth: each tooth ends where the next starts

  // Teeth k = 0 … n−1, those with k·s_g + base ≤ L.
  long n = static_cast<long>(std::floor((L - base) / sg)) + 1;
  while (n > 1 && (n - 1) * sg + base > L + tol) --n;
  while (n * sg + base <= L + tol) ++n;

  std::vector<std::pair<double, double>> nodes{{0.0, 0.0}};
  for (long k = 0; k < n; ++k) {
    const double u0 = static_cast<double>(k) * sg;
    if (nodes.back().first < u0) nodes.emplace_back(u0, 0.0);  // end of the land before
    double end = no_land ? static_cast<double>(k + 1) * sg : u0 + base;
    if (k == n - 1 && std::abs(end - L) <= tol) end = L;
    const double tip = c == 0 ? end : u0 + a;
    nodes.emplace_back(tip, hg);
    nodes.emplace_back(end, 0.0);
  }
  if (nodes.back().first < L) {
    nodes.emplace_back(L, 0.0);
  } else if (!s.end_face && c == 0) {
    nodes.pop_back();  // the vertical face (L, h_g) → (L, 0)
  }
  return extrude_profile(f, nodes, s.width_m, s.group);
}

TriangleMesh sinusoidal_wall(const SinusoidSpec& s) {
  const char* fn = "sinusoidal_wall";
  need_positive(fn, "wavelength_m", s.wavelength_m);
  if (!(std::isfinite(s.depth_m) && s.depth_m >= 0))
    bad(fn, "depth_m must be finite and >= 0", s.depth_m);
  if (s.segments_per_wavelength < 2)
    bad(fn, "segments_per_wavelength must be >= 2", s.segments_per_wavelength);
  need_positive(fn, "length_m", s.length_m);
  need_positive(fn, "width_m", s.width_m);
  const Frame f = patch_frame(fn, s.origin, s.along, s.normal);

  const double l = s.wavelength_m, L = s.length_m;
  const double N = s.segments_per_wavelength;
  const double step = l / N;
  const double tol = 1e-9 * step;
  std::vector<std::pair<double, double>> nodes;
  const double two_pi = 2 * std::numbers::pi;
  // The phase is reduced to [0, 1) before the sine (node i: (i mod N)/N, exact up to one
  // rounding), so every wavelength repeats the same heights bit for bit and h(k·l) = 0 exactly.
  auto height = [&](double phase) { return 0.5 * s.depth_m * std::sin(two_pi * phase); };
  const long n_seg = s.segments_per_wavelength;
  for (long i = 0;; ++i) {
    const double u = static_cast<double>(i) * l / N;
    if (u > L - tol) {
      const double q = L / l;
      nodes.emplace_back(L, height(q - std::floor(q)));
      break;
    }
    nodes.emplace_back(u, height(static_cast<double>(i % n_seg) / N));
  }
  return extrude_profile(f, nodes, s.width_m, s.group);
}

TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, BoxFacing facing) {
  for (int d = 0; d < 3; ++d)
    if (!(std::isfinite(lo[d]) && std::isfinite(hi[d]) && lo[d] < hi[d]))
      bad("box_mesh", std::string("lo must be below hi in ") + "xyz"[d] + ", hi - lo",
          hi[d] - lo[d]);
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)  // corner i: bit 0 → x, bit 1 → y, bit 2 → z at hi
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
  // Each face counter-clockwise seen from inside (normal into the box).
  static const int quad[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                 {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  m.group_names = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  for (int q = 0; q < 6; ++q) {
    int c[4] = {quad[q][0], quad[q][1], quad[q][2], quad[q][3]};
    if (facing == BoxFacing::Outward) std::swap(c[1], c[3]);
    m.triangles.push_back({c[0], c[1], c[2]});
    m.triangles.push_back({c[0], c[2], c[3]});
    m.group.push_back(q);
    m.group.push_back(q);
  }
  return m;
}

}  // namespace gs::solver
