#include "silo_report.hpp"

#include "contact_rose.hpp"
#include "love_weber_stress.hpp"
#include "shear_zone.hpp"
#include "sphere_box_volume.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace gs::analysis {

namespace {

// The base planes of the side walls across: the extreme wall points of each side.
std::pair<double, double> wall_bases(const Frame& f, const Eigen::Vector3d& across,
                                     const std::unordered_map<std::int64_t, int>& role) {
  double x0 = HUGE_VAL, x1 = -HUGE_VAL;
  for (const Wall& w : f.walls) {
    const auto it = role.find(w.id);
    if (it == role.end()) continue;
    if (it->second == 1) x0 = std::min(x0, w.a.dot(across));
    if (it->second == 2) x1 = std::max(x1, w.a.dot(across));
  }
  return {x0, x1};
}

void wall_zones(const Frame& f, const SiloReportOptions& o, const Eigen::Vector3d& up,
                const Eigen::Vector3d& across, double bottom, double top, double x0, double x1,
                SiloFrameReport& r) {
  if (!(o.zone_band > 0)) throw std::invalid_argument("zone band must be positive");
  if (!(o.zone_extent_factor > 1) || !std::isfinite(o.zone_extent_factor))
    throw std::invalid_argument("zone extent factor must be above 1");
  if (!(x1 > x0)) return;
  r.zone_height = o.zone_height > 0 ? o.zone_height : 0.5 * (top - bottom);
  const double z = bottom + r.zone_height;
  const Eigen::Vector3d depth_axis = up.cross(across);
  const double width = x1 - x0;
  // The profile's points, from the left wall's base plane: bin centres, or the REV cells'
  // centres (a cell `zone_window` wide moved by `zone_bin`, from flush with one wall to flush
  // with the other).
  const bool window = o.zone_window > 0;
  const double first = window ? 0.5 * o.zone_window : 0.5 * o.zone_bin;
  const int n = window
                    ? static_cast<int>(std::floor((width - o.zone_window) / o.zone_bin + 1e-9)) + 1
                    : std::max(3, static_cast<int>(std::ceil(width / o.zone_bin)));
  if (n < 3) return;  // (a silo narrower than the cell and two steps: no profile)
  std::vector<double> sum(n, 0.0), count(n, 0.0);
  for (const Particle& p : f.particles) {
    if (std::abs(p.position.dot(up) - z) > 0.5 * o.zone_band) continue;
    const double x = p.position.dot(across) - x0;
    const double w = std::abs(p.rotation.dot(depth_axis));
    if (window) {  // (the cells whose span [c − W/2, c + W/2] holds x)
      const double h = 0.5 * o.zone_window;
      const int lo = std::max(0, static_cast<int>(std::ceil((x - h - first) / o.zone_bin)));
      const int hi = std::min(n - 1, static_cast<int>(std::floor((x + h - first) / o.zone_bin)));
      for (int b = lo; b <= hi; ++b) {
        const double c = first + b * o.zone_bin;
        if (!(std::abs(x - c) <= h)) continue;  // (the rounding of lo and hi)
        sum[b] += w;
        count[b] += 1;
      }
      continue;
    }
    if (x < 0 || x >= n * o.zone_bin) continue;
    const int b = static_cast<int>(x / o.zone_bin);
    sum[b] += w;
    count[b] += 1;
  }
  std::vector<double> mean(n, 0.0);
  for (int b = 0; b < n; ++b) mean[b] = count[b] > 0 ? sum[b] / count[b] : 0.0;
  // (bins: smoothed by [1 2 1]/4; the cells are their own smoothing, as the seed's REV)
  std::vector<double> s(n);
  for (int b = 0; b < n; ++b)
    s[b] = window ? mean[b]
                  : (mean[std::max(0, b - 1)] + 2 * mean[b] + mean[std::min(n - 1, b + 1)]) / 4;
  r.zone_across.resize(n);
  for (int b = 0; b < n; ++b) r.zone_across[b] = x0 + first + b * o.zone_bin;
  r.zone_rotation = s;
  const int half = n / 2;
  const int pl = static_cast<int>(std::max_element(s.begin(), s.begin() + half) - s.begin());
  const int pr = static_cast<int>(std::max_element(s.begin() + (n - half), s.end()) - s.begin());
  // (point b is at first + b·bin from the left base plane)
  r.zone_left = profile_inflection(s, pl, +1, o.zone_bin) + first;
  const double right = profile_inflection(s, pr, -1, o.zone_bin);
  r.zone_right = std::isnan(right) ? NAN : width - (right + first);
  // The extent: where the profile falls below a multiple of the core's level (the median over
  // the middle third of the points).
  std::vector<double> core(s.begin() + n / 3, s.begin() + std::max(n / 3 + 1, 2 * n / 3));
  std::sort(core.begin(), core.end());
  const std::size_t m = core.size();
  r.zone_core = m % 2 ? core[m / 2] : 0.5 * (core[m / 2 - 1] + core[m / 2]);
  const double level = o.zone_extent_factor * r.zone_core;
  // From the peak `b` towards `step`, the crossing's position in steps from point 0.
  const auto crossing = [&](int b, int step) {
    if (!(s[b] >= level)) return static_cast<double>(NAN);
    while (b + step >= 0 && b + step < n && s[b + step] >= level) b += step;
    if (b + step < 0 || b + step >= n) return static_cast<double>(NAN);
    return b + step * (s[b] - level) / (s[b] - s[b + step]);
  };
  r.zone_extent_left = crossing(pl, +1) * o.zone_bin + first;
  r.zone_extent_right = width - (crossing(pr, -1) * o.zone_bin + first);
}

void void_ratio_layers(const Frame& f, const SiloReportOptions& o, const Eigen::Vector3d& up,
                       const Eigen::Vector3d& across, double bottom, double depth_lo,
                       double depth_hi, double x0, double x1, const Frame* reference,
                       SiloFrameReport& r) {
  if (!(o.layer_bin > 0) || !(o.layer_band > 0) || !std::isfinite(o.layer_bin) ||
      !std::isfinite(o.layer_band))
    throw std::invalid_argument("layer bin and band must be positive");
  if (!(x1 > x0)) return;
  const Eigen::Vector3d depth_axis = up.cross(across);
  std::unordered_map<std::int64_t, double> ref_height;  // (the reference frame's heights by id)
  if (reference)
    for (const Particle& p : reference->particles) ref_height[p.id] = p.position.dot(up);
  const int n = std::max(1, static_cast<int>(std::floor((x1 - x0) / o.layer_bin + 1e-9)));
  const double w = (x1 - x0) / n;  // (equal boxes filling the width)
  for (const double fr : o.layer_fractions) {
    if (!(fr > 0 && fr < 1)) throw std::invalid_argument("layer fractions must be in (0, 1)");
    SiloLayer layer;
    layer.height = fr * r.fill_height;  // (fill_height: set before the layers)
    const double z = bottom + layer.height;
    // (the band clipped to the fill: no space below the bottom or above the highest grain)
    const double zlo = std::max(bottom, z - 0.5 * o.layer_band);
    const double zhi = std::min(bottom + r.fill_height, z + 0.5 * o.layer_band);
    std::vector<double> solid(static_cast<std::size_t>(n), 0.0);
    std::vector<double> disp(solid), ndisp(solid), rot(solid), nrot(solid);
    for (const Particle& p : f.particles) {
      // The centre in the (across, depth, up) frame, where the boxes are axis-aligned.
      const Eigen::Vector3d c(p.position.dot(across), p.position.dot(depth_axis),
                              p.position.dot(up));
      if (!(c.z() + p.radius > zlo && c.z() - p.radius < zhi)) continue;
      if (c.z() >= zlo && c.z() < zhi && c.x() >= x0 && c.x() < x1) {  // (the centre's box)
        const auto b =
            static_cast<std::size_t>(std::min(n - 1, static_cast<int>((c.x() - x0) / w)));
        rot[b] += std::abs(p.rotation.dot(depth_axis));
        nrot[b] += 1;
        const auto it = ref_height.find(p.id);
        if (it != ref_height.end()) {
          disp[b] += it->second - c.z();
          ndisp[b] += 1;
        }
      }
      const int b0 = std::max(0, static_cast<int>(std::floor((c.x() - p.radius - x0) / w)));
      const int b1 = std::min(n - 1, static_cast<int>(std::floor((c.x() + p.radius - x0) / w)));
      for (int b = b0; b <= b1; ++b)
        solid[static_cast<std::size_t>(b)] += sphere_box_volume(
            c, p.radius, {x0 + b * w, depth_lo, zlo}, {x0 + (b + 1) * w, depth_hi, zhi});
    }
    const double box = w * (depth_hi - depth_lo) * (zhi - zlo);
    for (int b = 0; b < n; ++b) {
      layer.across.push_back(x0 + (b + 0.5) * w);
      const double v = solid[static_cast<std::size_t>(b)];
      layer.void_ratio.push_back(v > 0 ? box / v - 1 : NAN);
      const auto k = static_cast<std::size_t>(b);
      layer.displacement_down.push_back(ndisp[k] > 0 ? disp[k] / ndisp[k] : NAN);
      layer.rotation.push_back(nrot[k] > 0 ? rot[k] / nrot[k] : NAN);
    }
    r.layers.push_back(std::move(layer));
  }
}

void left_fabric(const Frame& f, const SiloReportOptions& o, const Eigen::Vector3d& up,
                 const Eigen::Vector3d& across, double bottom, double x0, double x1,
                 const std::unordered_map<std::int64_t, int>& role, SiloFrameReport& r) {
  if (!(x1 > x0)) return;
  const double mid = 0.5 * (x0 + x1);
  std::vector<RoseContact> picked;
  Eigen::Matrix2d F = Eigen::Matrix2d::Zero();
  for (const Contact& c : f.contacts) {
    if (role.count(c.id1) || role.count(c.id2)) continue;  // (particle–particle only)
    if (!(c.point.dot(across) < mid) || !(c.point.dot(up) > bottom)) continue;
    const Eigen::Vector2d n2(c.normal.dot(across), c.normal.dot(up));
    const double len = n2.norm();
    if (!(len > 0)) continue;
    const Eigen::Vector2d u = n2 / len;
    F += u * u.transpose();
    RoseContact rc;
    rc.normal = c.normal;
    rc.fn = c.normal_force.norm();
    rc.fs = c.shear_force.norm();
    picked.push_back(rc);
  }
  r.fabric_contacts = picked.size();
  if (picked.empty()) return;
  Eigen::Matrix3d axes;
  axes.row(0) = across.transpose();
  axes.row(1) = up.transpose();
  axes.row(2) = up.cross(across).transpose();
  const Rose rose = contact_rose_2d(picked, axes, o.fabric_bins);
  r.rose_angle_deg = rose.angle_deg;
  r.rose_density = rose.density;
  F /= static_cast<double>(picked.size());
  // Major principal direction of the symmetric 2×2 tensor: θ = ½·atan2(2F12, F11 − F22).
  double theta = 0.5 * std::atan2(2 * F(0, 1), F(0, 0) - F(1, 1)) * 180.0 / M_PI;
  if (theta <= -90) theta += 180;
  r.fabric_angle_deg = theta;
  const double mean = 0.5 * F.trace();
  const double dev =
      std::sqrt(0.25 * (F(0, 0) - F(1, 1)) * (F(0, 0) - F(1, 1)) + F(0, 1) * F(0, 1));
  r.fabric_anisotropy = dev / mean;  // ((F1 − F2) / (F1 + F2), the trace being 1)
}

void flow_pattern(const Frame& f, const SiloReportOptions& o, const Eigen::Vector3d& up,
                  const Eigen::Vector3d& across, double bottom, double x0, double x1,
                  SiloFrameReport& r) {
  if (!(o.flow_wall_width > 0) || !std::isfinite(o.flow_wall_width) || !(o.flow_threshold > 0) ||
      !(o.flow_threshold < 1))
    throw std::invalid_argument("flow wall width must be positive and the threshold in (0, 1)");
  if (!(x1 > x0) || !(r.fill_height > 0)) return;
  const int nb = o.flow_bands;
  const double w = o.flow_wall_width, band = r.fill_height / nb;
  const int cols = std::max(1, static_cast<int>(std::floor((x1 - x0) / w)));
  const double cw = (x1 - x0) / cols;
  // Per band: the sum and count of the downward velocity per column of the width w across, and
  // in the columns at the two walls (the column of width w at each base plane).
  std::vector<double> sum(static_cast<std::size_t>(nb * cols), 0.0), cnt(sum.size(), 0.0);
  std::vector<double> wl(static_cast<std::size_t>(nb), 0.0), nl(wl), wr(wl), nr(wl);
  for (const Particle& p : f.particles) {
    const double h = p.position.dot(up) - bottom, x = p.position.dot(across) - x0;
    if (!(h >= 0 && h < r.fill_height) || !(x >= 0 && x < x1 - x0)) continue;
    const auto b = static_cast<std::size_t>(std::min(nb - 1, static_cast<int>(h / band)));
    const double down = -p.velocity.dot(up);
    const auto c = static_cast<std::size_t>(std::min(cols - 1, static_cast<int>(x / cw)));
    sum[b * static_cast<std::size_t>(cols) + c] += down;
    cnt[b * static_cast<std::size_t>(cols) + c] += 1;
    if (x < w) wl[b] += down, nl[b] += 1;
    if (x >= (x1 - x0) - w) wr[b] += down, nr[b] += 1;
  }
  std::vector<double> fastest(static_cast<std::size_t>(nb), 0.0);
  for (std::size_t b = 0; b < static_cast<std::size_t>(nb); ++b)
    for (std::size_t c = 0; c < static_cast<std::size_t>(cols); ++c) {
      const std::size_t k = b * static_cast<std::size_t>(cols) + c;
      if (cnt[k] > 0) fastest[b] = std::max(fastest[b], sum[k] / cnt[k]);
    }
  r.flow_speed = *std::max_element(fastest.begin(), fastest.end());
  if (!(r.flow_speed > 1e-6)) {
    r.flow = FlowPattern::Rest;
    return;
  }
  // The transition of a wall: the lowest band from which the wall moves in every band up to the
  // one below the free surface's band at that wall (the highest band its column has grains in:
  // above an eccentric outlet the surface sinks into a crater, and the bands above it at that
  // wall are empty, not stagnant).
  auto highest = [&](const std::vector<double>& ns) {
    int b = nb - 1;
    while (b >= 0 && !(ns[static_cast<std::size_t>(b)] > 0)) --b;
    return b;  // (−1: no grains at the wall)
  };
  const int hl = highest(nl), hr = highest(nr);
  auto transition = [&](const std::vector<double>& ws, const std::vector<double>& ns, int hi) {
    const int top = std::max(0, hi - 1);
    int from = top + 1;
    for (int b = top; b >= 0; --b) {
      const auto k = static_cast<std::size_t>(b);
      const bool moves =
          ns[k] > 0 && fastest[k] > 0 && ws[k] / ns[k] > o.flow_threshold * fastest[k];
      if (!moves) break;
      from = b;
    }
    return from > top ? NAN : from * band;
  };
  r.transition_left = transition(wl, nl, hl);
  r.transition_right = transition(wr, nr, hr);
  auto pattern = [&](double t) {
    if (std::isnan(t)) return FlowPattern::Funnel;
    return t <= 0.25 * r.fill_height ? FlowPattern::Mass : FlowPattern::Mixed;
  };
  // A wall with no grains in its column (swept clean) holds no dead zone: the other decides.
  const bool left = hl >= 0, right = hr >= 0;
  if (left && right)
    r.flow = static_cast<FlowPattern>(std::min(static_cast<int>(pattern(r.transition_left)),
                                               static_cast<int>(pattern(r.transition_right))));
  else if (left || right)
    r.flow = pattern(left ? r.transition_left : r.transition_right);
  else
    r.flow = FlowPattern::Funnel;  // (grains moving between two bare walls: a stream)
}

}  // namespace

