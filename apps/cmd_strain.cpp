// `granoscope analyze strain` (Delaunay tetrahedra in 3D, triangles in 2D or on a projected
// slab) and `granoscope analyze voidcells` (2D Kuhn void cells, seed 002). Motion between two
// frames of a RUN.h5 matched by particle id, or the velocities of one frame. Outputs: HDF5
// (root attribute format = granoscope-strain / granoscope-voidcells, for `granoscope figures`)
// and optionally VTU, each written under a temporary name and renamed.

#include <CLI/CLI.hpp>
#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_motion.hpp"
#include "grain_size.hpp"
#include "hdf5_trajectory.hpp"
#include "kuhn_void_cells.hpp"
#include "particle_graph.hpp"
#include "slab_options.hpp"
#include "slab_projection.hpp"
#include "snapshot.hpp"
#include "tet_strain.hpp"

namespace gs::cli {
namespace {

namespace fs = std::filesystem;
using analysis::SimplexStrain;

// ---- outputs ------------------------------------------------------------------------------

/// Row-major n × cols dataset.
template <class T>
void write_rows(H5FieldFile& h, const std::string& name, const std::vector<T>& v,
                std::size_t cols) {
  h.write(name, v, {cols > 0 ? v.size() / cols : 0, cols});
}

std::vector<double> flat(const std::vector<Eigen::Matrix3d>& m, int dim) {
  std::vector<double> out;
  out.reserve(m.size() * static_cast<std::size_t>(dim * dim));
  for (const auto& a : m)
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) out.push_back(a(i, j));  // row-major H_ij
  return out;
}

void write_strain_vtu(const fs::path& path, const std::vector<Eigen::Vector3d>& x,
                      const SimplexStrain& r) {
  std::vector<std::vector<std::int64_t>> cells;
  for (const auto& s : r.simplices) cells.emplace_back(s.begin(), s.begin() + r.dim + 1);
  std::vector<double> vol, shear, sliver, quality;
  for (std::size_t t = 0; t < r.simplices.size(); ++t) {
    const auto m = analysis::strain_measures(r.gradient[t], r.dim);
    vol.push_back(m.volumetric);
    shear.push_back(m.equivalent_shear);
    sliver.push_back(r.sliver[t]);
    quality.push_back(r.quality[t]);
  }
  std::vector<double> pvol, pshear, valid;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const auto m = analysis::strain_measures(r.particle_gradient[i], r.dim);
    pvol.push_back(m.volumetric);
    pshear.push_back(m.equivalent_shear);
    valid.push_back(r.particle_valid[i]);
  }
  write_vtu_mesh(path, x, r.dim == 3 ? 10 : 5, cells,
                 {{"volumetric_strain", 1, pvol},
                  {"equivalent_shear_strain", 1, pshear},
                  {"valid", 1, valid},
                  {"gradient", 9, flat(r.particle_gradient, 3)}},
                 {{"volumetric_strain", 1, vol},
                  {"equivalent_shear_strain", 1, shear},
                  {"quality", 1, quality},
                  {"sliver", 1, sliver},
                  {"gradient", 9, flat(r.gradient, 3)}});
}

void write_voidcells_vtu(const fs::path& path, const std::vector<double>& polygon,
                         const std::vector<std::int64_t>& offsets,
                         const std::vector<std::pair<const char*, std::vector<double>>>& data) {
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t i = 0; i + 1 < polygon.size(); i += 2)
    pts.emplace_back(polygon[i], polygon[i + 1], 0.0);
  std::vector<std::vector<std::int64_t>> cells;
  for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
    cells.emplace_back();
    for (auto k = offsets[c]; k < offsets[c + 1]; ++k) cells.back().push_back(k);
  }
  std::vector<VtkArray> cell_data;
  for (const auto& [name, values] : data)
    cell_data.push_back({name, static_cast<int>(values.size() / cells.size()), values});
  write_vtu_mesh(path, pts, 7, cells, {}, cell_data);
}

// ---- strain -------------------------------------------------------------------------------

struct StrainArgs {
  std::string input, output, vtu;
  long from = 0;
  std::optional<long> to;
  double min_quality = 0.02;
  SlabArgs slab;
  bool weighted = false;
};

