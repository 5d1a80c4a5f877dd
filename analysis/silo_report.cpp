#include "silo_report.hpp"

#include "shear_zone.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

namespace gs::analysis {

namespace {

void wall_zones(const Frame& f, const SiloReportOptions& o, const Eigen::Vector3d& up,
                const Eigen::Vector3d& across, double bottom, double top,
                const std::unordered_map<std::int64_t, int>& role, SiloFrameReport& r) {
  if (!(o.zone_band > 0)) throw std::invalid_argument("zone band must be positive");
  // The walls' base planes across: the extreme wall points of each side.
  double x0 = HUGE_VAL, x1 = -HUGE_VAL;
  for (const Wall& w : f.walls) {
    const auto it = role.find(w.id);
    if (it == role.end()) continue;
    if (it->second == 1) x0 = std::min(x0, w.a.dot(across));
    if (it->second == 2) x1 = std::max(x1, w.a.dot(across));
  }
  if (!(x1 > x0)) return;
  r.zone_height = o.zone_height > 0 ? o.zone_height : 0.5 * (top - bottom);
  const double z = bottom + r.zone_height;
  const Eigen::Vector3d depth_axis = up.cross(across);
  const int n = std::max(3, static_cast<int>(std::ceil((x1 - x0) / o.zone_bin)));
  std::vector<double> sum(n, 0.0), count(n, 0.0);
  for (const Particle& p : f.particles) {
    if (std::abs(p.position.dot(up) - z) > 0.5 * o.zone_band) continue;
    const double x = p.position.dot(across) - x0;
    if (x < 0 || x >= n * o.zone_bin) continue;
    const int b = static_cast<int>(x / o.zone_bin);
    sum[b] += std::abs(p.rotation.dot(depth_axis));
    count[b] += 1;
  }
  std::vector<double> mean(n, 0.0);
  for (int b = 0; b < n; ++b) mean[b] = count[b] > 0 ? sum[b] / count[b] : 0.0;
  std::vector<double> s(n);
  for (int b = 0; b < n; ++b)
    s[b] = (mean[std::max(0, b - 1)] + 2 * mean[b] + mean[std::min(n - 1, b + 1)]) / 4;
  r.zone_across.resize(n);
  for (int b = 0; b < n; ++b) r.zone_across[b] = x0 + (b + 0.5) * o.zone_bin;
  r.zone_rotation = s;
  const int half = n / 2;
  const int pl = static_cast<int>(std::max_element(s.begin(), s.begin() + half) - s.begin());
  const int pr = static_cast<int>(std::max_element(s.begin() + (n - half), s.end()) - s.begin());
  // (bin centres are at (b + 1/2)·bin from the base plane)
  r.zone_left = profile_inflection(s, pl, +1, o.zone_bin) + 0.5 * o.zone_bin;
  const double right = profile_inflection(s, pr, -1, o.zone_bin);
  r.zone_right = std::isnan(right) ? NAN : (x1 - x0) - (right + 0.5 * o.zone_bin);
}

}  // namespace

SiloFrameReport silo_report(const Frame& f, const SiloReportOptions& o) {
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
  if (o.zone_bin > 0) wall_zones(f, o, up, across, bottom, top, role, r);
  const bool loaded = std::abs(r.T_left) + std::abs(r.N_left) + std::abs(r.T_right) +
                          std::abs(r.N_right) + std::abs(r.P) >
                      0;
  if (loaded && wall_contacts == 0)
    throw std::invalid_argument(
        "the walls carry forces but the frame holds no wall contact (write frames with contacts)");
  return r;
}

}  // namespace gs::analysis
