#include "specimen_generation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace gs::solver {

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

namespace {

std::string num(double x) {
  std::ostringstream o;
  o.precision(10);
  o << x;
  return o.str();
}

void check_range(const SizeSpec& s) {
  if (!(s.dmin_m > 0) || !(s.dmax_m >= s.dmin_m))
    throw std::invalid_argument("size distribution needs 0 < dmin <= dmax");
  if (s.mass_exponent < 1)
    throw std::invalid_argument(
        "size distribution: mass exponent k (mass ~ d^k) must be >= 1, not " +
        std::to_string(s.mass_exponent));
}

/// Bisection of an increasing function g on [lo, hi] (g(lo) <= 0 <= g(hi)) until the bracket
/// cannot shrink in doubles: the crossing to the last bit.
template <class G>
double bisect_increasing(G g, double lo, double hi) {
  for (int it = 0; it < 2200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi)) break;
    (g(mid) < 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// erfcx(x) = exp(x²)·erfc(x) for x >= 0: x² split exactly (fma) below 26, the asymptotic series
/// (8 terms, error < 1e-17 relative) above, where erfc underflows.
double erfcx(double x) {
  if (x < 26) {
    const double hi = x * x, lo = std::fma(x, x, -hi);
    return std::exp(hi) * (1 + lo) * std::erfc(x);
  }
  const double q = 1 / (2 * x * x);
  double term = 1, sum = 1;
  for (int n = 1; n <= 8; ++n) {
    term *= -(2 * n - 1) * q;
    sum += term;
  }
  return sum / (x * std::sqrt(M_PI));
}

/// A normal distribution N(mu, sigma²) truncated to [dmin, dmax]: its CDF without underflow
/// wherever mu lies (tails through erfcx, with the Gaussian factor common to numerator and
/// denominator cancelled analytically).
struct TruncatedNormal {
  double dmin, dmax, mu, sigma;

  /// 2·exp(u_a²)·(Φ(z_b) − Φ(z_a)) for mu <= a <= b, u = (d − mu)/(σ√2).
  double scaled_tail(double a, double b, double m) const {
    const double s2 = sigma * M_SQRT2;
    const double gap = (b - a) * (b + a - 2 * m) / (2 * sigma * sigma);  // u_b² − u_a² >= 0
    return erfcx((a - m) / s2) - std::exp(-gap) * erfcx((b - m) / s2);
  }
  /// Φ(z_b) − Φ(z_a) by the form without cancellation for the signs of z_a <= z_b.
  double mass(double a, double b) const {
    const double s2 = sigma * M_SQRT2, ua = (a - mu) / s2, ub = (b - mu) / s2;
    if (ua >= 0) return 0.5 * (std::erfc(ua) - std::erfc(ub));
    if (ub <= 0) return 0.5 * (std::erfc(-ub) - std::erfc(-ua));
    return 0.5 * (std::erf(ub) - std::erf(ua));
  }
  double finer(double d) const {
    if (d <= dmin) return 0;
    if (d >= dmax) return 1;
    if (mu <= dmin) return scaled_tail(dmin, d, mu) / scaled_tail(dmin, dmax, mu);
    if (mu >= dmax) {  // mirror image: d → −d, mu → −mu
      const double gap = (d - dmax) * (d + dmax - 2 * mu) / (2 * sigma * sigma);
      return std::exp(-gap) * scaled_tail(-d, -dmin, -mu) / scaled_tail(-dmax, -dmin, -mu);
    }
    return mass(dmin, d) / mass(dmin, dmax);
  }
  double quantile(double p) const {
    if (p <= 0) return dmin;
    if (p >= 1) return dmax;
    return bisect_increasing([&](double d) { return finer(d) - p; }, dmin, dmax);
  }
};

/// The limit σ → ∞ of the truncated normal with D50 held: mass density ∝ exp(λ·(d − dmin)).
struct ExponentialGrading {
  double dmin, length, lambda;

  double finer(double x) const {  // x = d − dmin in [0, length]
    if (lambda > 0)
      return std::exp(lambda * (x - length)) * std::expm1(-lambda * x) /
             std::expm1(-lambda * length);
    if (lambda < 0) return std::expm1(lambda * x) / std::expm1(lambda * length);
    return x / length;
  }
  double quantile(double p) const {
    if (lambda > 0)  // length + log(p + (1 − p)·exp(−λ·length))/λ, without cancellation
      return dmin + length + std::log1p((1 - p) * std::expm1(-lambda * length)) / lambda;
    if (lambda < 0) return dmin + std::log1p(p * std::expm1(lambda * length)) / lambda;
    return dmin + p * length;
  }
};

/// D60/D10 of the σ → ∞ limit with the given D50: the supremum a truncated normal reaches.
double uniformity_limit(double dmin, double dmax, double d50) {
  const double length = dmax - dmin, x50 = d50 - dmin;
  auto median_excess = [&](double lambda) {  // decreasing in lambda
    return ExponentialGrading{dmin, length, lambda}.finer(x50) - 0.5;
  };
  double lo = -1 / length, hi = 1 / length;
  for (int it = 0; it < 1100 && median_excess(lo) < 0; ++it) lo *= 2;
  for (int it = 0; it < 1100 && median_excess(hi) > 0; ++it) hi *= 2;
  const double lambda = bisect_increasing([&](double l) { return -median_excess(l); }, lo, hi);
  const ExponentialGrading e{dmin, length, lambda};
  return e.quantile(0.6) / e.quantile(0.1);
}

/// The mean that puts the median of the truncated normal at d50 for this σ (F(d50) decreases
/// as mu grows, from 1 at −∞ to 0 at +∞).
double median_mean(double dmin, double dmax, double d50, double sigma) {
  auto excess = [&](double mu) { return TruncatedNormal{dmin, dmax, mu, sigma}.finer(d50) - 0.5; };
  double lo = d50, hi = d50, step = (dmax - dmin) + sigma;
  for (int it = 0; it < 1100 && excess(lo) < 0; ++it, step *= 2) lo = d50 - step;
  step = (dmax - dmin) + sigma;
  for (int it = 0; it < 1100 && excess(hi) > 0; ++it, step *= 2) hi = d50 + step;
  return bisect_increasing([&](double mu) { return -excess(mu); }, lo, hi);
}

TruncatedNormal graded_curve(const SizeSpec& s) {
  if (!(s.fit_sigma_m > 0) || !std::isfinite(s.fit_mu_m))
    throw std::invalid_argument("Graded size distribution not fitted: call fit_graded() first");
  return {s.dmin_m, s.dmax_m, s.fit_mu_m, s.fit_sigma_m};
}

bool table_is_current(const SizeSpec& s) {
  const GradedTable* t = s.graded_table.get();
  return t && t->dmin_m == s.dmin_m && t->dmax_m == s.dmax_m && t->d50_m == s.d50_m &&
         t->uniformity == s.uniformity && t->mu_m == s.fit_mu_m && t->sigma_m == s.fit_sigma_m &&
         t->mass_exponent == s.mass_exponent;
}

/// Number CDF n(d) ∝ f_mass(d)/dᵏ tabulated on 4096 equal intervals of the range holding all but
/// 1e-15 of the mass (5-point Gauss–Legendre per interval, the Gaussian scaled by its maximum in
/// the range so that no tail underflows).
std::shared_ptr<const GradedTable> tabulate(const SizeSpec& s) {
  constexpr int kIntervals = 4096;
  static constexpr std::array<double, 5> node = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                                 0.5384693101056831, 0.9061798459386640};
  static constexpr std::array<double, 5> weight = {0.2369268850561891, 0.4786286704993665,
                                                   0.5688888888888889, 0.4786286704993665,
                                                   0.2369268850561891};
  const TruncatedNormal c = graded_curve(s);
  auto t = std::make_shared<GradedTable>();
  t->dmin_m = s.dmin_m;
  t->dmax_m = s.dmax_m;
  t->d50_m = s.d50_m;
  t->uniformity = s.uniformity;
  t->mu_m = s.fit_mu_m;
  t->sigma_m = s.fit_sigma_m;
  t->mass_exponent = s.mass_exponent;
  t->lo_m = c.quantile(1e-15);
  t->hi_m = c.quantile(1 - 1e-15);
  const double peak = std::clamp(c.mu, t->lo_m, t->hi_m), h = (t->hi_m - t->lo_m) / kIntervals;
  auto density = [&](double d) {
    const double g = std::exp(-(d - peak) * (d + peak - 2 * c.mu) / (2 * c.sigma * c.sigma));
    return g / std::pow(d, s.mass_exponent);
  };
  t->cdf.resize(kIntervals + 1);
  t->cdf[0] = 0;
  for (int i = 0; i < kIntervals; ++i) {
    const double mid = t->lo_m + (i + 0.5) * h;
    double sum = 0;
    for (int q = 0; q < 5; ++q) sum += weight[q] * density(mid + 0.5 * h * node[q]);
    t->cdf[i + 1] = t->cdf[i] + 0.5 * h * sum;
  }
  const double total = t->cdf.back();
  for (auto& x : t->cdf) x /= total;
  t->cdf.back() = 1;
  return t;
}

/// Inverse of the tabulated number CDF, linear within an interval.
double draw_graded(const GradedTable& t, double u) {
  const auto it = std::upper_bound(t.cdf.begin(), t.cdf.end(), u);  // cdf[i] <= u < cdf[i+1]
  const auto i = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(
      it - t.cdf.begin() - 1, 0, static_cast<std::ptrdiff_t>(t.cdf.size()) - 2));
  const double h = (t.hi_m - t.lo_m) / static_cast<double>(t.cdf.size() - 1);
  const double w = (u - t.cdf[i]) / (t.cdf[i + 1] - t.cdf[i]);
  return std::clamp(t.lo_m + (static_cast<double>(i) + w) * h, t.dmin_m, t.dmax_m);
}

