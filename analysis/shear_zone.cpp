// Shear-zone inclination (ridge of the band maximum, trimmed line fit) and thickness (inflection
// points of the profile across the band, seed 004 §4.2.3); method in the header.
#include "shear_zone.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

namespace gs::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double at(const ScalarMap& m, int i, int j) {
  return m.value[static_cast<std::size_t>(i) + static_cast<std::size_t>(m.nu) * j];
}

// Ridge along lines of the map: along rows (maxima over i for each j) or columns.
struct Ridge {
  std::vector<Eigen::Vector2d> points;
};

Ridge find_ridge(const ScalarMap& m, bool rows) {
  const int lines = rows ? m.nv : m.nu, len = rows ? m.nu : m.nv;
  auto value = [&](int line, int k) { return rows ? at(m, k, line) : at(m, line, k); };
  std::vector<double> contrast(static_cast<std::size_t>(lines), kNaN);
  std::vector<double> pos(static_cast<std::size_t>(lines), kNaN);
  for (int l = 0; l < lines; ++l) {
    std::vector<double> vals;
    int kmax = -1;
    for (int k = 0; k < len; ++k) {
      const double v = value(l, k);
      if (!std::isfinite(v)) continue;
      vals.push_back(v);
      if (kmax < 0 || v > value(l, kmax)) kmax = k;
    }
    if (kmax < 0 || vals.size() < 3) continue;
    double off = 0.0;
    if (kmax > 0 && kmax < len - 1) {
      const double a = value(l, kmax - 1), b = value(l, kmax), c = value(l, kmax + 1);
      const double den = a - 2.0 * b + c;
      if (std::isfinite(a) && std::isfinite(c) && den < 0.0)
        off = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
    }
    contrast[static_cast<std::size_t>(l)] = value(l, kmax) - median(vals);
    pos[static_cast<std::size_t>(l)] = kmax + off;
  }
  double best = 0.0;
  for (double c : contrast)
    if (std::isfinite(c)) best = std::max(best, c);
  Ridge r;
  if (!(best > 0.0)) return r;
  for (int l = 0; l < lines; ++l) {
    const double c = contrast[static_cast<std::size_t>(l)];
    if (!(c >= 0.25 * best)) continue;
    const double along = (rows ? m.u0 : m.v0) + pos[static_cast<std::size_t>(l)] * m.step;
    const double across = (rows ? m.v0 : m.u0) + l * m.step;
    r.points.push_back(rows ? Eigen::Vector2d(along, across) : Eigen::Vector2d(across, along));
  }
  return r;
}

struct LineFit {
  bool ok = false;
  Eigen::Vector2d point = Eigen::Vector2d::Zero(), direction = Eigen::Vector2d::UnitX();
  std::vector<std::uint8_t> inlier;
};

// Fit along = a + b * across (rows: u = a + b v; columns: v = a + b u) with 3-sigma trimming.
LineFit fit_line(const std::vector<Eigen::Vector2d>& p, bool rows, double step) {
  LineFit f;
  const std::size_t n = p.size();
  if (n < 3) return f;
  auto along = [&](std::size_t k) { return rows ? p[k].x() : p[k].y(); };
  auto across = [&](std::size_t k) { return rows ? p[k].y() : p[k].x(); };
  f.inlier.assign(n, 1);
  double a = 0.0, b = 0.0;
  for (int it = 0; it < 20; ++it) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0, cnt = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (!f.inlier[k]) continue;
      sx += across(k);
      sy += along(k);
      sxx += across(k) * across(k);
      sxy += across(k) * along(k);
      ++cnt;
    }
    if (cnt < 3) return f;
    const double mx = sx / cnt, my = sy / cnt, vx = sxx / cnt - mx * mx;
    if (!(vx > 0.0)) return f;
    b = (sxy / cnt - mx * my) / vx;
    a = my - b * mx;
    std::vector<double> res;
    for (std::size_t k = 0; k < n; ++k) res.push_back(std::abs(along(k) - (a + b * across(k))));
    std::vector<double> kept;
    for (std::size_t k = 0; k < n; ++k)
      if (f.inlier[k]) kept.push_back(res[k]);
    const double limit = std::max(3.0 * 1.4826 * median(kept), step);
    bool changed = false;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint8_t in = res[k] <= limit;
      changed = changed || in != f.inlier[k];
      f.inlier[k] = in;
    }
    if (!changed) break;
  }
  double mx = 0.0, cnt = 0.0;
  for (std::size_t k = 0; k < n; ++k)
    if (f.inlier[k]) mx += across(k), ++cnt;
  mx /= cnt;
  f.point = rows ? Eigen::Vector2d(a + b * mx, mx) : Eigen::Vector2d(mx, a + b * mx);
  f.direction = (rows ? Eigen::Vector2d(b, 1.0) : Eigen::Vector2d(1.0, b)).normalized();
  f.ok = true;
  return f;
}

