// Extrema and vortex tubes of an HHD: seed 000 §5–6.
#include "vortex_detection.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

// +1: strict maximum over the 1-ring, −1: strict minimum, 0: neither (or no neighbours).
int strict_extremum(const std::vector<double>& f, const VertexRings& rings, std::size_t i) {
  const auto b = static_cast<std::size_t>(rings.offset[i]);
  const auto e = static_cast<std::size_t>(rings.offset[i + 1]);
  if (b == e) return 0;
  bool max = true, min = true;
  for (std::size_t k = b; k < e && (max || min); ++k) {
    const double g = f[static_cast<std::size_t>(rings.index[k])];
    if (!(f[i] > g)) max = false;
    if (!(f[i] < g)) min = false;
  }
  return max ? 1 : (min ? -1 : 0);
}

Eigen::Vector3d potential(const HhdResult& r, std::int32_t i) {
  if (r.dim == 3) return r.v_coulomb.row(i).transpose();
  return Eigen::Vector3d(0.0, 0.0, r.v_coulomb(i, 0));
}

}  // namespace

const char* extremum_kind_name(ExtremumKind k) {
  switch (k) {
    case ExtremumKind::RightVortex:
      return "right_vortex";
    case ExtremumKind::LeftVortex:
      return "left_vortex";
    case ExtremumKind::Source:
      return "source";
    case ExtremumKind::Sink:
      return "sink";
  }
  return "?";
}

std::vector<Extremum> find_extrema(const HhdResult& r, const VertexRings& rings,
                                   const std::vector<std::uint8_t>& excluded,
                                   const Eigen::Vector3d& axis) {
  const auto n = static_cast<std::size_t>(r.u.size());
  if (rings.offset.size() != n + 1) {
    throw std::invalid_argument("vertex rings do not match the HHD nodes (" +
                                std::to_string(rings.offset.size()) + " offsets for " +
                                std::to_string(n) + " nodes)");
  }
  if (!excluded.empty() && excluded.size() != n) {
    throw std::invalid_argument("one exclusion flag per node needed");
  }
  std::vector<double> vortex(n), u(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    vortex[i] = r.dim == 3 ? r.v_coulomb.row(ii).norm() : r.v_coulomb(ii, 0);
    u[i] = r.u(ii);
  }
  std::vector<Extremum> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (!excluded.empty() && excluded[i]) continue;
    const int s = strict_extremum(vortex, rings, i);
    if (s == 0 || (r.dim == 3 && s < 0)) continue;  // 3D: maxima of |v| only
    Extremum e;
    e.node = static_cast<std::int32_t>(i);
    e.value = vortex[i];
    e.magnitude = std::abs(vortex[i]);
    e.v = potential(r, e.node);
    const bool right = r.dim == 3 ? e.v.dot(axis) < 0.0 : s < 0;
    e.kind = right ? ExtremumKind::RightVortex : ExtremumKind::LeftVortex;
    out.push_back(e);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!excluded.empty() && excluded[i]) continue;
    const int s = strict_extremum(u, rings, i);
    if (s == 0) continue;
    Extremum e;
    e.node = static_cast<std::int32_t>(i);
    e.kind = s < 0 ? ExtremumKind::Source : ExtremumKind::Sink;
    e.value = u[i];
    e.magnitude = std::abs(u[i]);
    e.v = potential(r, e.node);
    out.push_back(e);
  }
  return out;
}

void mark_significant(std::vector<Extremum>& extrema, double relative, double absolute) {
  if (!(relative >= 0.0 && relative <= 1.0)) {
    throw std::invalid_argument("relative significance must be in [0, 1] (" +
                                std::to_string(relative) + ")");
  }
  if (!(absolute >= 0.0 && std::isfinite(absolute))) {
    throw std::invalid_argument("absolute significance must be >= 0 (" + std::to_string(absolute) +
                                ")");
  }
  const auto is_vortex = [](const Extremum& e) {
    return e.kind == ExtremumKind::RightVortex || e.kind == ExtremumKind::LeftVortex;
  };
  double strongest[2] = {0.0, 0.0};  // vortices, sources and sinks
  for (const auto& e : extrema) {
    double& s = strongest[is_vortex(e) ? 0 : 1];
    s = std::max(s, e.magnitude);
  }
  for (auto& e : extrema) {
    e.significant = e.magnitude >= std::max(relative * strongest[is_vortex(e) ? 0 : 1], absolute);
  }
}

std::vector<VortexTube> trace_vortex_tubes(const HhdMesh& mesh, const HhdResult& r,
                                           const VertexRings& rings,
                                           const std::vector<Extremum>& extrema, double delta,
                                           const std::vector<std::uint8_t>& excluded) {
  if (!(delta >= 0.0 && delta < 1.0)) {
    throw std::invalid_argument("tube threshold delta must be in [0, 1) (" + std::to_string(delta) +
                                ")");
  }
  std::vector<VortexTube> tubes;
  if (r.dim != 3) return tubes;
  const auto norm = [&](std::int32_t i) { return r.v_coulomb.row(i).norm(); };
  const auto is_excluded = [&](std::int32_t i) {
    return !excluded.empty() && excluded[static_cast<std::size_t>(i)];
  };
  // One direction from the centre; returns the nodes after the centre.
  const auto trace = [&](std::int32_t start, double sign) {
    std::vector<std::int32_t> path;
    std::vector<std::int32_t> held{start};
    std::int32_t c = start;
    Eigen::Vector3d d = sign * r.v_coulomb.row(start).transpose();
    while (true) {
      const double vc = norm(c);
      std::int32_t best = -1;
      double best_v = -1.0;
      const auto ci = static_cast<std::size_t>(c);
      for (auto k = rings.offset[ci]; k < rings.offset[ci + 1]; ++k) {
        const std::int32_t j = rings.index[static_cast<std::size_t>(k)];
        const Eigen::Vector3d step = mesh.points[static_cast<std::size_t>(j)] - mesh.points[ci];
        if (!(step.dot(d) > 0.0)) continue;
        const double vj = norm(j);
        if (vj > best_v) {
          best_v = vj;
          best = j;
        }
      }
      if (best < 0 || best_v < (1.0 - delta) * vc || is_excluded(best) ||
          std::find(held.begin(), held.end(), best) != held.end()) {
        break;
      }
      path.push_back(best);
      held.push_back(best);
      const Eigen::Vector3d vb = r.v_coulomb.row(best).transpose();
      d = vb.dot(d) >= 0.0 ? vb : Eigen::Vector3d(-vb);
      c = best;
    }
    return path;
  };
  for (std::size_t e = 0; e < extrema.size(); ++e) {
    const auto& x = extrema[e];
    if (x.kind != ExtremumKind::RightVortex && x.kind != ExtremumKind::LeftVortex) continue;
    VortexTube t;
    t.extremum = e;
    const auto back = trace(x.node, -1.0);
    const auto fwd = trace(x.node, 1.0);
    t.nodes.assign(back.rbegin(), back.rend());
    t.nodes.push_back(x.node);
    t.nodes.insert(t.nodes.end(), fwd.begin(), fwd.end());
    tubes.push_back(std::move(t));
  }
  return tubes;
}

}  // namespace gs::analysis
