// `granoscope analyze hhd` (seed 000: Helmholtz–Hodge decomposition of one displacement
// increment, vortex centres, sources/sinks and vortex tubes) and `granoscope analyze vortices`
// (the same on every IT-frame increment of a trajectory: counts of right/left-handed vortices
// against strain and their Fourier spectrum, seed 000 Figs 16–18). Outputs: HDF5 (root attribute
// format = granoscope-hhd / granoscope-vortices, for `granoscope figures`), VTU, CSV of extrema,
// VTP of tubes, each written under a temporary name and renamed.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_motion.hpp"
#include "point_vectors_csv.hpp"
#include "slab_options.hpp"
#include "vortex_analysis.hpp"
#include "vortex_count_series.hpp"
#include "vortex_field.hpp"

namespace gs::cli {
namespace {

namespace fs = std::filesystem;
using analysis::VortexAnalysis;

// ---- options shared by hhd and vortices -----------------------------------------------------

using FieldArgs = analysis::VortexFieldSpec;
using Field = analysis::VortexField;

void add_field_options(CLI::App* s, FieldArgs& a) {
  s->add_flag("--slice", a.slice,
              "2D slice mode (seed 000 §5): the particles of a slab, 5 d50 thick at mid-depth "
              "unless --slab-* say otherwise, projected on its plane");
  add_slab_options(s, a.slab);
  s->add_flag("--ghosts", a.ghosts,
              "add ghost nodes outside the specimen (seed 000 §4.2); defaults scale the paper's "
              "4.5/4/50/80 mm with d50 and the specimen width");
  s->add_option("--ghost-spacing", a.ghost_spacing, "ghost lattice spacing h_g in m (1.8 d50)");
  s->add_option("--ghost-min-distance", a.ghost_min_distance,
                "least distance of a ghost from a centre in m (1.6 d50)");
  s->add_option("--ghost-extent", a.ghost_extent, "ghosts up to this distance in m (1.25 width)");
  s->add_option("--ghost-radius", a.ghost_radius, "Gaussian averaging radius R in m (2 width)");
  s->add_option("--d50", a.d50, "d50 in m for the ghost defaults (default: from the frame)");
  s->add_option(
      "--solver", a.solver,
      "auto (default: projection-amg in 3D, cholmod in 2D) | projection-amg (eq 18's L2 "
      "projection: PCG preconditioned by an AMG V-cycle of the Laplacian and block Jacobi) | "
      "projection (the same with the Laplacian's Cholesky factor) | cholmod (path b: Laplacian, "
      "gauge as a penalty) | ldlt (path c) | cg (path b, AMG-preconditioned CG) | bicgstab "
      "(path a: eq 17-18 as written, the paper's)");
  s->add_option("--tolerance", a.tolerance,
                "iterative solvers: relative residual (projection-amg and projection 1e-7, cg and "
                "bicgstab 1e-10)");
  s->add_option("--max-iterations", a.max_iterations, "iterative solvers (10000)");
  s->add_option("--axis", a.axis,
                "3D: out-of-plane axis x y z giving the handedness of vortices (default z, or the "
                "slab normal)")
      ->expected(3);
  s->add_option("--delta", a.delta, "vortex-tube threshold delta (seed 000 §6: 0.05)");
  s->add_option("--significance", a.significance,
                "extrema that count (summary, series, figures): magnitude >= this fraction of "
                "the strongest of the same potential (0.05; 0 counts every strict extremum)");
  s->add_option("--significance-abs", a.significance_abs,
                "and >= this magnitude in the potential's units (vector units x m; 0)");
}

// ---- hhd outputs ------------------------------------------------------------------------------

template <class T>
void write_rows(H5FieldFile& h, const std::string& name, const std::vector<T>& v,
                std::size_t cols) {
  h.write(name, v, {cols > 0 ? v.size() / cols : 0, cols});
}

void write_extrema_csv(const fs::path& path, const VortexAnalysis& a, const Field& f) {
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path());
    if (!o) throw InputError(path.string(), "cannot write file");
    o << "kind,node,id,x,y,z,value,magnitude,vx,vy,vz,significant\n";
    char buf[512];
    for (const auto& e : a.extrema) {
      const auto& p = a.mesh.points[static_cast<std::size_t>(e.node)];
      std::snprintf(buf, sizeof buf,
                    "%s,%d,%lld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d\n",
                    analysis::extremum_kind_name(e.kind), e.node,
                    static_cast<long long>(f.id[static_cast<std::size_t>(e.node)]), p.x(), p.y(),
                    p.z(), e.value, e.magnitude, e.v.x(), e.v.y(), e.v.z(), e.significant ? 1 : 0);
      o << buf;
    }
    if (!o.flush()) throw InputError(path.string(), "write failed");
  }
  out.commit();
}