/// The spec itself when it can be drawn from, else a fitted copy in `scratch`.
const SizeSpec& drawable(const SizeSpec& s, SizeSpec& scratch) {
  if (s.distribution != SizeDistribution::Graded || table_is_current(s)) return s;
  scratch = s;
  fit_graded(scratch);
  return scratch;
}

}  // namespace

void fit_graded(SizeSpec& s) {
  check_range(s);
  const double dmin = s.dmin_m, dmax = s.dmax_m, d50 = s.d50_m, cu = s.uniformity;
  const std::string what = "Graded size distribution (dmin = " + num(dmin) +
                           " m, dmax = " + num(dmax) + " m, D50 = " + num(d50) +
                           " m, D60/D10 = " + num(cu) + "): ";
  if (!(d50 > dmin && d50 < dmax))
    throw std::invalid_argument(what + "D50 must lie strictly between dmin and dmax");
  if (!(cu > 1)) throw std::invalid_argument(what + "D60/D10 must exceed 1");
  const double limit = uniformity_limit(dmin, dmax, d50);
  auto uniformity_at = [&](double log_sigma) {
    const double sigma = std::exp(log_sigma);
    const TruncatedNormal c{dmin, dmax, median_mean(dmin, dmax, d50, sigma), sigma};
    return c.quantile(0.6) / c.quantile(0.1);
  };
  // σ from 1e-9 to 1e4 times the range: D60/D10 from 1 + O(1e-9) to within O(1e-8) of the
  // σ → ∞ limit.
  const double length = dmax - dmin, lo = std::log(1e-9 * length), hi = std::log(1e4 * length);
  const double cu_lo = uniformity_at(lo), cu_hi = uniformity_at(hi);
  if (!(cu < limit) || !(cu > cu_lo && cu < cu_hi))
    throw std::invalid_argument(what + "no normal grading curve truncated to [dmin, dmax] " +
                                "reaches it; achievable D60/D10 with this D50: between 1 and " +
                                num(limit) +
                                " (the limit sigma -> infinity, an exponential mass density" +
                                ", uniform by mass when D50 = (dmin + dmax)/2)");
  const double log_sigma =
      bisect_increasing([&](double t) { return uniformity_at(t) - cu; }, lo, hi);
  s.fit_sigma_m = std::exp(log_sigma);
  s.fit_mu_m = median_mean(dmin, dmax, d50, s.fit_sigma_m);
  const TruncatedNormal c{dmin, dmax, s.fit_mu_m, s.fit_sigma_m};
  const double got_d50 = c.quantile(0.5), got_cu = c.quantile(0.6) / c.quantile(0.1);
  if (!(std::abs(got_d50 / d50 - 1) <= 1e-12 && std::abs(got_cu / cu - 1) <= 1e-12))
    throw std::invalid_argument(what + "fit did not converge (D50 = " + num(got_d50) +
                                " m, D60/D10 = " + num(got_cu) + ")");
  s.graded_table = tabulate(s);
}