double bilinear(const ScalarMap& m, const Eigen::Vector2d& x) {
  const double fi = (x.x() - m.u0) / m.step, fj = (x.y() - m.v0) / m.step;
  if (!(fi >= 0.0 && fj >= 0.0 && fi <= m.nu - 1 && fj <= m.nv - 1)) return kNaN;
  const int i = std::min(static_cast<int>(fi), std::max(0, m.nu - 2));
  const int j = std::min(static_cast<int>(fj), std::max(0, m.nv - 2));
  const double ti = m.nu > 1 ? fi - i : 0.0, tj = m.nv > 1 ? fj - j : 0.0;
  const int i1 = std::min(i + 1, m.nu - 1), j1 = std::min(j + 1, m.nv - 1);
  return (1 - ti) * (1 - tj) * at(m, i, j) + ti * (1 - tj) * at(m, i1, j) +
         (1 - ti) * tj * at(m, i, j1) + ti * tj * at(m, i1, j1);
}

// Mean of the map along the line, sampled every half step inside the map.
double line_mean(const ScalarMap& m, const LineFit& f) {
  const double reach = std::hypot(m.nu, m.nv) * m.step;
  double s = 0.0;
  int n = 0;
  for (double t = -reach; t <= reach; t += 0.5 * m.step) {
    const double v = bilinear(m, f.point + t * f.direction);
    if (std::isfinite(v)) s += v, ++n;
  }
  return n > 0 ? s / n : kNaN;
}

// Position of the first sign change of the second difference from `start` in direction `dir`,
// after it has been negative (concave flank of the peak); NaN if the profile ends first.
double inflection(const std::vector<double>& d, const std::vector<double>& f, int start, int dir) {
  const int n = static_cast<int>(f.size());
  auto second = [&](int k) { return f[k + 1] - 2.0 * f[k] + f[k - 1]; };
  bool concave = false;
  double prev = 0.0;
  int kprev = -1;
  for (int k = start; k >= 1 && k <= n - 2; k += dir) {
    const double s = second(k);
    if (s < 0.0) concave = true;
    if (concave && s >= 0.0 && kprev >= 0) {
      const double t = prev / (prev - s);  // prev < 0 <= s
      return d[static_cast<std::size_t>(kprev)] +
             t * (d[static_cast<std::size_t>(k)] - d[static_cast<std::size_t>(kprev)]);
    }
    prev = s;
    kprev = k;
  }
  return kNaN;
}

}  // namespace

