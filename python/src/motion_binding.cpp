// granoscope.strain, .voidcells, .hhd and .vortices: the analyses of a frame's motion (its
// velocities, or its displacement to frame `to`), through the same library calls as `granoscope
// analyze strain | voidcells | hhd | vortices` (analysis/strain_report.hpp, void_cell_report.hpp,
// vortex_field.hpp, vortex_count_series.hpp): same options, same numbers.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bindings.hpp"
#include "common.hpp"
#include "errors.hpp"
#include "frame_motion.hpp"
#include "strain_report.hpp"
#include "void_cell_report.hpp"
#include "vortex_count_series.hpp"
#include "vortex_field.hpp"

namespace py = pybind11;
namespace ga = gs::analysis;

namespace gs::py_bind {
namespace {

using OptD = std::optional<double>;

ga::ProjectionSlabSpec slab_spec(const OptVec& origin, const OptVec& normal, const OptVec& axis,
                                 OptD thickness, OptD slab_d50) {
  ga::ProjectionSlabSpec s;
  s.origin = origin.value_or(std::vector<double>{});
  s.normal = normal.value_or(std::vector<double>{});
  s.axis = axis.value_or(std::vector<double>{});
  if (thickness) {
    ga::require_positive(kFrame, "--slab-thickness", *thickness);
    s.thickness = *thickness;
  }
  if (slab_d50) {
    ga::require_positive(kFrame, "--slab-d50", *slab_d50);
    s.d50_multiple = *slab_d50;
  }
  for (const auto* v : {&s.origin, &s.normal, &s.axis})
    if (!v->empty() && v->size() != 3) throw InputError(kFrame, "slab vectors need 3 numbers");
  return s;
}

py::array_t<double> matrix_rows(const Eigen::MatrixXd& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) out.mutable_at(i, j) = m(i, j);
  return out;
}

template <std::size_t N>
py::array_t<std::int32_t> simplices(const std::vector<std::array<std::int32_t, N>>& s, int dim) {
  std::vector<std::int32_t> flat;
  for (const auto& t : s) flat.insert(flat.end(), t.begin(), t.begin() + dim + 1);
  return array2(flat, static_cast<std::size_t>(dim + 1));
}

ga::VortexFieldSpec field_spec(bool slice, const OptVec& slab_origin, const OptVec& slab_normal,
                               const OptVec& slab_axis, OptD slab_thickness, OptD slab_d50,
                               bool ghosts, OptD ghost_spacing, OptD ghost_min_distance,
                               OptD ghost_extent, OptD ghost_radius, OptD d50,
                               const std::string& solver, OptD tolerance, int max_iterations,
                               const OptVec& axis, double delta, double significance,
                               double significance_abs) {
  ga::VortexFieldSpec s;
  s.slab = slab_spec(slab_origin, slab_normal, slab_axis, slab_thickness, slab_d50);
  s.slice = slice;
  s.ghosts = ghosts;
  s.ghost_spacing = ghost_spacing.value_or(0.0);
  s.ghost_min_distance = ghost_min_distance.value_or(-1.0);
  s.ghost_extent = ghost_extent.value_or(0.0);
  s.ghost_radius = ghost_radius.value_or(0.0);
  if (d50) {
    ga::require_positive(kFrame, "--d50", *d50);
    s.d50 = *d50;
  }
  s.solver = solver;
  s.tolerance = tolerance;
  s.max_iterations = max_iterations;
  s.axis = axis.value_or(std::vector<double>{});
  s.delta = delta;
  s.significance = significance;
  s.significance_abs = significance_abs;
  s.poll = raise_pending_signal;  // between the phases and the projection solver's iterations
  return s;
}

py::dict hhd_dict(const ga::VortexAnalysis& r, const ga::VortexField& f,
                  const ga::VortexAnalysisOptions& o) {
  const auto& h = r.hhd;
  py::dict nodes;
  nodes["position"] = rows3(r.mesh.points);
  nodes["vector"] = rows3(r.vectors);
  std::vector<std::int64_t> id = f.id;
  id.resize(r.mesh.points.size(), -1);  // ghosts: id -1
  nodes["id"] = array1(id);
  nodes["u"] = array1(std::vector<double>(h.u.data(), h.u.data() + h.u.size()));
  nodes["v"] = matrix_rows(h.v);
  nodes["v_coulomb"] = matrix_rows(h.v_coulomb);
  std::vector<std::uint8_t> ghost(r.mesh.points.size(), 0);
  for (std::size_t i = r.true_nodes; i < ghost.size(); ++i) ghost[i] = 1;
  nodes["ghost"] = array1(ghost);
  nodes["dirichlet"] = array1(r.mesh.dirichlet);
  py::dict simp;
  simp["vertices"] = simplices(r.mesh.simplices, r.mesh.dim);
  simp["measure"] = array1(h.measure);
  simp["xi"] = rows3(h.xi);
  simp["grad_u"] = rows3(h.grad_u);
  simp["curl_v"] = rows3(h.curl_v);
  simp["harmonic"] = rows3(h.harmonic);
  const ga::ExtremaColumns e = ga::extrema_columns(r);
  py::dict ext;
  ext["node"] = array1(e.node);
  ext["kind"] = array1(e.kind);
  ext["value"] = array1(e.value);
  ext["magnitude"] = array1(e.magnitude);
  ext["significant"] = array1(e.significant);
  ext["position"] = rows3(e.position);
  ext["v"] = rows3(e.v);
  const ga::TubeColumns t = ga::tube_columns(r);
  py::dict tubes;
  tubes["offsets"] = array1(t.offsets);
  tubes["nodes"] = array1(t.nodes);
  tubes["extremum"] = array1(t.extremum);
  const auto sig = ga::count_extrema(r.extrema, true);
  const auto all = ga::count_extrema(r.extrema, false);
  py::dict counts;
  const char* names[4] = {"right", "left", "sources", "sinks"};
  for (std::size_t q = 0; q < 4; ++q) {
    counts[names[q]] = sig[q];
    counts[(std::string(names[q]) + "_all").c_str()] = all[q];
  }
  counts["tubes"] = ga::count_significant_tubes(r.tubes, r.extrema);
  py::dict rep;
  rep["solver"] = h.report.solver;
  rep["unknowns"] = h.report.unknowns;
  rep["iterations_u"] = h.report.iterations_u;
  rep["iterations_v"] = h.report.iterations_v;
  rep["converged"] = h.report.converged;
  rep["residual_eq17"] = h.report.residual_eq17;
  rep["residual_eq18"] = h.report.residual_eq18;
  rep["tolerance"] = h.report.tolerance;
  rep["seconds_ghosts"] = r.seconds_ghosts;
  rep["seconds_delaunay"] = r.seconds_delaunay;
  rep["seconds_assembly"] = h.report.seconds_assembly;
  rep["seconds_factor"] = h.report.seconds_factor;
  rep["seconds_solve"] = h.report.seconds_solve;
  rep["seconds_detection"] = r.seconds_detection;
  py::dict out;
  out["dim"] = h.dim;
  out["d50"] = f.d50;
  out["ghosts"] = r.mesh.points.size() - r.true_nodes;
  if (o.ghosts) {
    out["ghost_spacing"] = o.ghost.spacing;
    out["ghost_min_distance"] = o.ghost.min_distance;
    out["ghost_extent"] = o.ghost.extent;
    out["ghost_radius"] = o.ghost.radius;
  }
  out["norm_xi"] = h.norm_xi;
  out["norm_grad_u"] = h.norm_grad_u;
  out["norm_curl_v"] = h.norm_curl_v;
  out["norm_harmonic"] = h.norm_harmonic;
  out["norm_div_v"] = h.norm_div_v;
  out["dot_grad_curl"] = h.dot_grad_curl;
  out["dot_grad_harmonic"] = h.dot_grad_harmonic;
  out["dot_curl_harmonic"] = h.dot_curl_harmonic;
  out["report"] = rep;
  out["counts"] = counts;
  out["nodes"] = nodes;
  out["simplices"] = simp;
  out["extrema"] = ext;
  out["tubes"] = tubes;
  if (f.slab) {
    py::dict slab;
    slab["origin"] = Eigen::Vector3d(f.plane.origin);
    slab["axes"] = rows3({f.e1, f.e2});
    slab["thickness"] = f.plane.thickness;
    out["slab"] = slab;
  }
  return out;
}

}  // namespace

