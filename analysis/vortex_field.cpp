// The field of `analyze hhd | vortices` and its options (see vortex_field.hpp).
#include "vortex_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "errors.hpp"
#include "grain_size.hpp"

namespace gs::analysis {

VortexField vortex_field(const FrameMotion& m, const VortexFieldSpec& spec,
                         const std::string& file) {
  VortexField f;
  f.d50 = d50(m.frame);
  f.slab = spec.projected();
  for (const auto k : m.index) f.id.push_back(m.frame.particles[static_cast<std::size_t>(k)].id);
  if (f.slab) {
    if (m.frame.two_d) throw InputError(file, "--slice/--slab needs a 3D frame");
    ProjectionSlabSpec s = spec.slab;
    if (s.thickness <= 0.0 && s.d50_multiple <= 0.0) s.d50_multiple = 5.0;
    f.plane = s.make(m.frame);
    if (s.origin.empty()) {  // mid-depth: the centre of the particles' box
      const auto [lo, hi] = particle_bounds(m.frame);
      f.plane.origin = 0.5 * (lo + hi);
    }
    SlabProjection p;
    try {
      p = project_slab(m.x, m.u, f.plane);
    } catch (const std::invalid_argument& e) {
      throw InputError(file, e.what());
    }
    f.dim = 2;
    f.e1 = p.e1;
    f.e2 = p.e2;
    std::vector<std::int64_t> ids;
    for (std::size_t i = 0; i < p.index.size(); ++i) {
      f.x.emplace_back(p.position[i].x(), p.position[i].y(), 0.0);
      f.u.emplace_back(p.vector[i].x(), p.vector[i].y(), 0.0);
      ids.push_back(f.id[static_cast<std::size_t>(p.index[i])]);
    }
    f.id = ids;
    return f;
  }
  f.dim = m.frame.two_d ? 2 : 3;
  f.x = m.x;
  f.u = m.u;
  return f;
}

VortexAnalysisOptions vortex_analysis_options(const VortexFieldSpec& a, const VortexField& f,
                                              const std::string& file) {
  VortexAnalysisOptions o;
  try {
    o.hhd.solver = hhd_solver_from_name(a.solver);
  } catch (const std::invalid_argument&) {
    throw InputError(file, "--solver: unknown solver", a.solver);
  }
  if (a.tolerance && !(*a.tolerance > 0.0 && *a.tolerance < 1.0))
    throw InputError(file, "--tolerance must be in (0, 1)", value_str(*a.tolerance));
  if (a.max_iterations < 1)
    throw InputError(file, "--max-iterations must be >= 1", std::to_string(a.max_iterations));
  if (!(a.delta >= 0.0 && a.delta < 1.0))
    throw InputError(file, "--delta must be in [0, 1)", value_str(a.delta));
  if (!(a.significance >= 0.0 && a.significance <= 1.0))
    throw InputError(file, "--significance must be in [0, 1]", value_str(a.significance));
  if (!(a.significance_abs >= 0.0 && std::isfinite(a.significance_abs)))
    throw InputError(file, "--significance-abs must be >= 0", value_str(a.significance_abs));
  o.significance_relative = a.significance;
  o.significance_absolute = a.significance_abs;
  o.hhd.tolerance = a.tolerance.value_or(0.0);
  o.hhd.max_iterations = a.max_iterations;
  o.hhd.poll = a.poll;
  o.tube_delta = a.delta;
  if (a.axis.size() == 3) {
    o.axis = Eigen::Vector3d(a.axis.data());
    if (!(o.axis.norm() > 0.0) || !o.axis.allFinite())
      throw InputError(file, "--axis must be a non-zero vector");
  } else if (!a.axis.empty()) {
    throw InputError(file, "--axis needs 3 numbers", std::to_string(a.axis.size()));
  } else if (a.slab.normal.size() == 3) {
    o.axis = Eigen::Vector3d(a.slab.normal.data());
  }
  o.ghosts = a.ghosts;
  if (a.ghosts) {
    const double d = a.d50 > 0.0 ? a.d50 : f.d50;
    Eigen::Vector3d lo = f.x.empty() ? Eigen::Vector3d::Zero() : f.x[0], hi = lo;
    for (const auto& p : f.x) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    double width = hi.x() - lo.x();
    for (int k = 1; k < f.dim; ++k) width = std::min(width, hi[k] - lo[k]);
    if (!(d > 0.0) && (a.ghost_spacing <= 0.0 || a.ghost_min_distance < 0.0)) {
      throw InputError(file,
                       "--ghosts: no radii in the input; give --d50, or --ghost-spacing and "
                       "--ghost-min-distance");
    }
    o.ghost = paper_ghost_options(d, width);
    if (a.ghost_spacing > 0.0) o.ghost.spacing = a.ghost_spacing;
    if (a.ghost_min_distance >= 0.0) o.ghost.min_distance = a.ghost_min_distance;
    if (a.ghost_extent > 0.0) o.ghost.extent = a.ghost_extent;
    if (a.ghost_radius > 0.0) o.ghost.radius = a.ghost_radius;
  }
  return o;
}

VortexAnalysis analyze_field(const VortexField& f, const VortexAnalysisOptions& o,
                             const std::string& file) {
  try {
    return analyze_vortices(f.x, f.u, f.dim, o);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
}

ExtremaColumns extrema_columns(const VortexAnalysis& r) {
  ExtremaColumns c;
  for (const auto& e : r.extrema) {
    c.node.push_back(e.node);
    c.kind.push_back(static_cast<std::int32_t>(e.kind));
    c.value.push_back(e.value);
    c.magnitude.push_back(e.magnitude);
    c.significant.push_back(e.significant ? 1 : 0);
    c.position.push_back(r.mesh.points[static_cast<std::size_t>(e.node)]);
    c.v.push_back(e.v);
  }
  return c;
}

TubeColumns tube_columns(const VortexAnalysis& r) {
  TubeColumns c;
  for (const auto& t : r.tubes) {
    c.nodes.insert(c.nodes.end(), t.nodes.begin(), t.nodes.end());
    c.offsets.push_back(static_cast<std::int64_t>(c.nodes.size()));
    c.extremum.push_back(static_cast<std::int32_t>(t.extremum));
  }
  return c;
}

}  // namespace gs::analysis
