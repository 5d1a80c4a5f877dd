// Contact rose diagrams (seed 004 Figs 4.11c, 4.24, 5.27); conventions in the header.
#include "contact_rose.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

constexpr double kPi = std::numbers::pi;

void finish(Rose& r, std::size_t nbins, const std::vector<double>& sum_fn,
            const std::vector<double>& sum_fs) {
  const double n = static_cast<double>(r.contacts);
  r.density.resize(nbins);
  r.mean_fn.resize(nbins);
  r.mean_fs.resize(nbins);
  for (std::size_t k = 0; k < nbins; ++k) {
    r.density[k] = n > 0 ? r.count[k] / (n * r.bin_size) : 0.0;
    r.mean_fn[k] =
        r.count[k] > 0 ? sum_fn[k] / r.count[k] : std::numeric_limits<double>::quiet_NaN();
    r.mean_fs[k] =
        r.count[k] > 0 ? sum_fs[k] / r.count[k] : std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace

Rose contact_rose_2d(const std::vector<RoseContact>& contacts, const Eigen::Matrix3d& axes,
                     int bins) {
  if (bins < 2 || bins > 36000) throw std::invalid_argument("rose: bins must be in 2..36000");
  Rose r;
  r.dim = 2;
  const auto nb = static_cast<std::size_t>(bins);
  r.bin_size = 2.0 * kPi / bins;
  r.count.assign(nb, 0.0);
  std::vector<double> sfn(nb, 0.0), sfs(nb, 0.0);
  for (const auto& c : contacts) {
    const double x = axes.row(0).dot(c.normal), y = axes.row(1).dot(c.normal);
    if (!(std::hypot(x, y) > 1e-12 * c.normal.norm())) {
      ++r.skipped;
      continue;
    }
    ++r.contacts;
    const double a = std::atan2(y, x);
    for (const double ang : {a, a + kPi}) {  // n and -n, half each
      double t = std::fmod(ang, 2.0 * kPi);
      if (t < 0) t += 2.0 * kPi;
      const auto k = std::min(nb - 1, static_cast<std::size_t>(t / r.bin_size));
      r.count[k] += 0.5;
      sfn[k] += 0.5 * c.fn;
      sfs[k] += 0.5 * c.fs;
    }
  }
  for (std::size_t k = 0; k < nb; ++k) r.angle_deg.push_back((k + 0.5) * 360.0 / bins);
  finish(r, nb, sfn, sfs);
  return r;
}

Rose contact_rose_3d(const std::vector<RoseContact>& contacts, const Eigen::Matrix3d& axes,
                     int n_theta, int n_phi) {
  if (n_theta < 1 || n_phi < 1 || n_theta * static_cast<long>(n_phi) > 1000000)
    throw std::invalid_argument("rose: 3D bins must be >= 1 and at most 1e6 in all");
  Rose r;
  r.dim = 3;
  r.n_theta = n_theta;
  r.n_phi = n_phi;
  const auto nb = static_cast<std::size_t>(n_theta) * static_cast<std::size_t>(n_phi);
  r.bin_size = 4.0 * kPi / static_cast<double>(nb);
  r.count.assign(nb, 0.0);
  std::vector<double> sfn(nb, 0.0), sfs(nb, 0.0);
  for (const auto& c : contacts) {
    const Eigen::Vector3d l = axes * c.normal;
    const double len = l.norm();
    if (!(len > 0.0)) {
      ++r.skipped;
      continue;
    }
    ++r.contacts;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d u = sign * l / len;
      const auto band = std::min<std::size_t>(
          static_cast<std::size_t>(n_theta) - 1,
          static_cast<std::size_t>(std::max(0.0, (1.0 - u.z()) / 2.0 * n_theta)));
      double phi = std::atan2(u.y(), u.x());
      if (phi < 0) phi += 2.0 * kPi;
      const auto col = std::min<std::size_t>(static_cast<std::size_t>(n_phi) - 1,
                                             static_cast<std::size_t>(phi / (2.0 * kPi) * n_phi));
      const std::size_t k = band * static_cast<std::size_t>(n_phi) + col;
      r.count[k] += 0.5;
      sfn[k] += 0.5 * c.fn;
      sfs[k] += 0.5 * c.fs;
    }
  }
  for (int b = 0; b < n_theta; ++b)
    for (int p = 0; p < n_phi; ++p) {
      const double z = 1.0 - 2.0 * (b + 0.5) / n_theta;
      const double phi = 2.0 * kPi * (p + 0.5) / n_phi, s = std::sqrt(1.0 - z * z);
      r.direction.push_back(axes.transpose() *
                            Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), z));
    }
  finish(r, nb, sfn, sfs);
  return r;
}

}  // namespace gs::analysis