void check_piecewise(const SizeSpec& s) {
  const auto& g = s.grading;
  if (g.size() < 2) throw std::invalid_argument("Piecewise grading needs at least 2 points");
  if (g.front().first != s.dmin_m || g.front().second != 0 || g.back().first != s.dmax_m ||
      g.back().second != 1)
    throw std::invalid_argument("Piecewise grading must run from (dmin, 0) to (dmax, 1)");
  for (std::size_t i = 1; i < g.size(); ++i)
    if (!(g[i].first > g[i - 1].first) || !(g[i].second >= g[i - 1].second))
      throw std::invalid_argument(
          "Piecewise grading: diameters must increase and fractions not decrease (point " +
          std::to_string(i) + ")");
}

namespace {
/// ∫ x⁻ᵏ dx from a to d (the number of grains of a unit mass density, up to a constant).
double inverse_power_integral(int k, double a, double d) {
  if (k == 1) return std::log(d / a);
  return (std::pow(a, 1.0 - k) - std::pow(d, 1.0 - k)) / (k - 1.0);
}
/// The d in [a, b] at which inverse_power_integral(k, a, d) = t·inverse_power_integral(k, a, b).
double inverse_power_quantile(int k, double a, double b, double t) {
  if (k == 1) return std::clamp(a * std::exp(t * std::log(b / a)), a, b);
  const double e = 1.0 - k, pa = std::pow(a, e), pb = std::pow(b, e);
  return std::clamp(std::pow(pa - t * (pa - pb), 1 / e), a, b);
}
double draw_piecewise(const SizeSpec& s, double u) {
  check_piecewise(s);
  const auto& g = s.grading;
  std::vector<double> w(g.size() - 1);  // number share of each segment
  double total = 0;
  for (std::size_t i = 0; i + 1 < g.size(); ++i) {
    const double a = g[i].first, b = g[i + 1].first, dm = g[i + 1].second - g[i].second;
    w[i] = dm / (b - a) * inverse_power_integral(s.mass_exponent, a, b);
    total += w[i];
  }
  double acc = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (w[i] <= 0) continue;
    if (u * total < acc + w[i] || i + 1 == w.size())
      return inverse_power_quantile(s.mass_exponent, g[i].first, g[i + 1].first,
                                    std::clamp((u * total - acc) / w[i], 0.0, 1.0));
    acc += w[i];
  }
  return s.dmax_m;
}
}  // namespace

