// Vortex counts over a trajectory (see vortex_count_series.hpp).
#include "vortex_count_series.hpp"

#include <algorithm>
#include <functional>
#include <map>

#include "errors.hpp"
#include "frame_motion.hpp"

namespace gs::analysis {

VortexCountSeries vortex_count_series(
    const std::string& file, long n, const std::function<Frame(long)>& read,
    const VortexSeriesSpec& a, const std::function<void(const VortexSeriesStep&)>& progress) {
  if (a.every < 1) throw InputError(file, "--every must be >= 1", std::to_string(a.every));
  VortexCountSeries s;
  s.stride = a.stride > 0 ? a.stride : a.every;
  const long last = a.last.value_or(n - 1);
  if (a.from < 0 || a.from >= n)
    throw InputError(file, "--from out of range 0.." + std::to_string(n - 1),
                     std::to_string(a.from));
  if (last < 0 || last >= n)
    throw InputError(file, "--last out of range 0.." + std::to_string(n - 1), std::to_string(last));
  if (a.from + a.every > last)
    throw InputError(
        file, "no frame pair: --from + --every beyond the last frame " + std::to_string(last),
        std::to_string(a.from + a.every));
  int axis = -1;
  if (!a.strain_axis.empty()) {
    if (a.strain_axis != "x" && a.strain_axis != "y" && a.strain_axis != "z")
      throw InputError(file, "--strain-axis must be x, y or z", a.strain_axis);
    axis = a.strain_axis[0] - 'x';
  }
  std::map<long, Frame> cache;  // frames still needed (reference and target of the increment)
  const auto frame = [&](long i) -> const Frame& {
    auto it = cache.find(i);
    if (it == cache.end()) it = cache.emplace(i, read(i)).first;
    return it->second;
  };
  const Frame& first = frame(a.from);
  if (axis < 0) axis = first.two_d ? 1 : 2;
  s.strain_axis = static_cast<char>('x' + axis);
  s.dim = first.two_d || a.field.projected() ? 2 : 3;
  const auto height = [&](const Frame& fr) {
    const auto [lo, hi] = particle_bounds(fr);
    return hi[axis] - lo[axis];
  };
  const double h0 = height(first);
  if (!(h0 > 0.0)) throw InputError(file, "specimen has zero extent along the strain axis");
  for (long k = a.from; k + a.every <= last; k += s.stride) {
    cache.erase(cache.begin(), cache.lower_bound(k));
    const Frame& ref = frame(k);
    const double eps = (h0 - height(ref)) / h0;  // compression positive (seed 000: ε1 = u1/h)
    const FrameMotion m = motion_between(ref, frame(k + a.every), file);
    const VortexField f = vortex_field(m, a.field, file);
    const VortexAnalysis r = analyze_field(f, vortex_analysis_options(a.field, f, file), file);
    const auto c = count_extrema(r.extrema, true);
    const auto all = count_extrema(r.extrema, false);
    for (std::size_t q = 0; q < 4; ++q) s.all[q].push_back(static_cast<std::int32_t>(all[q]));
    s.frame_from.push_back(k);
    s.frame_to.push_back(k + a.every);
    s.time.push_back(ref.time);
    s.strain.push_back(eps);
    s.right.push_back(static_cast<std::int32_t>(c[0]));
    s.left.push_back(static_cast<std::int32_t>(c[1]));
    s.sources.push_back(static_cast<std::int32_t>(c[2]));
    s.sinks.push_back(static_cast<std::int32_t>(c[3]));
    s.tubes.push_back(static_cast<std::int32_t>(count_significant_tubes(r.tubes, r.extrema)));
    if (progress) {
      progress({k, k + a.every, eps, c,
                r.seconds_delaunay + r.hhd.report.seconds_assembly + r.hhd.report.seconds_factor +
                    r.hhd.report.seconds_solve + r.seconds_detection + r.seconds_ghosts});
    }
  }
  // Fourier spectrum of the counts against strain (Figs 17-18), when strain increases strictly.
  const bool increasing =
      s.strain.size() >= 4 && std::adjacent_find(s.strain.begin(), s.strain.end(),
                                                 std::greater_equal<double>()) == s.strain.end();
  if (increasing) {
    s.right_spectrum =
        amplitude_spectrum(s.strain, std::vector<double>(s.right.begin(), s.right.end()));
    s.left_spectrum =
        amplitude_spectrum(s.strain, std::vector<double>(s.left.begin(), s.left.end()));
  }
  return s;
}

}  // namespace gs::analysis
