// `granoscope analyze strain` (Delaunay tetrahedra in 3D, triangles in 2D or on a projected
// slab) and `granoscope analyze voidcells` (2D Kuhn void cells, seed 002). Motion between two
// frames of a RUN.h5 matched by particle id, or the velocities of one frame. Outputs: HDF5
// (root attribute format = granoscope-strain / granoscope-voidcells, for `granoscope figures`)
// and optionally VTU, each written under a temporary name and renamed.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_motion.hpp"
#include "slab_options.hpp"
#include "snapshot.hpp"
#include "strain_report.hpp"
#include "void_cell_report.hpp"

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

void write_strain_vtu(const fs::path& path, const analysis::StrainReport& s) {
  const SimplexStrain& r = s.strain;
  std::vector<std::vector<std::int64_t>> cells;
  for (const auto& t : r.simplices) cells.emplace_back(t.begin(), t.begin() + r.dim + 1);
  const std::vector<double> sliver(r.sliver.begin(), r.sliver.end());
  const std::vector<double> valid(r.particle_valid.begin(), r.particle_valid.end());
  write_vtu_mesh(path, s.position, r.dim == 3 ? 10 : 5, cells,
                 {{"volumetric_strain", 1, s.volumetric},
                  {"equivalent_shear_strain", 1, s.shear},
                  {"valid", 1, valid},
                  {"gradient", 9, flat(r.particle_gradient, 3)}},
                 {{"volumetric_strain", 1, s.simplex_volumetric},
                  {"equivalent_shear_strain", 1, s.simplex_shear},
                  {"quality", 1, r.quality},
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
  analysis::StrainSpec spec;
};

void run_strain(const StrainArgs& a) {
  if (!(a.spec.min_quality >= 0.0 && a.spec.min_quality < 1.0)) {  // before reading the file
    throw InputError(a.input, "--min-quality must be in [0, 1)", value_str(a.spec.min_quality));
  }
  const FrameMotion m = read_frame_motion(a.input, a.from, a.to);
  const analysis::StrainReport s = analysis::strain_report(a.input, m, a.spec);
  const SimplexStrain& r = s.strain;
  H5FieldFile h(a.output, "granoscope-strain");
  h.attr("source", a.input);
  h.attr("motion", m.kind);
  h.attr("dim", static_cast<long long>(r.dim));
  h.attr("frame_from", static_cast<long long>(a.from));
  h.attr("frame_to", static_cast<long long>(a.to.value_or(-1)));
  h.attr("min_quality", a.spec.min_quality);
  h.attr("slab", static_cast<long long>(s.slab ? 1 : 0));
  h.attr("weighted", static_cast<long long>(s.weighted ? 1 : 0));
  h.group("/particles");
  h.group("/simplices");
  h.write("/particles/id", s.id);
  h.write("/particles/position", s.position);
  write_rows(h, "/particles/gradient", flat(r.particle_gradient, 3), 9);
  h.write("/particles/valid", r.particle_valid);
  h.write("/particles/volumetric_strain", s.volumetric);
  h.write("/particles/equivalent_shear_strain", s.shear);
  h.write("/particles/rotation_xy", s.rotation_xy);
  std::vector<std::int32_t> simp;
  for (const auto& t : r.simplices)
    for (int k = 0; k < r.dim + 1; ++k) simp.push_back(t[static_cast<std::size_t>(k)]);
  write_rows(h, "/simplices/vertices", simp, static_cast<std::size_t>(r.dim + 1));
  h.write("/simplices/measure", r.measure);
  h.write("/simplices/quality", r.quality);
  h.write("/simplices/sliver", r.sliver);
  write_rows(h, "/simplices/gradient", flat(r.gradient, 3), 9);
  write_rows(h, "/mean_gradient", flat({r.mean_gradient}, 3), 3);
  if (r.dim == 2) {
    h.write("/simplices/alpha", s.alpha);
    h.write("/simplices/w", s.w);
  }
  h.commit();
  if (!a.vtu.empty()) write_strain_vtu(a.vtu, s);
  std::cout << "strain: " << s.id.size() << " particles, " << r.simplices.size()
            << (r.dim == 3 ? " tetrahedra" : " triangles") << " (" << s.slivers
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
  std::optional<Frame> to;
  if (a.to && m.frame.two_d && m.frame.domain.periodic) to = read_frame(a.input, *a.to);
  analysis::VoidCellSpec spec;
  spec.d50 = a.d50;
  if (a.cell_gradient.size() == 4)
    spec.cell_velocity_gradient = Eigen::Matrix2d{{a.cell_gradient[0], a.cell_gradient[1]},
                                                  {a.cell_gradient[2], a.cell_gradient[3]}};
  const analysis::VoidCellReport r =
      analysis::void_cell_report(a.input, m, to ? &*to : nullptr, spec);
  const auto& cells = r.cells;
  const auto& d = r.deformation;
  H5FieldFile h(a.output, "granoscope-voidcells");
  h.attr("source", a.input);
  h.attr("motion", m.kind);
  h.attr("frame_from", static_cast<long long>(a.from));
  h.attr("frame_to", static_cast<long long>(a.to.value_or(-1)));
  h.attr("d50", r.d50);
  h.attr("faces", static_cast<long long>(cells.faces));
  h.attr("edges", static_cast<long long>(cells.edges));
  h.attr("vertices", static_cast<long long>(cells.vertices));
  h.attr("euler", static_cast<long long>(cells.euler()));
  h.attr("removed_isolated", static_cast<long long>(cells.removed_isolated));
  h.attr("removed_pendant", static_cast<long long>(cells.removed_pendant));
  h.attr("removed_peninsular", static_cast<long long>(cells.removed_peninsular));
  h.attr("removed_island", static_cast<long long>(cells.removed_island));
  h.attr("periodic", static_cast<long long>(r.graph.periodic ? 1 : 0));
  h.group("/cells");
  h.group("/particles");
  std::vector<double> poly, area, centroid, grad;
  for (const auto& p : r.polygon) poly.insert(poly.end(), {p.x(), p.y()});
  for (std::size_t i = 0; i < cells.cells.size(); ++i) {
    const auto& c = cells.cells[i];
    area.push_back(c.area);
    centroid.insert(centroid.end(), {c.centroid.x(), c.centroid.y()});
    for (int row = 0; row < 2; ++row)
      for (int q = 0; q < 2; ++q) grad.push_back(d.gradient[i](row, q));
  }
  h.write("/cells/offsets", r.offsets);
  h.write("/cells/vertices", r.vertices);
  write_rows(h, "/cells/polygon", poly, 2);
  h.write("/cells/area", area);
  write_rows(h, "/cells/centroid", centroid, 2);
  write_rows(h, "/cells/gradient", grad, 4);
  h.write("/cells/alpha", d.alpha);
  h.write("/cells/w", d.w);
  std::vector<double> pos, vrel;
  for (std::size_t k = 0; k < r.id.size(); ++k) {
    pos.insert(pos.end(), {r.graph.position[k].x(), r.graph.position[k].y()});
    vrel.insert(vrel.end(), {d.relative_velocity[k].x(), d.relative_velocity[k].y()});
  }
  h.write("/particles/id", r.id);
  write_rows(h, "/particles/position", pos, 2);
  h.write("/particles/active", cells.vertex_active);
  write_rows(h, "/particles/relative_velocity", vrel, 2);
  std::vector<double> mean{d.mean(0, 0), d.mean(0, 1), d.mean(1, 0), d.mean(1, 1)};
  write_rows(h, "/mean_gradient", mean, 2);
  h.attr("relative_velocity_scale", d.relative_velocity_scale);
  h.commit();
  if (!a.vtu.empty() && !cells.cells.empty()) {
    write_voidcells_vtu(a.vtu, poly, r.offsets,
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
    s->add_option("--min-quality", a->spec.min_quality,
                  "simplices of lower quality are slivers, excluded from averages (0.02)");
    s->add_flag("--weighted", a->spec.weighted,
                "3D: regular (weighted Delaunay) triangulation with weights radius^2");
    add_slab_options(s, a->spec.slab);
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