double mass_fraction_finer(const SizeSpec& s, double d) {
  check_range(s);
  if (d <= s.dmin_m) return 0;
  if (d >= s.dmax_m) return 1;
  switch (s.distribution) {
    case SizeDistribution::Uniform: {  // n(d) = const: mass finer ∝ d^(k+1) − dmin^(k+1)
      const int e = s.mass_exponent + 1;
      const double a = std::pow(s.dmin_m, e);
      return (std::pow(d, e) - a) / (std::pow(s.dmax_m, e) - a);
    }
    case SizeDistribution::Linear:
      return (d - s.dmin_m) / (s.dmax_m - s.dmin_m);
    case SizeDistribution::Graded:
      return graded_curve(s).finer(d);
    case SizeDistribution::Piecewise: {
      check_piecewise(s);
      const auto& g = s.grading;
      for (std::size_t i = 1; i < g.size(); ++i)
        if (d <= g[i].first)
          return g[i - 1].second + (g[i].second - g[i - 1].second) * (d - g[i - 1].first) /
                                       (g[i].first - g[i - 1].first);
      return 1;
    }
  }
  throw std::invalid_argument("unknown size distribution");
}

double mass_quantile(const SizeSpec& s, double p) {
  check_range(s);
  if (!(p >= 0 && p <= 1))
    throw std::invalid_argument("mass quantile: fraction " + num(p) + " outside [0, 1]");
  switch (s.distribution) {
    case SizeDistribution::Uniform: {
      const double e = s.mass_exponent + 1, a = std::pow(s.dmin_m, e);
      return std::clamp(std::pow(a + p * (std::pow(s.dmax_m, e) - a), 1 / e), s.dmin_m, s.dmax_m);
    }
    case SizeDistribution::Linear:
      return s.dmin_m + p * (s.dmax_m - s.dmin_m);
    case SizeDistribution::Graded:
      if (s.dmax_m == s.dmin_m) return s.dmin_m;
      return graded_curve(s).quantile(p);
    case SizeDistribution::Piecewise: {
      check_piecewise(s);
      const auto& g = s.grading;
      for (std::size_t i = 1; i < g.size(); ++i)
        if (p <= g[i].second && g[i].second > g[i - 1].second)
          return g[i - 1].first + (g[i].first - g[i - 1].first) * (p - g[i - 1].second) /
                                      (g[i].second - g[i - 1].second);
      return s.dmax_m;
    }
  }
  throw std::invalid_argument("unknown size distribution");
}