void write_tubes_vtp(const fs::path& path, const VortexAnalysis& a) {
  std::vector<Eigen::Vector3d> pts;
  std::vector<std::vector<std::int64_t>> lines;
  std::vector<double> vnorm, kind, magnitude;
  for (const auto& t : a.tubes) {
    if (t.nodes.size() < 2) continue;  // a centre without a tube: in the extrema only
    lines.emplace_back();
    for (const auto i : t.nodes) {
      lines.back().push_back(static_cast<std::int64_t>(pts.size()));
      pts.push_back(a.mesh.points[static_cast<std::size_t>(i)]);
      vnorm.push_back(a.hhd.v_coulomb.row(i).norm());
    }
    kind.push_back(static_cast<double>(a.extrema[t.extremum].kind));
    magnitude.push_back(a.extrema[t.extremum].magnitude);
  }
  write_vtp_polylines(path, pts, lines, {{"v_norm", 1, vnorm}},
                      {{"kind", 1, kind}, {"magnitude", 1, magnitude}});
}

void write_hhd_vtu(const fs::path& path, const VortexAnalysis& a,
                   const std::vector<Eigen::Vector3d>& vectors) {
  const int dim = a.mesh.dim;
  std::vector<std::vector<std::int64_t>> cells;
  cells.reserve(a.mesh.simplices.size());
  for (const auto& s : a.mesh.simplices) cells.emplace_back(s.begin(), s.begin() + dim + 1);
  std::vector<double> ghost(a.mesh.points.size(), 0.0);
  for (std::size_t i = a.true_nodes; i < ghost.size(); ++i) ghost[i] = 1.0;
  const auto& r = a.hhd;
  write_vtu_mesh(path, a.mesh.points, dim == 3 ? 10 : 5, cells,
                 {{"u", 1, std::vector<double>(r.u.data(), r.u.data() + r.u.size())},
                  {"v", static_cast<int>(r.v.cols()), flat_rows(r.v)},
                  {"v_coulomb", static_cast<int>(r.v_coulomb.cols()), flat_rows(r.v_coulomb)},
                  {"vector", 3, flat_rows(vectors)},
                  {"ghost", 1, ghost}},
                 {{"xi", 3, flat_rows(r.xi)},
                  {"grad_u", 3, flat_rows(r.grad_u)},
                  {"curl_v", 3, flat_rows(r.curl_v)},
                  {"h", 3, flat_rows(r.harmonic)},
                  {"measure", 1, r.measure}});
}

void write_report_attrs(H5FieldFile& h, const VortexAnalysis& a) {
  const auto& r = a.hhd;
  h.attr("dim", static_cast<long long>(r.dim));
  h.attr("solver", r.report.solver);
  h.attr("unknowns", static_cast<long long>(r.report.unknowns));
  h.attr("iterations_u", static_cast<long long>(r.report.iterations_u));
  h.attr("iterations_v", static_cast<long long>(r.report.iterations_v));
  h.attr("converged", static_cast<long long>(r.report.converged ? 1 : 0));
  h.attr("residual_eq17", r.report.residual_eq17);
  h.attr("residual_eq18", r.report.residual_eq18);
  h.attr("tolerance", r.report.tolerance);
  h.attr("norm_xi", r.norm_xi);
  h.attr("norm_grad_u", r.norm_grad_u);
  h.attr("norm_curl_v", r.norm_curl_v);
  h.attr("norm_harmonic", r.norm_harmonic);
  h.attr("norm_div_v", r.norm_div_v);
  h.attr("dot_grad_curl", r.dot_grad_curl);
  h.attr("dot_grad_harmonic", r.dot_grad_harmonic);
  h.attr("dot_curl_harmonic", r.dot_curl_harmonic);
  h.attr("seconds_ghosts", a.seconds_ghosts);
  h.attr("seconds_delaunay", a.seconds_delaunay);
  h.attr("seconds_assembly", r.report.seconds_assembly);
  h.attr("seconds_factor", r.report.seconds_factor);
  h.attr("seconds_solve", r.report.seconds_solve);
  h.attr("seconds_detection", a.seconds_detection);
}

double cosine(double dot, double a, double b) {
  return a > 0.0 && b > 0.0 ? dot / (a * b) : 0.0;
}