void bind_motion(py::module_& m) {
  m.def(
      "strain",
      [](const Frame& f, std::optional<Frame> to, double min_quality, bool weighted,
         OptVec slab_origin, OptVec slab_normal, OptVec slab_axis, OptD slab_thickness,
         OptD slab_d50) {
        ga::StrainSpec spec;
        spec.min_quality = min_quality;
        spec.weighted = weighted;
        spec.slab = slab_spec(slab_origin, slab_normal, slab_axis, slab_thickness, slab_d50);
        ga::StrainReport s;
        std::string kind;
        {
          py::gil_scoped_release unlocked;
          const FrameMotion mo = frame_motion(f, to ? &*to : nullptr, kFrame);
          kind = mo.kind;
          s = ga::strain_report(kFrame, mo, spec);
        }
        const auto& r = s.strain;
        py::dict particles;
        particles["id"] = array1(s.id);
        particles["position"] = rows3(s.position);
        particles["gradient"] = mats3(r.particle_gradient);
        particles["valid"] = array1(r.particle_valid);
        particles["volumetric_strain"] = array1(s.volumetric);
        particles["equivalent_shear_strain"] = array1(s.shear);
        particles["rotation_xy"] = array1(s.rotation_xy);
        py::dict simp;
        simp["vertices"] = simplices(r.simplices, r.dim);
        simp["measure"] = array1(r.measure);
        simp["quality"] = array1(r.quality);
        simp["sliver"] = array1(r.sliver);
        simp["gradient"] = mats3(r.gradient);
        simp["volumetric_strain"] = array1(s.simplex_volumetric);
        simp["equivalent_shear_strain"] = array1(s.simplex_shear);
        if (r.dim == 2) {
          simp["alpha"] = array1(s.alpha);
          simp["w"] = array1(s.w);
        }
        py::dict out;
        out["motion"] = kind;
        out["dim"] = r.dim;
        out["slab"] = s.slab;
        out["weighted"] = s.weighted;
        out["slivers"] = s.slivers;
        out["mean_gradient"] = r.mean_gradient;
        out["particles"] = particles;
        out["simplices"] = simp;
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("to") = py::none(), py::arg("min_quality") = 0.02,
      py::arg("weighted") = false, py::arg("slab_origin") = py::none(),
      py::arg("slab_normal") = py::none(), py::arg("slab_axis") = py::none(),
      py::arg("slab_thickness") = py::none(), py::arg("slab_d50") = py::none(),
      "Local strain as `granoscope analyze strain`: the gradient H of the velocities of `frame` "
      "(1/s) or of its displacement to `to` (dimensionless) on Delaunay tetrahedra (3D), "
      "triangles (2D) or a slab projected onto its plane (slab_*: origin, normal, axis, "
      "thickness in m or slab_d50). particles: id, position (m; slab: in-plane), gradient (n, 3, "
      "3), volumetric and equivalent shear strain, rotation_xy; simplices: vertices, measure "
      "(m^3 / m^2), quality, sliver, gradient, and in 2D seed 002's alpha and w.");

  m.def(
      "voidcells",
      [](const Frame& f, std::optional<Frame> to, OptD d50,
         std::optional<Eigen::Matrix2d> cell_velocity_gradient) {
        ga::VoidCellSpec spec;
        if (d50) {
          ga::require_positive(kFrame, "--d50", *d50);
          spec.d50 = *d50;
        }
        if (cell_velocity_gradient && !cell_velocity_gradient->allFinite())
          throw InputError(kFrame, "--cell-velocity-gradient must be 4 finite numbers");
        spec.cell_velocity_gradient = cell_velocity_gradient;
        ga::VoidCellReport r;
        std::string kind;
        {
          py::gil_scoped_release unlocked;
          const FrameMotion mo = frame_motion(f, to ? &*to : nullptr, kFrame);
          kind = mo.kind;
          r = ga::void_cell_report(kFrame, mo, to ? &*to : nullptr, spec);
        }
        const auto& c = r.cells;
        const auto& d = r.deformation;
        std::vector<double> area, grad;
        std::vector<Eigen::Vector2d> centroid;
        for (std::size_t i = 0; i < c.cells.size(); ++i) {
          area.push_back(c.cells[i].area);
          centroid.push_back(c.cells[i].centroid);
          for (int row = 0; row < 2; ++row)
            for (int q = 0; q < 2; ++q) grad.push_back(d.gradient[i](row, q));
        }
        py::dict cells;
        cells["offsets"] = array1(r.offsets);
        cells["vertices"] = array1(r.vertices);
        cells["polygon"] = rows2(r.polygon);
        cells["area"] = array1(area);
        cells["centroid"] = rows2(centroid);
        auto g = array2(grad, 4);
        cells["gradient"] =
            g.reshape({static_cast<py::ssize_t>(area.size()), py::ssize_t{2}, py::ssize_t{2}});
        cells["alpha"] = array1(d.alpha);
        cells["w"] = array1(d.w);
        py::dict particles;
        particles["id"] = array1(r.id);
        particles["position"] = rows2(r.graph.position);
        particles["active"] = array1(c.vertex_active);
        particles["relative_velocity"] = rows2(d.relative_velocity);
        py::dict out;
        out["motion"] = kind;
        out["d50"] = r.d50;
        out["faces"] = c.faces;
        out["edges"] = c.edges;
        out["vertices"] = c.vertices;
        out["euler"] = c.euler();
        out["removed_isolated"] = c.removed_isolated;
        out["removed_pendant"] = c.removed_pendant;
        out["removed_peninsular"] = c.removed_peninsular;
        out["removed_island"] = c.removed_island;
        out["periodic"] = r.graph.periodic;
        out["mean_gradient"] = Eigen::Matrix2d(d.mean);
        out["relative_velocity_scale"] = d.relative_velocity_scale;
        out["cells"] = cells;
        out["particles"] = particles;
        return out;
      },
      py::arg("frame"), py::kw_only(), py::arg("to") = py::none(), py::arg("d50") = py::none(),
      py::arg("cell_velocity_gradient") = py::none(),
      "Kuhn void cells of a 2D frame as `granoscope analyze voidcells` (seed 002): L, M, N and "
      "the removals of Fig. 4; per cell its polygon (cell c: polygon[offsets[c]:offsets[c+1]], "
      "m), area, velocity gradient L^i (eq 7; 1/s, or dimensionless with `to`), alignment alpha "
      "(eq 18) and vorticity w (eq 20); per particle the relative velocity of eq 21.");

  m.def(
      "hhd",
      [](std::optional<Frame> frame, std::optional<Frame> to, std::optional<Eigen::MatrixXd> points,
         std::optional<Eigen::MatrixXd> vectors, bool slice, OptVec slab_origin, OptVec slab_normal,
         OptVec slab_axis, OptD slab_thickness, OptD slab_d50, bool ghosts, OptD ghost_spacing,
         OptD ghost_min_distance, OptD ghost_extent, OptD ghost_radius, OptD d50,
         const std::string& solver, OptD tolerance, int max_iterations, OptVec axis, double delta,
         double significance, double significance_abs) {
        const ga::VortexFieldSpec spec =
            field_spec(slice, slab_origin, slab_normal, slab_axis, slab_thickness, slab_d50, ghosts,
                       ghost_spacing, ghost_min_distance, ghost_extent, ghost_radius, d50, solver,
                       tolerance, max_iterations, axis, delta, significance, significance_abs);
        if (frame.has_value() == (points.has_value() || vectors.has_value()))
          throw InputError(kFrame, "give either a frame or points and vectors");
        ga::VortexField field;
        if (points) {  // as `analyze hhd --csv`: nodes and vectors given
          if (!vectors) throw InputError(kFrame, "points need vectors");
          if (spec.projected())
            throw InputError(kFrame, "--slice/--slab need a frame (give 2D points instead)");
          const auto n = points->rows();
          if ((points->cols() != 2 && points->cols() != 3) || vectors->cols() != points->cols() ||
              vectors->rows() != n)
            throw InputError(kFrame, "points and vectors must be (n, 2) or (n, 3) alike");
          field.dim = static_cast<int>(points->cols());
          for (Eigen::Index i = 0; i < n; ++i) {
            Eigen::Vector3d x = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::Zero();
            x.head(field.dim) = points->row(i).transpose();
            u.head(field.dim) = vectors->row(i).transpose();
            field.x.push_back(x);
            field.u.push_back(u);
            field.id.push_back(i);
          }
        }
        ga::VortexAnalysisOptions o;
        ga::VortexAnalysis r;
        {
          py::gil_scoped_release unlocked;
          if (frame) {
            const FrameMotion mo = frame_motion(*frame, to ? &*to : nullptr, kFrame);
            field = ga::vortex_field(mo, spec, kFrame);
          }
          o = ga::vortex_analysis_options(spec, field, kFrame);
          r = ga::analyze_field(field, o, kFrame);
        }
        return hhd_dict(r, field, o);
      },
      py::arg("frame") = py::none(), py::kw_only(), py::arg("to") = py::none(),
      py::arg("points") = py::none(), py::arg("vectors") = py::none(), py::arg("slice") = false,
      py::arg("slab_origin") = py::none(), py::arg("slab_normal") = py::none(),
      py::arg("slab_axis") = py::none(), py::arg("slab_thickness") = py::none(),
      py::arg("slab_d50") = py::none(), py::arg("ghosts") = false,
      py::arg("ghost_spacing") = py::none(), py::arg("ghost_min_distance") = py::none(),
      py::arg("ghost_extent") = py::none(), py::arg("ghost_radius") = py::none(),
      py::arg("d50") = py::none(), py::arg("solver") = "auto", py::arg("tolerance") = py::none(),
      py::arg("max_iterations") = 10000, py::arg("axis") = py::none(), py::arg("delta") = 0.05,
      py::arg("significance") = ga::kSignificanceRelative, py::arg("significance_abs") = 0.0,
      "Helmholtz-Hodge decomposition as `granoscope analyze hhd` (seed 000 eqs 17-18): of the "
      "velocities of `frame` or its displacement to `to`, on the Delaunay mesh of the centres "
      "(3D, 2D, or slice=True / slab_*: a slab projected on its plane). nodes: position, vector, "
      "id (ghosts -1), u, v, v_coulomb; simplices: vertices, measure, xi, grad_u, curl_v, "
      "harmonic; extrema (kind 0 right vortex, 1 left, 2 source, 3 sink; position, value, "
      "significant), tubes (nodes[offsets[t]:offsets[t+1]]), counts, norms, solver report. "
      "Without a frame: points (n, 2|3) and vectors, as `analyze hhd --csv`.");

  m.def(
      "vortices",
      [](py::object run, long every, long stride, long from, std::optional<long> last,
         const std::string& strain_axis, bool slice, OptVec slab_origin, OptVec slab_normal,
         OptVec slab_axis, OptD slab_thickness, OptD slab_d50, bool ghosts, OptD ghost_spacing,
         OptD ghost_min_distance, OptD ghost_extent, OptD ghost_radius, OptD d50,
         const std::string& solver, OptD tolerance, int max_iterations, OptVec axis, double delta,
         double significance, double significance_abs, py::object progress) {
        ga::VortexSeriesSpec spec;
        spec.every = every;
        spec.stride = stride;
        spec.from = from;
        spec.last = last;
        spec.strain_axis = strain_axis;
        spec.field =
            field_spec(slice, slab_origin, slab_normal, slab_axis, slab_thickness, slab_d50, ghosts,
                       ghost_spacing, ghost_min_distance, ghost_extent, ghost_radius, d50, solver,
                       tolerance, max_iterations, axis, delta, significance, significance_abs);
        const auto n = static_cast<long>(py::len(run));
        // Frames are read through the trajectory (or list) with the GIL held; the decomposition
        // runs without it. A progress callable gets (frame_from, frame_to, strain, counts).
        const auto read = [&run](long i) {
          py::gil_scoped_acquire locked;
          return run[py::int_(i)].cast<Frame>();
        };
        const auto report = [&progress](const ga::VortexSeriesStep& p) {
          raise_pending_signal();
          py::gil_scoped_acquire locked;
          if (!progress.is_none())
            progress(p.from, p.to, p.strain,
                     py::make_tuple(p.counts[0], p.counts[1], p.counts[2], p.counts[3]));
        };
        ga::VortexCountSeries s;
        {
          py::gil_scoped_release unlocked;
          s = ga::vortex_count_series("<trajectory>", n, read, spec, report);
        }
        py::dict series;
        series["frame_from"] = array1(s.frame_from);
        series["frame_to"] = array1(s.frame_to);
        series["time"] = array1(s.time);
        series["strain"] = array1(s.strain);
        series["right"] = array1(s.right);
        series["left"] = array1(s.left);
        series["sources"] = array1(s.sources);
        series["sinks"] = array1(s.sinks);
        series["tubes"] = array1(s.tubes);
        series["right_all"] = array1(s.all[0]);
        series["left_all"] = array1(s.all[1]);
        series["sources_all"] = array1(s.all[2]);
        series["sinks_all"] = array1(s.all[3]);
        py::dict out;
        out["dim"] = s.dim;
        out["every"] = every;
        out["stride"] = s.stride;
        out["strain_axis"] = std::string(1, s.strain_axis);
        out["series"] = series;
        if (s.right_spectrum && s.left_spectrum) {
          py::dict spectrum;
          for (const auto& [name, sp] :
               {std::pair<const char*, const ga::AmplitudeSpectrum*>{"right", &*s.right_spectrum},
                {"left", &*s.left_spectrum}}) {
            py::dict d;
            d["frequency"] = array1(sp->frequency);
            d["period"] = array1(sp->period);
            d["amplitude"] = array1(sp->amplitude);
            d["dominant_period"] = sp->dominant_period;
            spectrum[name] = d;
          }
          out["spectrum"] = spectrum;
        }
        return out;
      },
      py::arg("run"), py::kw_only(), py::arg("every"), py::arg("stride") = 0,
      py::arg("from_frame") = 0, py::arg("last") = py::none(), py::arg("strain_axis") = "",
      py::arg("slice") = false, py::arg("slab_origin") = py::none(),
      py::arg("slab_normal") = py::none(), py::arg("slab_axis") = py::none(),
      py::arg("slab_thickness") = py::none(), py::arg("slab_d50") = py::none(),
      py::arg("ghosts") = false, py::arg("ghost_spacing") = py::none(),
      py::arg("ghost_min_distance") = py::none(), py::arg("ghost_extent") = py::none(),
      py::arg("ghost_radius") = py::none(), py::arg("d50") = py::none(), py::arg("solver") = "auto",
      py::arg("tolerance") = py::none(), py::arg("max_iterations") = 10000,
      py::arg("axis") = py::none(), py::arg("delta") = 0.05,
      py::arg("significance") = ga::kSignificanceRelative, py::arg("significance_abs") = 0.0,
      py::arg("progress") = py::none(),
      "Vortex counts over a trajectory as `granoscope analyze vortices` (seed 000 Figs 16-18): "
      "the HHD of every `every`-frame displacement increment of `run` (a Trajectory or a list "
      "of Frames), counts of right/left-handed vortices, sources and sinks against the strain "
      "(relative shortening along strain_axis) and their spectrum. `from_frame` is the CLI's "
      "--from; progress(frame_from, frame_to, strain, counts) is called after each increment.");
}

}  // namespace gs::py_bind