double draw_diameter(const SizeSpec& s, std::mt19937_64& rng) {
  return diameter_at(s, uniform01(rng));
}

double diameter_at(const SizeSpec& s, double u) {
  check_range(s);
  if (s.distribution == SizeDistribution::Graded && !table_is_current(s))
    throw std::invalid_argument(
        "Graded size distribution: no number table for the spec's current parameters (call "
        "fit_graded() after setting them)");
  if (!(u >= 0 && u <= 1)) throw std::invalid_argument("diameter_at: u outside [0, 1]");
  switch (s.distribution) {
    case SizeDistribution::Uniform:
      return s.dmin_m + u * (s.dmax_m - s.dmin_m);
    case SizeDistribution::Graded:
      return draw_graded(*s.graded_table, u);
    case SizeDistribution::Piecewise:
      return draw_piecewise(s, u);
    case SizeDistribution::Linear:
      break;
  }
  // Straight grading curve by mass with mass ∝ dᵏ: number density ∝ d⁻ᵏ on [dmin, dmax], one
  // segment of a broken line.
  if (s.mass_exponent == 3) {
    // F(d) = (dmin⁻² − d⁻²)/(dmin⁻² − dmax⁻²) (this form since before k: the same draws).
    const double a = 1 / (s.dmin_m * s.dmin_m), b = 1 / (s.dmax_m * s.dmax_m);
    return 1 / std::sqrt(a - u * (a - b));
  }
  return inverse_power_quantile(s.mass_exponent, s.dmin_m, s.dmax_m, u);
}

std::vector<double> draw_diameters(const SizeSpec& size, double solid_volume_m3,
                                   std::mt19937_64& rng) {
  if (!(solid_volume_m3 > 0)) throw std::invalid_argument("solid volume must be positive");
  const double vmin = M_PI / 6 * std::pow(size.dmin_m, 3);
  if (solid_volume_m3 / vmin > 2e7)
    throw std::invalid_argument("more than 20 million particles requested");
  SizeSpec scratch;
  const SizeSpec& s = drawable(size, scratch);
  std::vector<double> d;
  double v = 0;
  while (v < solid_volume_m3) {
    d.push_back(draw_diameter(s, rng));
    v += M_PI / 6 * std::pow(d.back(), 3);
  }
  std::sort(d.begin(), d.end(), std::greater<>());
  return d;
}