const char* flow_pattern_name(FlowPattern p) {
  switch (p) {
    case FlowPattern::Rest:
      return "at rest";
    case FlowPattern::Funnel:
      return "funnel";
    case FlowPattern::Mixed:
      return "mixed";
    case FlowPattern::Mass:
      return "mass";
  }
  return "?";
}

SiloFrameReport silo_report(const Frame& f, const SiloReportOptions& o, const Frame* reference) {
  if (!(o.bin > 0) || !std::isfinite(o.bin)) throw std::invalid_argument("bin must be positive");
  if (!(o.depth >= 0) || !std::isfinite(o.depth))
    throw std::invalid_argument("depth must not be negative");
  if (!(o.gravity > 0)) throw std::invalid_argument("gravity must be positive");
  if (!(o.up.norm() > 0) || !(o.across.norm() > 0))
    throw std::invalid_argument("up and across must not be zero");
  const Eigen::Vector3d up = o.up.normalized(), across = o.across.normalized();
  if (std::abs(up.dot(across)) > 1e-9)
    throw std::invalid_argument("up and across must be orthogonal");
  SiloFrameReport r;
  r.time = f.time;
  // The walls' roles: 1 left side, 2 right side, 3 bottom, 0 neither.
  std::unordered_map<std::int64_t, int> role;
  std::unordered_map<std::int64_t, Eigen::Vector3d> inward;  // sides: their horizontal inward
  double bottom = -HUGE_VAL;
  for (const Wall& w : f.walls) {
    int k = 0;
    if (w.kind == WallKind::Box) {
      k = 3;
      bottom = std::max(bottom, w.a.dot(up) + w.b.cwiseAbs().dot(up.cwiseAbs()));
    } else {
      const Eigen::Vector3d n = w.b.normalized();
      if (n.dot(up) >= 0.99) {
        k = 3;
        bottom = std::max(bottom, w.a.dot(up));
      } else if (std::abs(n.dot(up)) < 0.99 && std::abs(n.dot(across)) >= 0.1) {
        k = n.dot(across) > 0 ? 1 : 2;
        inward[w.id] = k == 1 ? across : Eigen::Vector3d(-across);
      }
    }
    role[w.id] = k;
    const Eigen::Vector3d& F = w.force;
    if (k == 3) {
      r.P -= F.dot(up);
      ++r.bottom_walls;
    } else if (k == 1) {
      r.T_left -= F.dot(up);
      r.N_left -= F.dot(across);
      ++r.side_walls_left;
    } else if (k == 2) {
      r.T_right -= F.dot(up);
      r.N_right += F.dot(across);
      ++r.side_walls_right;
    }
  }
  if (r.side_walls_left == 0 || r.side_walls_right == 0)
    throw std::invalid_argument("no left and right side walls (walls facing across, " +
                                std::to_string(r.side_walls_left) + " left, " +
                                std::to_string(r.side_walls_right) + " right)");
  if (r.bottom_walls == 0) throw std::invalid_argument("no bottom wall (a box or an upward plane)");
  r.bottom_level = bottom;
  // The weight of the particles above the bottom, and their extent across the depth.
  const Eigen::Vector3d depth_axis = up.cross(across);
  double lo = HUGE_VAL, hi = -HUGE_VAL, top = bottom;
  for (const Particle& p : f.particles) {
    const double z = p.position.dot(up);
    if (z > bottom) r.G += p.mass * o.gravity;
    const double y = p.position.dot(depth_axis);
    lo = std::min(lo, y - p.radius);
    hi = std::max(hi, y + p.radius);
    top = std::max(top, z + p.radius);
  }
  if (!(r.G > 0)) throw std::invalid_argument("no particles above the bottom");
  const double depth = o.depth > 0 ? o.depth : hi - lo;
  const double deg = 180.0 / M_PI;
  r.phi_left_deg = std::atan2(r.T_left, r.N_left) * deg;
  r.phi_right_deg = std::atan2(r.T_right, r.N_right) * deg;
  r.balance = (r.P + r.T_left + r.T_right) / r.G;
  // Profiles from the side walls' contacts.
  const std::size_t bins =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil((top - bottom) / o.bin - 1e-12)));
  SiloProfile& pr = r.profile;
  for (auto* v : {&pr.height, &pr.sigma11_left, &pr.sigma21_left, &pr.sigma11_right,
                  &pr.sigma21_right, &pr.contacts_left, &pr.contacts_right})
    v->assign(bins, 0.0);
  for (std::size_t b = 0; b < bins; ++b) pr.height[b] = (static_cast<double>(b) + 0.5) * o.bin;
  const double area = o.bin * depth;
  std::size_t wall_contacts = 0;
  for (const Contact& c : f.contacts) {
    const bool first = role.count(c.id1) != 0;
    const std::int64_t id = first ? c.id1 : c.id2;
    const auto it = role.find(id);
    if (it == role.end()) continue;
    ++wall_contacts;
    if (it->second != 1 && it->second != 2) continue;
    // The force of the material on the wall: the contact's forces are those of id1 on id2.
    const Eigen::Vector3d F = first ? Eigen::Vector3d(-(c.normal_force + c.shear_force))
                                    : Eigen::Vector3d(c.normal_force + c.shear_force);
    const double h = c.point.dot(up) - bottom;
    if (h < 0) continue;  // (a wall reaching below the bottom)
    const auto b = std::min(bins - 1, static_cast<std::size_t>(h / o.bin));
    const double s11 = -F.dot(inward.at(id)) / area, s21 = -F.dot(up) / area;
    if (it->second == 1) {
      pr.sigma11_left[b] += s11;
      pr.sigma21_left[b] += s21;
      pr.contacts_left[b] += 1;
    } else {
      pr.sigma11_right[b] += s11;
      pr.sigma21_right[b] += s21;
      pr.contacts_right[b] += 1;
    }
  }
  // The side walls' base planes across, and the depth the stresses and boxes span.
  const auto [x0, x1] = wall_bases(f, across, role);
  const double dlo = o.depth > 0 ? 0.5 * (lo + hi) - 0.5 * depth : lo;
  const double dhi = o.depth > 0 ? 0.5 * (lo + hi) + 0.5 * depth : hi;
  if (o.rev_width > 0) {
    // Love–Weber stress in near-wall cells, in the (across, depth, up) frame.
    Eigen::Matrix3d R;
    R.row(0) = across.transpose();
    R.row(1) = depth_axis.transpose();
    R.row(2) = up.transpose();
    ContactBranches cb = contact_branches(f);
    for (ContactBranch& b : cb.branches) {
      b.start = R * b.start;
      b.branch = R * b.branch;
      b.force = R * b.force;
    }
    for (auto* v :
         {&pr.lw_sigma11_left, &pr.lw_sigma21_left, &pr.lw_sigma11_right, &pr.lw_sigma21_right})
      v->assign(bins, 0.0);
    for (std::size_t b = 0; b < bins; ++b) {
      const double z0 = bottom + static_cast<double>(b) * o.bin, z1 = z0 + o.bin;
      const Eigen::Matrix3d sl =
          love_weber_stress(cb.branches, {x0, dlo, z0}, {x0 + o.rev_width, dhi, z1});
      const Eigen::Matrix3d sr =
          love_weber_stress(cb.branches, {x1 - o.rev_width, dlo, z0}, {x1, dhi, z1});
      pr.lw_sigma11_left[b] = sl(0, 0);
      pr.lw_sigma21_left[b] = 0.5 * (sl(0, 2) + sl(2, 0));
      pr.lw_sigma11_right[b] = sr(0, 0);
      pr.lw_sigma21_right[b] = -0.5 * (sr(0, 2) + sr(2, 0));
    }
  }
  if (o.zone_bin > 0) wall_zones(f, o, up, across, bottom, top, x0, x1, r);
  r.fill_height = top - bottom;
  r.width = x1 > x0 ? x1 - x0 : 0.0;
  if (!o.layer_fractions.empty())
    void_ratio_layers(f, o, up, across, bottom, dlo, dhi, x0, x1, reference, r);
  if (o.fabric_bins > 0) left_fabric(f, o, up, across, bottom, x0, x1, role, r);
  if (o.flow_bands > 0) flow_pattern(f, o, up, across, bottom, x0, x1, r);
  const bool loaded = std::abs(r.T_left) + std::abs(r.N_left) + std::abs(r.T_right) +
                          std::abs(r.N_right) + std::abs(r.P) >
                      0;
  if (loaded && wall_contacts == 0)
    throw std::invalid_argument(
        "the walls carry forces but the frame holds no wall contact (write frames with contacts)");
  return r;
}

}  // namespace gs::analysis
