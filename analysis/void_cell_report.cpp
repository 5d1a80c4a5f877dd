// Kuhn void cells of a 2D frame's motion (see void_cell_report.hpp).
#include "void_cell_report.hpp"

#include <stdexcept>
#include <unordered_map>

#include "errors.hpp"
#include "grain_size.hpp"

namespace gs::analysis {

VoidCellReport void_cell_report(const std::string& file, const FrameMotion& m, const Frame* to,
                                const VoidCellSpec& spec) {
  if (!m.frame.two_d) {
    throw InputError(file,
                     "void cells need a 2D frame (two_d is false); use `analyze strain "
                     "--slab-...` for 3D data");
  }
  VoidCellReport out;
  out.d50 = spec.d50 > 0.0 ? spec.d50 : d50(m.frame);
  // Particles without a match in the target frame get no motion: they are left out.
  Frame f = m.frame;
  std::vector<Eigen::Vector2d> v(f.particles.size(), Eigen::Vector2d::Zero());
  std::vector<std::uint8_t> matched(f.particles.size(), 0);
  for (std::size_t k = 0; k < m.index.size(); ++k) {
    v[static_cast<std::size_t>(m.index[k])] = m.u[k].head<2>();
    matched[static_cast<std::size_t>(m.index[k])] = 1;
  }
  std::vector<Contact> kept;
  std::unordered_map<std::int64_t, std::size_t> by_id;
  for (std::size_t i = 0; i < f.particles.size(); ++i) by_id.emplace(f.particles[i].id, i);
  for (const auto& c : f.contacts) {
    const auto i1 = by_id.find(c.id1), i2 = by_id.find(c.id2);
    if (i1 != by_id.end() && i2 != by_id.end() && (!matched[i1->second] || !matched[i2->second]))
      continue;
    kept.push_back(c);
  }
  f.contacts = kept;
  ParticleGraph& g = out.graph;
  VoidCellGraph& cells = out.cells;
  try {
    g = particle_graph(f);
    cells = find_void_cells(g);
    if (cells.euler() != cells.expected_euler) {
      throw InputError(file,
                       "particle graph is not planar: Euler L - M + N = " +
                           std::to_string(cells.euler()) + ", expected",
                       std::to_string(cells.expected_euler));
    }
    // Periodic images move with the cell: from velocities the cell velocity gradient the frame
    // records (or the one given); between frames the change of the cell.
    const bool displacement = m.kind == "displacement";
    Eigen::Matrix2d rate = Eigen::Matrix2d::Zero();
    if (f.domain.periodic && !displacement)
      rate = f.domain.velocity_gradient.topLeftCorner<2, 2>() * f.domain.cell.topLeftCorner<2, 2>();
    if (spec.cell_velocity_gradient) {
      if (displacement)
        throw InputError(file, "--cell-velocity-gradient is for velocities, not --to");
      rate = *spec.cell_velocity_gradient * f.domain.cell.topLeftCorner<2, 2>();
    }
    if (displacement && f.domain.periodic) {
      if (!to) throw InputError(file, "a periodic cell's displacement needs the target frame");
      rate = (to->domain.cell - f.domain.cell).topLeftCorner<2, 2>();
    }
    out.deformation = void_cell_deformation(g, cells, v, out.d50, rate);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  out.offsets.push_back(0);
  for (const auto& c : cells.cells) {
    for (std::size_t k = 0; k < c.vertices.size(); ++k) {
      out.vertices.push_back(c.vertices[k]);
      out.polygon.push_back(g.position[static_cast<std::size_t>(c.vertices[k])] +
                            g.cell * c.image[k].cast<double>());
    }
    out.offsets.push_back(static_cast<std::int64_t>(out.vertices.size()));
  }
  for (const auto& p : f.particles) out.id.push_back(p.id);
  return out;
}

}  // namespace gs::analysis