std::vector<double> draw_diameter_count(const SizeSpec& size, std::size_t n, std::mt19937_64& rng) {
  SizeSpec scratch;
  const SizeSpec& s = drawable(size, scratch);
  // Stratified by number: the i-th diameter from the quantile (i + U_i)/n, so that the sample's
  // grading follows the curve to within one particle per size class — a plain random sample of
  // 1 002 disks misses a 10 % mass class by ±2 % and can move D50 or D60 across a gap.
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i)
    d[i] = diameter_at(s, (static_cast<double>(i) + uniform01(rng)) / static_cast<double>(n));
  std::sort(d.begin(), d.end(), std::greater<>());
  return d;
}

std::vector<Particle> random_sequential_packing(const std::vector<double>& diameters,
                                                const Eigen::Vector3d& lo,
                                                const Eigen::Vector3d& hi, std::mt19937_64& rng,
                                                int max_attempts) {
  std::vector<Particle> out;
  if (diameters.empty()) return out;
  const double dmax = *std::max_element(diameters.begin(), diameters.end());
  if (((hi - lo).array() <= dmax).any())
    throw std::invalid_argument("generation box is smaller than the largest sphere");
  // Hash grid of cell size dmax: a sphere can only overlap spheres in the 27 cells around it.
  const double cell = dmax;
  Eigen::Array3i dims;
  for (int k = 0; k < 3; ++k)
    dims[k] = std::max(1, static_cast<int>(std::floor((hi[k] - lo[k]) / cell)));
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> grid;
  auto cell_of = [&](const Eigen::Vector3d& x) {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp(static_cast<int>((x[k] - lo[k]) / cell), 0, dims[k] - 1);
    return c;
  };
  auto key = [&](int x, int y, int z) {
    return (static_cast<std::int64_t>(z) * dims[1] + y) * dims[0] + x;
  };
  out.reserve(diameters.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) {
    const double r = 0.5 * diameters[i];
    bool placed = false;
    for (int attempt = 0; attempt < max_attempts && !placed; ++attempt) {
      Eigen::Vector3d x;
      for (int k = 0; k < 3; ++k) x[k] = lo[k] + r + uniform01(rng) * (hi[k] - lo[k] - 2 * r);
      const auto c = cell_of(x);
      bool free = true;
      for (int dz = -1; dz <= 1 && free; ++dz)
        for (int dy = -1; dy <= 1 && free; ++dy)
          for (int dx = -1; dx <= 1 && free; ++dx) {
            const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
            if (cx < 0 || cy < 0 || cz < 0 || cx >= dims[0] || cy >= dims[1] || cz >= dims[2])
              continue;
            const auto it = grid.find(key(cx, cy, cz));
            if (it == grid.end()) continue;
            for (const auto j : it->second) {
              const double reach = r + out[j].radius;
              if ((out[j].position - x).squaredNorm() < reach * reach) {
                free = false;
                break;
              }
            }
          }
      if (!free) continue;
      Particle p;
      p.id = static_cast<std::int64_t>(i);
      p.position = x;
      p.radius = r;
      grid[key(c[0], c[1], c[2])].push_back(static_cast<std::uint32_t>(out.size()));
      out.push_back(p);
      placed = true;
    }
    if (!placed)
      throw std::invalid_argument("random packing: sphere " + std::to_string(i) + " of " +
                                  std::to_string(diameters.size()) + " found no free place after " +
                                  std::to_string(max_attempts) +
                                  " draws (generation box too small for the solid volume)");
  }
  return out;
}

namespace {

/// Minimum-image component of a difference of two coordinates in [0, l): exact (Sterbenz).
double minimum_image(double dx, double l) {
  if (dx > 0.5 * l) return dx - l;
  if (dx < -0.5 * l) return dx + l;
  return dx;
}

}  // namespace