void run_strain(const StrainArgs& a) {
  if (!(a.min_quality >= 0.0 && a.min_quality < 1.0)) {
    throw InputError(a.input, "--min-quality must be in [0, 1)", value_str(a.min_quality));
  }
  const FrameMotion m = read_frame_motion(a.input, a.from, a.to);
  const bool slab = a.slab.any();
  SimplexStrain r;
  std::vector<std::int32_t> index = m.index;
  std::vector<Eigen::Vector3d> x3;
  analysis::SimplexStrainOptions options;
  options.min_quality = a.min_quality;
  try {
    if (m.frame.two_d || slab) {
      std::vector<Eigen::Vector2d> x2, u2;
      if (slab) {
        if (m.frame.two_d) throw InputError(a.input, "--slab needs a 3D frame");
        const auto p = analysis::project_slab(m.x, m.u, make_slab(a.slab, m.frame));
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
      r = analysis::triangle_strain(x2, u2, options);
      for (const auto& p : x2) x3.emplace_back(p.x(), p.y(), 0.0);
    } else {
      if (a.weighted) {
        for (const auto k : m.index)
          options.radii.push_back(m.frame.particles[static_cast<std::size_t>(k)].radius);
      }
      r = analysis::tet_strain(m.x, m.u, options);
      x3 = m.x;
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(a.input, e.what());
  }
  H5FieldFile h(a.output, "granoscope-strain");
  h.attr("source", a.input);
  h.attr("motion", m.kind);
  h.attr("dim", static_cast<long long>(r.dim));
  h.attr("frame_from", static_cast<long long>(a.from));
  h.attr("frame_to", static_cast<long long>(a.to.value_or(-1)));
  h.attr("min_quality", a.min_quality);
  h.attr("slab", static_cast<long long>(slab ? 1 : 0));
  h.attr("weighted", static_cast<long long>(options.radii.empty() ? 0 : 1));
  h.group("/particles");
  h.group("/simplices");
  std::vector<std::int64_t> ids;
  std::vector<double> pos, vol, shear, rot;
  for (std::size_t i = 0; i < index.size(); ++i) {
    ids.push_back(m.frame.particles[static_cast<std::size_t>(index[i])].id);
    for (int c = 0; c < 3; ++c) pos.push_back(x3[i](c));
    const auto s = analysis::strain_measures(r.particle_gradient[i], r.dim);
    vol.push_back(s.volumetric);
    shear.push_back(s.equivalent_shear);
    rot.push_back(s.rotation(1, 0));  // in-plane rotation (about z); 3D: see gradient
  }
  h.write("/particles/id", ids);
  write_rows(h, "/particles/position", pos, 3);
  write_rows(h, "/particles/gradient", flat(r.particle_gradient, 3), 9);
  h.write("/particles/valid", r.particle_valid);
  h.write("/particles/volumetric_strain", vol);
  h.write("/particles/equivalent_shear_strain", shear);
  h.write("/particles/rotation_xy", rot);
  std::vector<std::int32_t> simp;
  for (const auto& s : r.simplices)
    for (int k = 0; k < r.dim + 1; ++k) simp.push_back(s[static_cast<std::size_t>(k)]);
  write_rows(h, "/simplices/vertices", simp, static_cast<std::size_t>(r.dim + 1));
  h.write("/simplices/measure", r.measure);
  h.write("/simplices/quality", r.quality);
  h.write("/simplices/sliver", r.sliver);
  write_rows(h, "/simplices/gradient", flat(r.gradient, 3), 9);
  write_rows(h, "/mean_gradient", flat({r.mean_gradient}, 3), 3);
  if (r.dim == 2) {  // triangle (Bagi eq 4) variant of seed 002's alpha and w maps
    std::vector<double> alpha, w;
    const Eigen::Matrix2d mean = r.mean_gradient.topLeftCorner<2, 2>();
    for (const auto& gt : r.gradient) {
      alpha.push_back(analysis::alignment(gt.topLeftCorner<2, 2>(), mean));
      w.push_back(analysis::normalised_vorticity(gt.topLeftCorner<2, 2>(), mean));
    }
    h.write("/simplices/alpha", alpha);
    h.write("/simplices/w", w);
  }
  h.commit();
  if (!a.vtu.empty()) write_strain_vtu(a.vtu, x3, r);
  std::size_t slivers = 0;
  for (auto s : r.sliver) slivers += s;
  std::cout << "strain: " << index.size() << " particles, " << r.simplices.size()
            << (r.dim == 3 ? " tetrahedra" : " triangles") << " (" << slivers
            << " slivers), time delaunay " << r.seconds_delaunay << " s, gradients "
            << r.seconds_gradients << " s, averaging " << r.seconds_averaging << " s\n";
}

// ---- voidcells ----------------------------------------------------------------------------

struct VoidArgs {
  std::string input, output, vtu;
  long from = 0;
  std::optional<long> to;
  double d50 = 0.0;
  std::vector<double> cell_gradient;  // velocity gradient of a periodic cell, row-major 2x2
};

void run_voidcells(const VoidArgs& a) {
  const FrameMotion m = read_frame_motion(a.input, a.from, a.to);
  if (!m.frame.two_d) {
    throw InputError(a.input,
                     "void cells need a 2D frame (two_d is false); use `analyze strain "
                     "--slab-...` for 3D data");
  }
  const double d50 = a.d50 > 0.0 ? a.d50 : analysis::d50(m.frame);
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
  analysis::VoidCellGraph cells;
  analysis::VoidCellDeformation d;
  analysis::ParticleGraph g;
  try {
    g = analysis::particle_graph(f);
    cells = analysis::find_void_cells(g);
    if (cells.euler() != cells.expected_euler) {
      throw InputError(a.input,
                       "particle graph is not planar: Euler L - M + N = " +
                           std::to_string(cells.euler()) + ", expected",
                       std::to_string(cells.expected_euler));
    }
    // Periodic images move with the cell: from velocities the cell velocity gradient the frame
    // records (or the one given on the command line); between frames the change of the cell.
    Eigen::Matrix2d rate = Eigen::Matrix2d::Zero();
    if (f.domain.periodic && !a.to)
      rate = f.domain.velocity_gradient.topLeftCorner<2, 2>() * f.domain.cell.topLeftCorner<2, 2>();
    if (a.cell_gradient.size() == 4) {
      if (a.to) throw InputError(a.input, "--cell-velocity-gradient is for velocities, not --to");
      const Eigen::Matrix2d lc{{a.cell_gradient[0], a.cell_gradient[1]},
                               {a.cell_gradient[2], a.cell_gradient[3]}};
      rate = lc * f.domain.cell.topLeftCorner<2, 2>();
    }
    if (a.to && f.domain.periodic) {
      const Frame t = read_frame(a.input, *a.to);
      rate = (t.domain.cell - f.domain.cell).topLeftCorner<2, 2>();
    }
    d = analysis::void_cell_deformation(g, cells, v, d50, rate);
  } catch (const std::invalid_argument& e) {
    throw InputError(a.input, e.what());
  }
  H5FieldFile h(a.output, "granoscope-voidcells");
  h.attr("source", a.input);
  h.attr("motion", m.kind);
  h.attr("frame_from", static_cast<long long>(a.from));
  h.attr("frame_to", static_cast<long long>(a.to.value_or(-1)));
  h.attr("d50", d50);
  h.attr("faces", static_cast<long long>(cells.faces));
  h.attr("edges", static_cast<long long>(cells.edges));
  h.attr("vertices", static_cast<long long>(cells.vertices));
  h.attr("euler", static_cast<long long>(cells.euler()));
  h.attr("removed_isolated", static_cast<long long>(cells.removed_isolated));
  h.attr("removed_pendant", static_cast<long long>(cells.removed_pendant));
  h.attr("removed_peninsular", static_cast<long long>(cells.removed_peninsular));
  h.attr("removed_island", static_cast<long long>(cells.removed_island));
  h.attr("periodic", static_cast<long long>(g.periodic ? 1 : 0));
  h.group("/cells");
  h.group("/particles");
  std::vector<std::int64_t> offsets{0};
  std::vector<std::int32_t> verts;
  std::vector<double> poly, area, centroid, grad, alpha, w;
  for (std::size_t i = 0; i < cells.cells.size(); ++i) {
    const auto& c = cells.cells[i];
    for (std::size_t k = 0; k < c.vertices.size(); ++k) {
      verts.push_back(c.vertices[k]);
      const Eigen::Vector2d p =
          g.position[static_cast<std::size_t>(c.vertices[k])] + g.cell * c.image[k].cast<double>();
      poly.push_back(p.x());
      poly.push_back(p.y());
    }
    offsets.push_back(static_cast<std::int64_t>(verts.size()));
    area.push_back(c.area);
    centroid.push_back(c.centroid.x());
    centroid.push_back(c.centroid.y());
    for (int r = 0; r < 2; ++r)
      for (int q = 0; q < 2; ++q) grad.push_back(d.gradient[i](r, q));
  }
  h.write("/cells/offsets", offsets);
  h.write("/cells/vertices", verts);
  write_rows(h, "/cells/polygon", poly, 2);
  h.write("/cells/area", area);
  write_rows(h, "/cells/centroid", centroid, 2);
  write_rows(h, "/cells/gradient", grad, 4);
  h.write("/cells/alpha", d.alpha);
  h.write("/cells/w", d.w);
  std::vector<std::int64_t> ids;
  std::vector<double> pos, vrel;
  for (std::size_t k = 0; k < f.particles.size(); ++k) {
    ids.push_back(f.particles[k].id);
    pos.push_back(g.position[k].x());
    pos.push_back(g.position[k].y());
    vrel.push_back(d.relative_velocity[k].x());
    vrel.push_back(d.relative_velocity[k].y());
  }
  h.write("/particles/id", ids);
  write_rows(h, "/particles/position", pos, 2);
  h.write("/particles/active", cells.vertex_active);
  write_rows(h, "/particles/relative_velocity", vrel, 2);
  std::vector<double> mean{d.mean(0, 0), d.mean(0, 1), d.mean(1, 0), d.mean(1, 1)};
  write_rows(h, "/mean_gradient", mean, 2);
  h.attr("relative_velocity_scale", d.relative_velocity_scale);
  h.commit();
  if (!a.vtu.empty() && !cells.cells.empty()) {
    write_voidcells_vtu(a.vtu, poly, offsets,
                        {{"area", area}, {"alpha", d.alpha}, {"w", d.w}, {"gradient", grad}});
  }
  std::cout << "voidcells: L " << cells.faces << " M " << cells.edges << " N " << cells.vertices
            << " (Euler " << cells.euler() << "), removed isolated " << cells.removed_isolated
            << " pendant " << cells.removed_pendant << " peninsular " << cells.removed_peninsular
            << " island " << cells.removed_island << "\n";
}

}  // namespace

void register_analyze_strain(CLI::App& app) {
  auto& analyze = analyze_command(app);
  {
    auto a = std::make_shared<StrainArgs>();
    auto* s = analyze.add_subcommand(
        "strain",
        "Local strain on a Delaunay mesh of particle centres (3D tetrahedra, 2D "
        "triangles, or a slab projected onto its plane)");
    s->add_option("input", a->input, "RUN.h5 trajectory")->required();
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-strain)")->required();
    s->add_option("--vtu", a->vtu, "also write a VTU mesh with cell and point data");
    s->add_option("--from", a->from, "reference frame index (default 0)");
    s->add_option("--to", a->to,
                  "target frame: displacement from --from to --to matched by id; "
                  "without it the velocities of --from are used");
    s->add_option("--min-quality", a->min_quality,
                  "simplices of lower quality are slivers, excluded from averages (0.02)");
    s->add_flag("--weighted", a->weighted,
                "3D: regular (weighted Delaunay) triangulation with weights radius^2");
    add_slab_options(s, a->slab);
    s->callback([a] { run_strain(*a); });
  }
  {
    auto a = std::make_shared<VoidArgs>();
    auto* s = analyze.add_subcommand("voidcells",
                                     "Kuhn void cells of a 2D frame: per-cell velocity gradient, "
                                     "alignment alpha, vorticity w, relative velocity");
    s->add_option("input", a->input, "RUN.h5 trajectory (2D frames with contacts)")->required();
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-voidcells)")
        ->required();
    s->add_option("--from", a->from, "frame index (default 0)");
    s->add_option("--to", a->to, "target frame: displacements instead of velocities");
    s->add_option("--d50", a->d50, "D50 for eq 21 in m (default: from the frame)");
    s->add_option("--vtu", a->vtu, "also write the void-cell polygons with cell data (VTU)");
    s->add_option("--cell-velocity-gradient", a->cell_gradient,
                  "periodic cell, velocity mode: cell velocity gradient L11 L12 L21 L22 (1/s); "
                  "images of a particle move with v + L (cell shift) (default: the frame's)")
        ->expected(4);
    s->callback([a] { run_voidcells(*a); });
  }
}

}  // namespace gs::cli