void print_summary(const char* what, const VortexAnalysis& a) {
  const auto& r = a.hhd;
  const auto c = analysis::count_extrema(a.extrema, true);
  const auto all = analysis::count_extrema(a.extrema, false);
  std::printf(
      "%s: %zu nodes (%zu ghosts), %zu %s, solver %s (%s%d/%d iterations), "
      "residual eq17 %.2e eq18 %.2e\n"
      "  |xi| %.4g  |grad u| %.4g  |curl v| %.4g  |h| %.4g  cos(grad,curl) %.2e "
      "cos(grad,h) %.2e cos(curl,h) %.2e |div v| %.3g\n"
      "  vortices right %zu left %zu, sources %zu, sinks %zu, tubes %zu (significant: >= %g of "
      "the strongest%s; all strict extrema: right %zu left %zu, sources %zu, sinks %zu)\n"
      "  time ghosts %.3f s, delaunay %.3f s, assembly %.3f s, factor %.3f s, solve %.3f s, "
      "detection %.3f s\n",
      what, a.mesh.points.size(), a.mesh.points.size() - a.true_nodes, a.mesh.simplices.size(),
      r.dim == 3 ? "tetrahedra" : "triangles", r.report.solver.c_str(),
      r.report.converged ? "" : "NOT CONVERGED, ", r.report.iterations_u, r.report.iterations_v,
      r.report.residual_eq17, r.report.residual_eq18, r.norm_xi, r.norm_grad_u, r.norm_curl_v,
      r.norm_harmonic, cosine(r.dot_grad_curl, r.norm_grad_u, r.norm_curl_v),
      cosine(r.dot_grad_harmonic, r.norm_grad_u, r.norm_harmonic),
      cosine(r.dot_curl_harmonic, r.norm_curl_v, r.norm_harmonic), r.norm_div_v, c[0], c[1], c[2],
      c[3], analysis::count_significant_tubes(a.tubes, a.extrema), a.significance_relative,
      a.significance_absolute > 0.0 ? (" and >= " + value_str(a.significance_absolute)).c_str()
                                    : "",
      all[0], all[1], all[2], all[3], a.seconds_ghosts, a.seconds_delaunay,
      r.report.seconds_assembly, r.report.seconds_factor, r.report.seconds_solve,
      a.seconds_detection);
}

// ---- analyze hhd ---------------------------------------------------------------------------

struct HhdArgs {
  std::string input, csv, output, vtu, extrema, tubes;
  long from = 0;
  std::optional<long> to;
  FieldArgs field;
};

