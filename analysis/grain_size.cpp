#include "grain_size.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "text_parse.hpp"

namespace gs::analysis {

double diameter_percentile(std::vector<double> radii, double fraction, int exponent) {
  if (radii.empty()) throw std::invalid_argument("diameter_percentile: no particles");
  if (!(fraction >= 0 && fraction <= 1))
    throw std::invalid_argument("diameter_percentile: fraction outside [0, 1]");
  std::sort(radii.begin(), radii.end());
  // Cumulative volume passing at each distinct diameter, counting half of that size class's
  // own volume (mid-point rule), so a monodisperse sample returns its diameter for every fraction.
  if (exponent != 2 && exponent != 3)
    throw std::invalid_argument("diameter_percentile: weight exponent must be 2 or 3");
  const auto weight = [exponent](double r) { return exponent == 3 ? r * r * r : r * r; };
  double total = 0;
  for (double r : radii) total += weight(r);
  double below = 0, prev_d = 2 * radii.front(), prev_c = 0;
  for (std::size_t i = 0; i < radii.size();) {
    std::size_t j = i;
    double v = 0;
    for (; j < radii.size() && radii[j] == radii[i]; ++j) v += weight(radii[j]);
    const double c = (below + 0.5 * v) / total;
    const double d = 2 * radii[i];
    if (fraction <= c) {
      if (i == 0 || c == prev_c) return d;
      return prev_d + (d - prev_d) * (fraction - prev_c) / (c - prev_c);
    }
    below += v;
    prev_d = d;
    prev_c = c;
    i = j;
  }
  return 2 * radii.back();
}

double diameter_percentile(const Frame& frame, double fraction) {
  std::vector<double> r;
  r.reserve(frame.particles.size());
  for (const auto& p : frame.particles) r.push_back(p.radius);
  return diameter_percentile(std::move(r), fraction, frame.two_d ? 2 : 3);
}

namespace {

// A positive finite number that is the whole of `text` (a trailing TOML comment allowed).
std::optional<double> positive_number(std::string_view text) {
  const std::string s(text::trim(text.substr(0, text.find('#'))));
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v) || !(v > 0)) return std::nullopt;
  return v;
}

}  // namespace

std::optional<double> recorded_d50(
    const std::vector<std::pair<std::string, std::string>>& parameters) {
  for (const auto& [key, value] : parameters)
    if (key == "scene.d50_m") return positive_number(value);
  // Older runs: the scene file as the run recorded it (one `key = value` a line, tables as
  // `[name]`, the way the scene reader writes it back).
  for (const auto& [key, value] : parameters) {
    if (key != "scene.toml") continue;
    std::string_view table;
    for (const std::string_view raw : text::split_lines(value)) {
      const std::string_view line = text::trim(raw);
      if (line.size() > 1 && line.front() == '[') {
        table = text::trim(line.substr(1, line.find(']') - 1));
        continue;
      }
      const auto eq = line.find('=');
      if ((table == "silo" || table == "interface_shear") && eq != std::string_view::npos &&
          text::trim(line.substr(0, eq)) == "d50_m")
        return positive_number(line.substr(eq + 1));
    }
  }
  return std::nullopt;
}

}  // namespace gs::analysis
