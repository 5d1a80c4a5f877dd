// Local strain of a frame's motion (see strain_report.hpp).
#include "strain_report.hpp"

#include <stdexcept>

#include "errors.hpp"
#include "kuhn_void_cells.hpp"
#include "slab_projection.hpp"

namespace gs::analysis {

StrainReport strain_report(const std::string& file, const FrameMotion& m, const StrainSpec& spec) {
  if (!(spec.min_quality >= 0.0 && spec.min_quality < 1.0))
    throw InputError(file, "--min-quality must be in [0, 1)", value_str(spec.min_quality));
  StrainReport out;
  out.slab = spec.slab.any();
  SimplexStrain& r = out.strain;
  std::vector<std::int32_t> index = m.index;
  SimplexStrainOptions options;
  options.min_quality = spec.min_quality;
  try {
    if (m.frame.two_d || out.slab) {
      std::vector<Eigen::Vector2d> x2, u2;
      if (out.slab) {
        if (m.frame.two_d) throw InputError(file, "--slab needs a 3D frame");
        const auto p = project_slab(m.x, m.u, spec.slab.make(m.frame));
        std::vector<std::int32_t> sub;
        for (const auto k : p.index) sub.push_back(index[static_cast<std::size_t>(k)]);
        index = sub;
        x2 = p.position;
        u2 = p.vector;
      } else {
        for (std::size_t i = 0; i < m.x.size(); ++i) {
          x2.push_back(m.x[i].head<2>());
          u2.push_back(m.u[i].head<2>());
        }
      }
      r = triangle_strain(x2, u2, options);
      for (const auto& p : x2) out.position.emplace_back(p.x(), p.y(), 0.0);
    } else {
      if (spec.weighted) {
        for (const auto k : m.index)
          options.radii.push_back(m.frame.particles[static_cast<std::size_t>(k)].radius);
      }
      r = tet_strain(m.x, m.u, options);
      out.position = m.x;
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  out.weighted = !options.radii.empty();
  for (std::size_t i = 0; i < index.size(); ++i) {
    out.id.push_back(m.frame.particles[static_cast<std::size_t>(index[i])].id);
    const auto s = strain_measures(r.particle_gradient[i], r.dim);
    out.volumetric.push_back(s.volumetric);
    out.shear.push_back(s.equivalent_shear);
    out.rotation_xy.push_back(s.rotation(1, 0));  // in-plane rotation (about z); 3D: gradient
  }
  for (const auto& g : r.gradient) {
    const auto s = strain_measures(g, r.dim);
    out.simplex_volumetric.push_back(s.volumetric);
    out.simplex_shear.push_back(s.equivalent_shear);
  }
  if (r.dim == 2) {  // triangle (Bagi eq 4) variant of seed 002's alpha and w maps
    const Eigen::Matrix2d mean = r.mean_gradient.topLeftCorner<2, 2>();
    for (const auto& gt : r.gradient) {
      out.alpha.push_back(alignment(gt.topLeftCorner<2, 2>(), mean));
      out.w.push_back(normalised_vorticity(gt.topLeftCorner<2, 2>(), mean));
    }
  }
  for (const auto s : r.sliver) out.slivers += s;
  return out;
}

}  // namespace gs::analysis