void run_hhd(const HhdArgs& a) {
  if (a.input.empty() == a.csv.empty()) {
    throw InputError(a.input.empty() ? "granoscope analyze hhd" : a.input,
                     "give either RUN.h5 or --csv FILE");
  }
  const std::string source = a.csv.empty() ? a.input : a.csv;
  Field f;
  std::string motion = "csv";
  if (!a.csv.empty()) {
    if (a.field.projected()) {
      throw InputError(source, "--slice/--slab need a trajectory (give a 2D CSV instead)");
    }
    const auto p = read_point_vectors_csv(a.csv);
    f.dim = p.dim;
    f.x = p.x;
    f.u = p.u;
    f.id = p.id;
  } else {
    const FrameMotion m = read_frame_motion(a.input, a.from, a.to);
    motion = m.kind;
    f = analysis::vortex_field(m, a.field, a.input);
  }
  const auto opts = analysis::vortex_analysis_options(a.field, f, source);
  const VortexAnalysis r = analysis::analyze_field(f, opts, source);
  f.id.resize(r.mesh.points.size(), -1);  // ghosts: id -1
  const auto& vectors = r.vectors;

  H5FieldFile h(a.output, "granoscope-hhd");
  h.attr("source", source);
  h.attr("motion", motion);
  h.attr("frame_from", static_cast<long long>(a.csv.empty() ? a.from : -1));
  h.attr("frame_to", static_cast<long long>(a.csv.empty() ? a.to.value_or(-1) : -1));
  h.attr("slab", static_cast<long long>(f.slab ? 1 : 0));
  h.attr("ghosts", static_cast<long long>(r.mesh.points.size() - r.true_nodes));
  if (opts.ghosts) {
    h.attr("ghost_spacing", opts.ghost.spacing);
    h.attr("ghost_min_distance", opts.ghost.min_distance);
    h.attr("ghost_extent", opts.ghost.extent);
    h.attr("ghost_radius", opts.ghost.radius);
  }
  h.attr("d50", f.d50);
  h.attr("delta", a.field.delta);
  write_report_attrs(h, r);
  h.group("/nodes");
  h.group("/simplices");
  h.group("/extrema");
  h.group("/tubes");
  write_rows(h, "/nodes/position", flat_rows(r.mesh.points), 3);
  write_rows(h, "/nodes/vector", flat_rows(vectors), 3);
  h.write("/nodes/id", f.id);
  h.write("/nodes/u", std::vector<double>(r.hhd.u.data(), r.hhd.u.data() + r.hhd.u.size()));
  write_rows(h, "/nodes/v", flat_rows(r.hhd.v), static_cast<std::size_t>(r.hhd.v.cols()));
  write_rows(h, "/nodes/v_coulomb", flat_rows(r.hhd.v_coulomb),
             static_cast<std::size_t>(r.hhd.v_coulomb.cols()));
  std::vector<std::uint8_t> ghost(r.mesh.points.size(), 0);
  for (std::size_t i = r.true_nodes; i < ghost.size(); ++i) ghost[i] = 1;
  h.write("/nodes/ghost", ghost);
  h.write("/nodes/dirichlet", r.mesh.dirichlet);
  std::vector<std::int32_t> simp;
  for (const auto& s : r.mesh.simplices)
    for (int k = 0; k <= r.mesh.dim; ++k) simp.push_back(s[static_cast<std::size_t>(k)]);
  write_rows(h, "/simplices/vertices", simp, static_cast<std::size_t>(r.mesh.dim + 1));
  h.write("/simplices/measure", r.hhd.measure);
  write_rows(h, "/simplices/xi", flat_rows(r.hhd.xi), 3);
  write_rows(h, "/simplices/grad_u", flat_rows(r.hhd.grad_u), 3);
  write_rows(h, "/simplices/curl_v", flat_rows(r.hhd.curl_v), 3);
  write_rows(h, "/simplices/harmonic", flat_rows(r.hhd.harmonic), 3);
  const analysis::ExtremaColumns e = analysis::extrema_columns(r);
  h.attr("kinds", "0 right_vortex, 1 left_vortex, 2 source, 3 sink", "/extrema");
  h.write("/extrema/node", e.node);
  h.write("/extrema/kind", e.kind);
  h.write("/extrema/value", e.value);
  h.write("/extrema/magnitude", e.magnitude);
  h.write("/extrema/significant", e.significant);
  h.attr("significance_relative", r.significance_relative, "/extrema");
  h.attr("significance_absolute", r.significance_absolute, "/extrema");
  write_rows(h, "/extrema/position", flat_rows(e.position), 3);
  write_rows(h, "/extrema/v", flat_rows(e.v), 3);
  const analysis::TubeColumns t = analysis::tube_columns(r);
  h.write("/tubes/offsets", t.offsets);
  h.write("/tubes/nodes", t.nodes);
  h.write("/tubes/extremum", t.extremum);
  if (f.slab) {
    h.group("/slab");
    h.write("/slab/origin", std::vector<Eigen::Vector3d>{f.plane.origin});
    h.write("/slab/axes", std::vector<Eigen::Vector3d>{f.e1, f.e2});
    h.attr("thickness", f.plane.thickness, "/slab");
  }
  h.commit();
  if (!a.vtu.empty()) write_hhd_vtu(a.vtu, r, vectors);
  if (!a.extrema.empty()) write_extrema_csv(a.extrema, r, f);
  if (!a.tubes.empty()) write_tubes_vtp(a.tubes, r);
  print_summary("hhd", r);
  if (!r.hhd.report.converged) {
    std::printf("warning: %s did not reach --tolerance %.1e in %d iterations\n",
                r.hhd.report.solver.c_str(), r.hhd.report.tolerance, a.field.max_iterations);
  }
}

// ---- analyze vortices ------------------------------------------------------------------------

struct SeriesArgs {
  std::string input, output;
  analysis::VortexSeriesSpec spec;
};

