// Wall loads and resultants P, T, N, G, phi_w (seed 004 §5.3.1); conventions in the header.
#include "wall_stress.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include "errors.hpp"
#include "selection.hpp"

namespace gs::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = 180.0 / std::numbers::pi;

}  // namespace

WallLoads wall_loads(const Frame& frame, const ContactBranches& branches, const WallOptions& opt) {
  if (!(opt.bin > 0.0) || !std::isfinite(opt.bin))
    throw std::invalid_argument("walls: bin must be > 0");
  if (!(opt.width >= 0.0) || !std::isfinite(opt.width))
    throw std::invalid_argument("walls: width must be >= 0");
  if (!opt.up.allFinite() || !(opt.up.norm() > 0.0))
    throw std::invalid_argument("walls: up vector is zero");
  const Eigen::Vector3d up = opt.up.normalized();
  WallLoads out;
  // Walls of the snapshot, and bodies in wall contacts that it does not describe (e.g. YADE
  // facets or boxes in a VTKExporter file): a plane through their mean contact point with the
  // mean direction from the contact points to the particle centres as its normal.
  std::vector<Wall> walls = frame.walls;
  std::vector<std::uint8_t> inferred(walls.size(), 0);
  {
    std::unordered_map<std::int64_t, std::size_t> known;
    for (std::size_t k = 0; k < walls.size(); ++k) known.emplace(walls[k].id, k);
    std::unordered_map<std::int64_t, std::size_t> extra;
    std::vector<std::pair<Eigen::Vector3d, double>> sums;
    for (const auto& b : branches.branches) {
      if (b.p2 >= 0) continue;
      const Contact& c = frame.contacts[static_cast<std::size_t>(b.contact)];
      const std::int64_t pid = frame.particles[static_cast<std::size_t>(b.p1)].id;
      const std::int64_t wid = c.id1 == pid ? c.id2 : c.id1;
      if (known.count(wid)) continue;
      auto [it, added] = extra.emplace(wid, walls.size());
      if (added) {
        Wall w;
        w.id = wid;
        w.a = Eigen::Vector3d::Zero();
        w.b = Eigen::Vector3d::Zero();
        walls.push_back(w);
        inferred.push_back(1);
      }
      Wall& w = walls[it->second];
      w.a += c.point;
      w.b -= b.branch.normalized();
      w.force[0] += 1.0;  // count, replaced below
    }
    for (std::size_t k = 0; k < walls.size(); ++k) {
      if (!inferred[k]) continue;
      walls[k].a /= walls[k].force[0];
      walls[k].force.setZero();
      if (!(walls[k].b.norm() > 0.0)) walls[k].kind = WallKind::Box;
    }
  }
  std::unordered_map<std::int64_t, std::size_t> index;
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const Wall& w = walls[k];
    WallLoad l;
    l.id = w.id;
    l.recorded = w.force;
    l.inferred = inferred[k] != 0;
    if (w.kind == WallKind::Plane || w.kind == WallKind::Facet) {  // (a facet: its plane)
      l.normal = w.b.normalized();
      const double c = l.normal.dot(up);
      l.role = c > 0.9 ? "bottom" : c < -0.9 ? "top" : std::abs(c) < 0.1 ? "side" : "other";
      // Binning axis: up for side walls, else the lab axis most in the plane, projected.
      Eigen::Vector3d ax = up - up.dot(l.normal) * l.normal;
      if (l.role != "side") {
        int best = 0;
        for (int d = 1; d < 3; ++d)
          if (std::abs(l.normal[d]) < std::abs(l.normal[best])) best = d;
        ax = Eigen::Vector3d::Unit(best) - l.normal[best] * l.normal;
      }
      l.axis = ax.normalized();
    } else {
      l.role = "box";
    }
    index.emplace(w.id, out.walls.size());
    out.walls.push_back(l);
  }
  // Extent of the material across each wall's axis, in the wall plane.
  for (auto& l : out.walls) {
    if (l.role == "box") continue;
    if (opt.width > 0.0) {
      l.width = opt.width;
    } else if (frame.two_d) {
      l.width = 1.0;  // per unit depth: N/m
    } else {
      const Eigen::Vector3d across = l.normal.cross(l.axis);
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const auto& p : frame.particles) {
        lo = std::min(lo, p.position.dot(across) - p.radius);
        hi = std::max(hi, p.position.dot(across) + p.radius);
      }
      l.width = hi - lo;
    }
  }
  // Contacts: force by the particle on the wall (branch force), position along the axis.
  std::vector<std::vector<std::pair<double, Eigen::Vector3d>>> per_wall(out.walls.size());
  for (const auto& b : branches.branches) {
    if (b.p2 >= 0) continue;
    const Contact& c = frame.contacts[static_cast<std::size_t>(b.contact)];
    const std::int64_t pid = frame.particles[static_cast<std::size_t>(b.p1)].id;
    const std::int64_t wid = c.id1 == pid ? c.id2 : c.id1;
    const auto it = index.find(wid);
    WallLoad& l = out.walls[it->second];
    l.force += b.force;
    ++l.contacts;
    per_wall[it->second].emplace_back(l.role == "box" ? 0.0 : c.point.dot(l.axis), b.force);
  }
  std::size_t total = 0;
  for (const auto& l : out.walls) total += l.contacts;
  if (total == 0) throw std::invalid_argument("walls: no particle-wall contact in the frame");
  for (std::size_t w = 0; w < out.walls.size(); ++w) {
    WallLoad& l = out.walls[w];
    if (l.role == "box") {
      l.N = l.T = l.phi_deg = kNaN;
      continue;
    }
    l.N = -l.force.dot(l.normal);
    // Side walls: the vertical (friction) force; other walls: the tangential force magnitude.
    l.T = l.role == "side" ? -l.force.dot(up) : (l.force + l.N * l.normal).norm();
    l.phi_deg = l.N != 0.0 ? std::atan(l.T / l.N) * kDeg : kNaN;
    if (l.role == "bottom") out.P += -l.force.dot(up);
    if (l.role == "side") {
      out.T += l.T;
      out.N += l.N;
    }
    const auto& pts = per_wall[w];
    if (pts.empty()) continue;
    double lo = pts[0].first, hi = lo;
    for (const auto& [s, f] : pts) lo = std::min(lo, s), hi = std::max(hi, s);
    if ((hi - lo) / opt.bin > 1e6) throw std::invalid_argument("walls: bin too small for the wall");
    const int nb = static_cast<int>(std::floor((hi - lo) / opt.bin)) + 1;
    if (nb > 1000000) throw std::invalid_argument("walls: bin too small for the wall");
    const double start = 0.5 * (lo + hi) - 0.5 * nb * opt.bin;
    l.position.resize(static_cast<std::size_t>(nb));
    l.sigma_n.assign(static_cast<std::size_t>(nb), 0.0);
    l.tau.assign(static_cast<std::size_t>(nb), 0.0);
    l.count.assign(static_cast<std::size_t>(nb), 0.0);
    const double area = opt.bin * l.width;
    for (int k = 0; k < nb; ++k)
      l.position[static_cast<std::size_t>(k)] = start + (k + 0.5) * opt.bin;
    for (const auto& [s, f] : pts) {
      const auto k = static_cast<std::size_t>(
          std::clamp(static_cast<int>(std::floor((s - start) / opt.bin)), 0, nb - 1));
      l.sigma_n[k] += -f.dot(l.normal) / area;
      l.tau[k] += -f.dot(l.axis) / area;
      l.count[k] += 1.0;
    }
  }
  out.phi_deg = out.N != 0.0 ? std::atan(out.T / out.N) * kDeg : kNaN;
  for (const auto& p : frame.particles) {
    const double vol = frame.two_d ? std::numbers::pi * p.radius * p.radius
                                   : 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius, 3);
    out.G += (p.mass > 0.0 ? p.mass : opt.particle_density * vol) * opt.gravity;
  }
  return out;
}

WallReport wall_report(const std::string& file, const Frame& frame, double d50,
                       const WallSpec& spec) {
  WallReport r;
  r.options.up = spec.up;
  r.options.bin = length_option(file, "--bin", spec.bin, spec.bin_d50, 5.0, d50);
  if (spec.width) require_positive(file, "--width", *spec.width);
  r.options.width = spec.width.value_or(0.0);
  require_positive(file, "--gravity", spec.gravity);
  require_positive(file, "--particle-density", spec.particle_density);
  r.options.gravity = spec.gravity;
  r.options.particle_density = spec.particle_density;
  try {
    r.loads = wall_loads(frame, contact_branches(frame), r.options);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  return r;
}

}  // namespace gs::analysis
