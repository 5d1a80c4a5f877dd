// Vortex counts over a trajectory as `granoscope analyze vortices` computes them (and Python's
// granoscope.vortices): the HHD of every IT-frame displacement increment, counts of right/left-
// handed vortices, sources and sinks against the strain, and their Fourier spectrum (seed 000
// §6, Figs 16-18). One implementation for both faces; frames are read through a callback.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "snapshot.hpp"
#include "vortex_field.hpp"
#include "vortex_series.hpp"

namespace gs::analysis {

struct VortexSeriesSpec {
  long every = 0;            // IT: frames between the two frames of an increment (>= 1)
  long stride = 0;           // frames between successive increments (0: every)
  long from = 0;             // first reference frame
  std::optional<long> last;  // last frame used (default: the last)
  std::string strain_axis;   // x | y | z (default z, y for 2D frames)
  VortexFieldSpec field;
};

/// One increment, as it is done (for progress reports).
struct VortexSeriesStep {
  long from = 0, to = 0;
  double strain = 0.0;
  std::array<std::size_t, 4> counts{};  // significant right, left, sources, sinks
  double seconds = 0.0;
};

struct VortexCountSeries {
  int dim = 3;
  long stride = 0;
  char strain_axis = 'z';
  std::vector<std::int64_t> frame_from, frame_to;
  std::vector<double> time, strain;  // strain: relative shortening along the axis (compression +)
  std::vector<std::int32_t> right, left, sources, sinks, tubes;  // significant ones
  std::array<std::vector<std::int32_t>, 4> all;                  // every strict extremum
  /// Spectra of the right- and left-handed counts against strain (when strain increases
  /// strictly over at least 4 increments).
  std::optional<AmplitudeSpectrum> right_spectrum, left_spectrum;
};

/// The series over `frames` frames, frame(i) reading frame i. Throws InputError (naming file).
VortexCountSeries vortex_count_series(
    const std::string& file, long frames, const std::function<Frame(long)>& frame,
    const VortexSeriesSpec& spec,
    const std::function<void(const VortexSeriesStep&)>& progress = {});

}  // namespace gs::analysis
