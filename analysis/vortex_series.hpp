// Vortex counts over a trajectory and their Fourier spectrum against strain (seed 000 §6,
// Figs 16–18: number of right/left-handed vortices vs the vertical strain ε1, and the period
// T = 1/f of that signal in units of strain).
#pragma once

#include <vector>

namespace gs::analysis {

struct AmplitudeSpectrum {
  double spacing = 0.0;           // uniform sample spacing used (units of x)
  std::vector<double> frequency;  // k / (n spacing), k = 1 .. n/2 (cycles per unit of x)
  std::vector<double> period;     // 1 / frequency (units of x, e.g. strain)
  std::vector<double> amplitude;  // single-sided amplitude of the mean-free signal
  double dominant_period = 0.0;   // period of the largest amplitude (0 if all zero)
};

/// One-sided amplitude spectrum of y(x): the samples are first interpolated linearly onto n
/// equally spaced x over [x_0, x_{n-1}] (DEM frames are nearly, not exactly, uniform in strain),
/// the mean is removed, and |Y_k| 2/n is reported (so a sine of amplitude A on a whole number of
/// periods gives A at its frequency). Throws std::invalid_argument for fewer than 4 samples,
/// sizes that differ, non-finite values, or x not strictly increasing.
AmplitudeSpectrum amplitude_spectrum(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace gs::analysis