void run_vortices(const SeriesArgs& a) {
  const auto n = static_cast<long>(frame_count(a.input));
  const analysis::VortexCountSeries s = analysis::vortex_count_series(
      a.input, n, [&](long i) { return read_frame(a.input, i); }, a.spec,
      [](const analysis::VortexSeriesStep& p) {
        std::printf(
            "frames %ld-%ld strain %.5f: right %zu left %zu sources %zu sinks %zu (%.2f s)\n",
            p.from, p.to, p.strain, p.counts[0], p.counts[1], p.counts[2], p.counts[3], p.seconds);
      });
  const FieldArgs& field = a.spec.field;
  H5FieldFile h(a.output, "granoscope-vortices");
  h.attr("source", a.input);
  h.attr("dim", static_cast<long long>(s.dim));
  h.attr("every", static_cast<long long>(a.spec.every));
  h.attr("stride", static_cast<long long>(s.stride));
  h.attr("strain_axis", std::string(1, s.strain_axis));
  h.attr("solver", field.solver);
  h.attr("delta", field.delta);
  h.attr("ghosts", static_cast<long long>(field.ghosts ? 1 : 0));
  h.group("/series");
  h.write("/series/frame_from", s.frame_from);
  h.write("/series/frame_to", s.frame_to);
  h.write("/series/time", s.time);
  h.write("/series/strain", s.strain);
  h.write("/series/right", s.right);
  h.write("/series/left", s.left);
  h.write("/series/sources", s.sources);
  h.write("/series/sinks", s.sinks);
  h.write("/series/tubes", s.tubes);
  h.write("/series/right_all", s.all[0]);
  h.write("/series/left_all", s.all[1]);
  h.write("/series/sources_all", s.all[2]);
  h.write("/series/sinks_all", s.all[3]);
  h.attr("significance_relative", field.significance);
  h.attr("significance_absolute", field.significance_abs);
  if (s.right_spectrum && s.left_spectrum) {
    h.group("/spectrum");
    for (const auto& [name, sp] :
         {std::pair<const char*, const analysis::AmplitudeSpectrum*>{"right", &*s.right_spectrum},
          {"left", &*s.left_spectrum}}) {
      const std::string g = std::string("/spectrum/") + name;
      h.group(g);
      h.write(g + "/frequency", sp->frequency);
      h.write(g + "/period", sp->period);
      h.write(g + "/amplitude", sp->amplitude);
      h.attr("dominant_period", sp->dominant_period, g);
      std::printf("%s-handed vortices: dominant period %.4g of strain\n", name,
                  sp->dominant_period);
    }
  } else {
    std::printf("no spectrum: fewer than 4 pairs or strain not increasing along the series\n");
  }
  h.commit();
}

}  // namespace

void register_analyze_hhd(CLI::App& app) {
  auto& analyze = analyze_command(app);
  {
    auto a = std::make_shared<HhdArgs>();
    auto* s = analyze.add_subcommand(
        "hhd",
        "Helmholtz-Hodge decomposition of a displacement increment on the Delaunay mesh of the "
        "particle centres (seed 000): potentials u, v, parts grad u, curl v, h, vortex centres, "
        "sources/sinks, vortex tubes");
    s->add_option("input", a->input, "RUN.h5 trajectory (or any snapshot file)");
    s->add_option("--csv", a->csv, "points and vectors instead: header x,y[,z],ux,uy[,uz][,id]");
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-hhd)")->required();
    s->add_option("--from", a->from, "reference frame index (default 0)");
    s->add_option("--to", a->to,
                  "target frame: displacement increment from --from to --to matched by id "
                  "(seed 000: IT steps apart); without it the velocities of --from");
    s->add_option("--vtu", a->vtu, "also write the mesh: point u, v; cell xi, grad_u, curl_v, h");
    s->add_option("--extrema", a->extrema, "also write the extrema as CSV");
    s->add_option("--tubes", a->tubes,
                  "also write the vortex tubes of 2 or more nodes as VTP polylines (3D)");
    add_field_options(s, a->field);
    s->callback([a] { run_hhd(*a); });
  }
  {
    auto a = std::make_shared<SeriesArgs>();
    auto* s = analyze.add_subcommand(
        "vortices",
        "HHD of every IT-frame displacement increment of a trajectory: counts of right/left-"
        "handed vortices, sources, sinks against strain and their Fourier spectrum (seed 000 "
        "Figs 16-18)");
    s->add_option("input", a->input, "RUN.h5 trajectory")->required();
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-vortices)")->required();
    s->add_option("--every", a->spec.every, "IT: frames between the two frames of an increment")
        ->required();
    s->add_option("--stride", a->spec.stride, "frames between successive increments (default IT)");
    s->add_option("--from", a->spec.from, "first reference frame (default 0)");
    s->add_option("--last", a->spec.last, "last frame used (default: the last)");
    s->add_option("--strain-axis", a->spec.strain_axis,
                  "x|y|z: strain = relative shortening of the particles' extent along it "
                  "(default z, y for 2D frames)");
    add_field_options(s, a->spec.field);
    s->callback([a] { run_vortices(*a); });
  }
}

}  // namespace gs::cli