std::vector<Particle> random_disk_packing_periodic(const std::vector<double>& diameters, double lx,
                                                   double ly, double z, std::mt19937_64& rng,
                                                   int max_attempts) {
  std::vector<Particle> out;
  if (diameters.empty()) return out;
  for (std::size_t i = 0; i < diameters.size(); ++i)
    if (!(diameters[i] > 0) || !std::isfinite(diameters[i]))
      throw std::invalid_argument("periodic disk packing: disk " + std::to_string(i) +
                                  " has diameter " + num(diameters[i]));
  const double dmax = *std::max_element(diameters.begin(), diameters.end());
  if (!(lx >= 2 * dmax) || !(ly >= 2 * dmax))
    throw std::invalid_argument("periodic disk packing: cell " + num(lx) + " m x " + num(ly) +
                                " m is smaller than twice the largest disk (" + num(dmax) +
                                " m) per side");
  // Hash grid of cells at least dmax wide (2 to 1e6 per side): a disk can only overlap disks in the
  // 9 cells around it, counted once each when a side has only 2 cells.
  const int nx = static_cast<int>(std::min(std::floor(lx / dmax), 1e6)),
            ny = static_cast<int>(std::min(std::floor(ly / dmax), 1e6));
  const double cx = lx / nx, cy = ly / ny;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> grid;
  out.reserve(diameters.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) {
    const double r = 0.5 * diameters[i];
    bool placed = false;
    for (int attempt = 0; attempt < max_attempts && !placed; ++attempt) {
      double x = uniform01(rng) * lx, y = uniform01(rng) * ly;
      if (x >= lx) x -= lx;
      if (y >= ly) y -= ly;
      const int ix = std::min(nx - 1, static_cast<int>(x / cx));
      const int iy = std::min(ny - 1, static_cast<int>(y / cy));
      std::array<std::int64_t, 9> seen{};
      int n_seen = 0;
      bool free = true;
      for (int dy = -1; dy <= 1 && free; ++dy)
        for (int dx = -1; dx <= 1 && free; ++dx) {
          const std::int64_t k =
              static_cast<std::int64_t>((iy + dy + ny) % ny) * nx + (ix + dx + nx) % nx;
          if (std::find(seen.begin(), seen.begin() + n_seen, k) != seen.begin() + n_seen) continue;
          seen[n_seen++] = k;
          const auto it = grid.find(k);
          if (it == grid.end()) continue;
          for (const auto j : it->second) {
            const double ex = minimum_image(out[j].position.x() - x, lx);
            const double ey = minimum_image(out[j].position.y() - y, ly);
            const double reach = r + out[j].radius;
            if (ex * ex + ey * ey < reach * reach) {
              free = false;
              break;
            }
          }
        }
      if (!free) continue;
      Particle p;
      p.id = static_cast<std::int64_t>(i);
      p.position = Eigen::Vector3d(x, y, z);
      p.radius = r;
      grid[static_cast<std::int64_t>(iy) * nx + ix].push_back(
          static_cast<std::uint32_t>(out.size()));
      out.push_back(p);
      placed = true;
    }
    if (!placed)
      throw std::invalid_argument("periodic disk packing: disk " + std::to_string(i) + " of " +
                                  std::to_string(diameters.size()) + " found no free place after " +
                                  std::to_string(max_attempts) +
                                  " draws (cell too small for the disks' area)");
  }
  return out;
}

double void_ratio(const std::vector<double>& radii, double box_volume_m3) {
  double vs = 0;
  for (double r : radii) vs += 4.0 / 3.0 * M_PI * r * r * r;
  if (!(vs > 0)) return std::numeric_limits<double>::quiet_NaN();
  return box_volume_m3 / vs - 1;
}

double disk_void_ratio(const std::vector<double>& radii, double area_m2) {
  double as = 0;
  for (double r : radii) as += M_PI * r * r;
  if (!(as > 0)) return std::numeric_limits<double>::quiet_NaN();
  return area_m2 / as - 1;
}

}  // namespace gs::solver
