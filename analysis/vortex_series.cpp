// Fourier spectrum of a vortex-count series (seed 000 Figs 17–18).
#include "vortex_series.hpp"

#include <unsupported/Eigen/FFT>

#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

namespace gs::analysis {

AmplitudeSpectrum amplitude_spectrum(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 4 || y.size() != n) {
    throw std::invalid_argument("spectrum needs at least 4 samples and one value per sample (" +
                                std::to_string(n) + ", " + std::to_string(y.size()) + ")");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      throw std::invalid_argument("non-finite sample (" + std::to_string(i) + ")");
    }
    if (i > 0 && !(x[i] > x[i - 1])) {
      throw std::invalid_argument("spectrum abscissae must increase strictly (sample " +
                                  std::to_string(i) + ")");
    }
  }
  AmplitudeSpectrum s;
  s.spacing = (x[n - 1] - x[0]) / static_cast<double>(n - 1);
  std::vector<double> u(n);
  std::size_t j = 0;
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double xi = i + 1 == n ? x[n - 1] : x[0] + static_cast<double>(i) * s.spacing;
    while (j + 2 < n && x[j + 1] < xi) ++j;
    const double t = (xi - x[j]) / (x[j + 1] - x[j]);
    u[i] = (1.0 - t) * y[j] + t * y[j + 1];
    mean += u[i];
  }
  mean /= static_cast<double>(n);
  for (auto& v : u) v -= mean;
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> f;
  fft.fwd(f, u);
  double best = 0.0;
  for (std::size_t k = 1; k <= n / 2; ++k) {
    const double freq = static_cast<double>(k) / (static_cast<double>(n) * s.spacing);
    // One-sided: double every bin but the Nyquist one (n even).
    const double scale = (2 * k == n) ? 1.0 : 2.0;
    const double a = scale * std::abs(f[k]) / static_cast<double>(n);
    s.frequency.push_back(freq);
    s.period.push_back(1.0 / freq);
    s.amplitude.push_back(a);
    if (a > best) {
      best = a;
      s.dominant_period = 1.0 / freq;
    }
  }
  return s;
}

}  // namespace gs::analysis
