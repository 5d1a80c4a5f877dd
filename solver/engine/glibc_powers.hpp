// x^0.5 and x^1.5 exactly as glibc's pow(x, 0.5) and pow(x, 1.5) return them, without calling
// pow where the answer is certain.
//
// YADE's Hertz–Mindlin law (Law2_ScGeom_MindlinPhys_Mindlin; seed 004 eq 3.2's Hertzian
// counterpart, docs/physics.md) calls pow(uN, 1.5) and pow(uN, 0.5) for every contact, and the
// contact law here matches YADE to the bit, so it must return glibc's values. glibc's pow (since
// 2.28, from Arm's optimized-routines) is not correctly rounded: its worst-case error is 0.54 ulp
// of the exact result (the bound stated in its source), so where the exact value lies near the
// midpoint of two doubles it may return either, and then only a call can tell (sqrt(x), correctly
// rounded, differs from pow(x, 0.5) for about 0.1 % of doubles).
//
// Everywhere else the answer is certain: if the exact value t lies within 0.45 ulp of a double q,
// every other double is more than 0.55 ulp from t, so a result within 0.54 ulp of t is q (this
// holds for any pow within 0.55 ulp: glibc before 2.28 was correctly rounded, musl uses Arm's). The
// functions below find q and |t - q| from a correctly rounded sqrt and exact error terms (fma),
// and report whether the answer is certain; the caller calls pow for the other lanes (about 10 %).
// Outside [2^-900, 2^900], at zero, for negative or NaN x, and where q or its neighbour crosses a
// power of two (where the ulp changes), they report "uncertain".
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

namespace gs::solver {

struct CertainPower {
  double value;  // glibc's pow(x, y) where `certain`
  bool certain;
};

namespace glibc_powers_detail {
constexpr std::uint64_t kExponent = 0x7ff0000000000000ull;
constexpr std::uint64_t kMantissa = 0x000fffffffffffffull;
// The ulp of a positive normal double.
[[gnu::always_inline]] inline double ulp_of(double q) {
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(q) & kExponent) * 0x1p-52;
}
[[gnu::always_inline]] inline bool in_range(double x) {
  return x >= 0x1p-900 && x <= 0x1p900;
}
// Not a power of two (its lower neighbour is then one ulp below it, like the upper one).
[[gnu::always_inline]] inline bool off_binade_edge(double q) {
  return (std::bit_cast<std::uint64_t>(q) & kMantissa) != 0;
}
}  // namespace glibc_powers_detail

// pow(x, 0.5): s = sqrt(x) rounded; the exact root is s - (s*s - x)/(2s) to 2^-106 relative.
[[gnu::always_inline]] inline CertainPower glibc_pow_half(double x) {
  using namespace glibc_powers_detail;
  const double s = std::sqrt(x);
  const double r = std::fma(s, s, -x);  // s*s - x, exact
  const double off = r / (2 * s);       // s - t
  const bool certain = in_range(x) & off_binade_edge(s) & (std::fabs(off) < 0.45 * ulp_of(s));
  return {s, certain};
}

// pow(x, 1.5) = x * sqrt(x): t = p + e - x*(s - sqrt(x)) with p = x*s rounded and e its exact
// error, so t - p is known to about 2^-50 ulp; q is p or a neighbour in p's binade.
[[gnu::always_inline]] inline CertainPower glibc_pow_three_halves(double x) {
  using namespace glibc_powers_detail;
  const double s = std::sqrt(x);
  const double r = std::fma(s, s, -x);
  const double off = r / (2 * s);
  const double p = x * s;
  const double e = std::fma(x, s, -p);  // x*s - p, exact
  const double c = e - x * off;         // t - p
  const double u = ulp_of(p);
  const double k = std::nearbyint(c / u);  // (-1, 0 or 1 where certain)
  const double q = p + k * u;              // (exact in p's binade)
  const bool certain = in_range(x) & (std::fabs(k) <= 1) & (std::fabs(c - k * u) < 0.45 * u) &
                       (ulp_of(q) == u) & off_binade_edge(q);
  return {q, certain};
}

}  // namespace gs::solver