ShearZone shear_zone(const ScalarMap& m) {
  if (m.nu < 3 || m.nv < 3 || !(m.step > 0.0) ||
      m.value.size() != static_cast<std::size_t>(m.nu) * static_cast<std::size_t>(m.nv)) {
    throw std::invalid_argument("shear zone: the map needs at least 3 x 3 cells");
  }
  ShearZone z;
  const Ridge rr = find_ridge(m, true), rc = find_ridge(m, false);
  const LineFit fr = fit_line(rr.points, true, m.step), fcol = fit_line(rc.points, false, m.step);
  const double sr = fr.ok ? line_mean(m, fr) : kNaN, sc = fcol.ok ? line_mean(m, fcol) : kNaN;
  if (!std::isfinite(sr) && !std::isfinite(sc))
    throw std::invalid_argument("shear zone: no band found in the map");
  z.by_rows = std::isfinite(sr) && !(sc > sr);
  const LineFit& f = z.by_rows ? fr : fcol;
  z.ridge = z.by_rows ? rr.points : rc.points;
  z.inlier = f.inlier;
  z.point = f.point;
  z.direction = f.direction;
  z.line_mean = z.by_rows ? sr : sc;
  double ang = std::atan2(f.direction.y(), f.direction.x()) * 180.0 / std::numbers::pi;
  if (ang < 0.0) ang += 180.0;
  if (ang >= 180.0) ang -= 180.0;
  z.angle_deg = ang;
  z.inclination_deg = std::min(ang, 180.0 - ang);

  // Profile across the band: the mean of the map along lines parallel to the fitted one, one step
  // apart (bilinear samples every half step), outwards from the line while the map lasts.
  const Eigen::Vector2d normal(-f.direction.y(), f.direction.x());
  const double reach = std::hypot(m.nu, m.nv) * m.step;
  std::map<long, double> prof;
  for (const int side : {1, -1}) {
    for (long k = side > 0 ? 0 : -1;; k += side) {
      double sum = 0.0;
      int n = 0;
      for (double t = -reach; t <= reach; t += 0.5 * m.step) {
        const double v =
            bilinear(m, f.point + static_cast<double>(k) * m.step * normal + t * f.direction);
        if (std::isfinite(v)) sum += v, ++n;
      }
      if (n < 3) break;
      prof[k] = sum / n;
    }
  }
  for (const auto& [k, v] : prof) {
    z.profile_d.push_back(static_cast<double>(k) * m.step);
    z.profile_value.push_back(v);
  }
  // The profile smoothed by the binomial [1 2 1] / 4 (particle-scale noise would otherwise make
  // the second difference change sign early; it widens the band by a variance of s^2 / 2).
  const std::size_t np = z.profile_value.size();
  std::vector<double> sm = z.profile_value;
  for (std::size_t k = 1; k + 1 < np; ++k)
    sm[k] = 0.25 * (z.profile_value[k - 1] + 2.0 * z.profile_value[k] + z.profile_value[k + 1]);
  // Peak: the largest value within 3 steps of the line.
  int kp = -1;
  for (std::size_t k = 0; k < np; ++k) {
    if (std::abs(z.profile_d[k]) > 3.0 * m.step + 1e-12 * m.step) continue;
    if (kp < 0 || sm[k] > sm[static_cast<std::size_t>(kp)]) kp = static_cast<int>(k);
  }
  if (kp < 0) throw std::invalid_argument("shear zone: no profile across the band");
  z.peak_d = z.profile_d[static_cast<std::size_t>(kp)];
  z.peak_value = z.profile_value[static_cast<std::size_t>(kp)];
  z.lower_d = inflection(z.profile_d, sm, kp, -1);
  z.upper_d = inflection(z.profile_d, sm, kp, 1);
  z.thickness = z.upper_d - z.lower_d;
  return z;
}

double profile_inflection(const std::vector<double>& v, int from, int step, double bin) {
  const int n = static_cast<int>(v.size());
  if (n < 3) return NAN;
  auto d2 = [&](int i) { return v[i - 1] - 2 * v[i] + v[i + 1]; };
  int i = std::clamp(from, 1, n - 2);
  for (; i + step >= 1 && i + step <= n - 2; i += step) {
    const double a = d2(i), b = d2(i + step);
    if ((a < 0 && b >= 0) || (a > 0 && b <= 0)) {
      const double t = a / (a - b);
      return (i + step * t) * bin;
    }
  }
  return NAN;
}

}  // namespace gs::analysis
