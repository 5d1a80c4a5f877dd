// `granoscope analyze rev` (REV cell maps or Gaussian coarse-graining), `analyze shearzone`
// (inclination and thickness of a shear band from a REV map) and `analyze invariants` (specimen
// stress and deformation invariants). Methods and seed equations: docs/analysis.md. Outputs:
// HDF5 (root attribute format = granoscope-rev / -shearzone / -invariants, for `granoscope
// figures`), optionally VTI and CSV; every file written under a temporary name and renamed.

#include <CLI/CLI.hpp>
#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "analyze_common.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_series.hpp"
#include "rev_map.hpp"
#include "specimen_stress.hpp"
#include "tensor_invariants.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

std::vector<double> flat(const Eigen::Matrix3d& m) {
  return flat_rows(std::vector<Eigen::Matrix3d>{m});
}

void write_grid(H5FieldFile& h, const ga::RevGrid& g) {
  h.group("/grid");
  h.write("/grid/dims", std::vector<std::int64_t>{g.n[0], g.n[1], g.n[2]});
  h.write("/grid/axes", flat(g.axes), {3, 3});
  h.write("/grid/origin", std::vector<double>{g.origin.x(), g.origin.y(), g.origin.z()});
  const Eigen::Vector3d first = g.lo + 0.5 * g.size;
  h.write("/grid/first_centre_local", std::vector<double>{first.x(), first.y(), first.z()});
  h.attr("step", g.step, "/grid");
  h.attr("dim", static_cast<long long>(g.dim), "/grid");
  h.attr("slab", static_cast<long long>(g.slab ? 1 : 0), "/grid");
  std::vector<Eigen::Vector3d> centre, local;
  for (std::size_t c = 0; c < g.count(); ++c) {
    centre.push_back(g.centre(c));
    local.push_back(g.local(centre.back()));
  }
  h.group("/cells");
  h.write("/cells/centre", centre);
  h.write("/cells/local", local);
}

// ---- rev ---------------------------------------------------------------------------------

struct RevArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  SelectionArgs sel;
  std::string output, vti, csv;
  GridArgs grid;
  ga::RevMapSpec spec;
  std::vector<double> profile;
  int profile_points = 0;
};

void run_rev(const RevArgs& a) {
  if (!a.profile.empty() && a.csv.empty())
    throw InputError(a.in.input, "--profile writes a CSV: give --csv FILE");
  const Frame f = a.in.load();
  const std::optional<Frame> to = a.in.load_to();
  ga::RevMapSpec spec = a.spec;
  spec.grid = a.grid;
  spec.selection = a.sel;
  const ga::RevMap r = ga::rev_map(a.in.input, f, to ? &*to : nullptr, a.in.d50_of(f), spec);
  const ga::RevGrid& g = r.grid;
  H5FieldFile h(a.output, "granoscope-rev");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("frame_to", static_cast<long long>(a.in.to.value_or(-1)));
  h.attr("method", r.method);
  h.attr("mode", r.mode());
  h.attr("d50", r.d50);
  h.attr("cell", r.cell);
  h.attr("step", r.step);
  h.attr("width", r.width);
  h.attr("slab_thickness", r.slab_thickness);
  h.attr("stress_convention", "compression positive; stress_ij = (1/V) sum w l_i f_j");
  h.attr("seconds", r.seconds);
  write_grid(h, g);
  for (const auto& [n, v] : r.fields.scalar) h.write("/cells/" + n, v);
  for (const auto& [n, v] : r.fields.vector) h.write("/cells/" + n, v);
  for (const auto& [n, v] : r.fields.tensor) h.write("/cells/" + n, v);
  h.commit();
  if (!a.vti.empty()) {
    const Eigen::Vector3d first = g.lo + 0.5 * g.size;
    write_vti_image(a.vti, g.dim == 2 ? Eigen::Vector3d(first.x(), first.y(), 0.0) : first,
                    Eigen::Vector3d::Constant(g.step), g.n, r.fields.arrays());
  }
  if (!a.csv.empty())
    write_csv_table(a.csv, a.profile.empty()
                               ? ga::rev_cell_table(r)
                               : ga::rev_profile(a.in.input, r, a.profile, a.profile_points));
  std::cout << "rev (" << r.method << ", "
            << (g.dim == 2 ? "2D"
                : g.slab   ? "slab"
                           : "3D")
            << "): " << g.n[0] << " x " << g.n[1] << " x " << g.n[2] << " cells, "
            << f.particles.size() << " particles, " << r.particle_contacts << " + "
            << r.wall_contacts << " wall contacts, " << r.seconds << " s\n";
}

// ---- shearzone ---------------------------------------------------------------------------

struct ShearArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  SelectionArgs sel;
  std::string output, csv, field = "rotation";
  GridArgs grid;
};

void run_shearzone(const ShearArgs& a) {
  const Frame f = a.in.load();
  const std::optional<Frame> to = a.in.load_to();
  ga::ShearZoneSpec spec;
  spec.field = a.field;
  spec.grid = a.grid;
  spec.selection = a.sel;
  const double d50 = a.in.d50_of(f);
  const ga::ShearZoneMap s = ga::shear_zone_map(a.in.input, f, to ? &*to : nullptr, d50, spec);
  const ga::ScalarMap& m = s.map;
  const ga::ShearZone& z = s.zone;
  H5FieldFile h(a.output, "granoscope-shearzone");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("frame_to", static_cast<long long>(a.in.to.value_or(-1)));
  h.attr("field", a.field);
  h.attr("d50", d50);
  h.attr("cell", s.cell);
  h.attr("step", s.step);
  h.attr("angle_deg", z.angle_deg);
  h.attr("inclination_deg", z.inclination_deg);
  h.attr("thickness_m", z.thickness);
  h.attr("thickness_mm", 1e3 * z.thickness);
  h.attr("thickness_d50", z.thickness / d50);
  h.attr("lower_m", z.lower_d);
  h.attr("upper_m", z.upper_d);
  h.attr("peak_value", z.peak_value);
  h.attr("by_rows", static_cast<long long>(z.by_rows ? 1 : 0));
  write_grid(h, s.grid);
  h.group("/map");
  h.write("/map/value", m.value, {static_cast<std::size_t>(m.nv), static_cast<std::size_t>(m.nu)});
  h.attr("u0", m.u0, "/map");
  h.attr("v0", m.v0, "/map");
  h.attr("step", m.step, "/map");
  h.group("/ridge");
  std::vector<double> ridge;
  for (const auto& p : z.ridge) ridge.insert(ridge.end(), {p.x(), p.y()});
  h.write("/ridge/points", ridge, {z.ridge.size(), 2});
  h.write("/ridge/inlier", z.inlier);
  h.group("/line");
  h.write("/line/point", std::vector<double>{z.point.x(), z.point.y()});
  h.write("/line/direction", std::vector<double>{z.direction.x(), z.direction.y()});
  h.group("/profile");
  h.write("/profile/distance", z.profile_d);
  h.write("/profile/value", z.profile_value);
  h.commit();
  if (!a.csv.empty())
    write_csv_table(a.csv, {{"distance", 1, z.profile_d}, {a.field, 1, z.profile_value}});
  std::cout << std::fixed << std::setprecision(2) << "shearzone (" << a.field << "): inclination "
            << z.inclination_deg << " deg to the horizontal (direction " << z.angle_deg
            << " deg), thickness " << 1e3 * z.thickness << " mm = " << z.thickness / d50
            << " d50; map " << m.nu << " x " << m.nv << " cells, ridge from "
            << (z.by_rows ? "rows" : "columns") << "\n";
}

// ---- invariants --------------------------------------------------------------------------

struct InvArgs {
  FrameArgs in;
  FrameSeriesArgs series;
  SelectionArgs sel;
  std::string output, csv;
  std::vector<double> stress, gradient;
};

Eigen::Matrix3d matrix9(const std::string& file, const char* name, const std::vector<double>& v) {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = v[static_cast<std::size_t>(k)];
  if (!m.allFinite()) throw InputError(file, std::string(name) + " must be 9 finite numbers");
  return m;
}

void run_invariants(const InvArgs& a) {
  const bool direct = !a.stress.empty() || !a.gradient.empty();
  if (a.in.input.empty() && !direct)
    throw InputError("granoscope", "analyze invariants needs a snapshot, --stress or --gradient");
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero(), F = Eigen::Matrix3d::Identity();
  bool has_sigma = false, has_F = false, has_boundary = false;
  Eigen::Matrix3d boundary = Eigen::Matrix3d::Zero();
  int dim = 3;
  double volume = 0.0;
  const std::string src = a.in.input.empty() ? std::string("--stress") : a.in.input;
  if (!a.stress.empty()) sigma = matrix9(src, "--stress", a.stress), has_sigma = true;
  if (!a.gradient.empty()) F = matrix9(src, "--gradient", a.gradient), has_F = true;
  if (!a.in.input.empty()) {
    const Frame f = a.in.load();
    dim = f.two_d ? 2 : 3;
    if (!has_sigma) {
      const ga::SpecimenStress st =
          ga::specimen_stress(a.in.input, f, a.sel.make_region(a.in.input));
      sigma = st.sigma;
      volume = st.volume;
      has_sigma = true;
      if (st.boundary_eq14) {
        boundary = *st.boundary_eq14;
        has_boundary = true;
      }
    }
    if (!has_F && a.in.to) {
      F = ga::fit_deformation_gradient(a.in.input, f, *a.in.load_to());
      has_F = true;
    }
  }
  H5FieldFile h(a.output, "granoscope-invariants");
  h.attr("source", a.in.input);
  h.attr("stress_convention", "compression positive");
  std::vector<VtkArray> row;
  if (has_sigma) {
    const auto s = ga::stress_invariants(sigma, dim);
    h.group("/stress");
    h.write("/stress/tensor", flat(sigma), {3, 3});
    h.write("/stress/principal",
            std::vector<double>{s.principal.x(), s.principal.y(), s.principal.z()});
    h.write("/stress/directions", flat(s.directions), {3, 3});
    for (const auto& [n, v] :
         std::vector<std::pair<const char*, double>>{{"p", s.p},
                                                     {"q", s.q},
                                                     {"eta", s.eta},
                                                     {"b", s.b},
                                                     {"lode_deg", s.lode_deg},
                                                     {"phi_mob_deg", s.phi_mob_deg},
                                                     {"j2d", s.j2d},
                                                     {"j3d", s.j3d},
                                                     {"asymmetry", s.asymmetry},
                                                     {"volume", volume}}) {
      h.attr(n, v, "/stress");
      row.push_back({n, 1, {v}});
    }
    row.push_back({"stress", 9, flat(sigma)});
    if (has_boundary) {
      h.write("/stress/boundary_eq14", flat(boundary), {3, 3});
      row.push_back({"stress_boundary_eq14", 9, flat(boundary)});
    }
    std::cout << std::setprecision(6) << "stress (compression positive): p " << s.p << ", q " << s.q
              << ", eta " << s.eta << ", b " << s.b << ", Lode " << s.lode_deg
              << " deg, mobilised friction " << s.phi_mob_deg << " deg\n";
  }
  if (has_F) {
    ga::StrainInvariants e;
    try {
      e = ga::strain_invariants(F);
    } catch (const std::invalid_argument& x) {
      throw InputError(src, x.what());
    }
    h.group("/strain");
    for (const auto& [n, m] :
         std::vector<std::pair<const char*, Eigen::Matrix3d>>{{"F", F},
                                                              {"U", e.U},
                                                              {"R", e.R},
                                                              {"biot", e.biot},
                                                              {"Fv", e.Fv},
                                                              {"Fd", e.Fd},
                                                              {"directions", e.directions}})
      h.write(std::string("/strain/") + n, flat(m), {3, 3});
    h.write("/strain/principal",
            std::vector<double>{e.principal.x(), e.principal.y(), e.principal.z()});
    for (const auto& [n, v] :
         std::vector<std::pair<const char*, double>>{{"J", e.J},
                                                     {"eps_v", e.eps_v},
                                                     {"eps_q", e.eps_q},
                                                     {"b_eps", e.b_eps},
                                                     {"b_stretch", e.b_stretch},
                                                     {"lode_deg", e.lode_deg}}) {
      h.attr(n, v, "/strain");
      row.push_back({std::string("strain_") + n, 1, {v}});
    }
    row.push_back({"F", 9, flat(F)});
    std::cout << std::setprecision(6) << "deformation: J " << e.J << ", eps_v " << e.eps_v
              << ", eps_q " << e.eps_q << ", b_eps " << e.b_eps << "\n";
  }
  if (!has_sigma && !has_F) throw InputError(src, "nothing to evaluate");
  h.commit();
  if (!a.csv.empty()) write_csv_table(a.csv, row);
}

}  // namespace

void register_analyze_rev(CLI::App& app) {
  auto& analyze = analyze_command(app);
  {
    auto a = std::make_shared<RevArgs>();
    auto* s = analyze.add_subcommand(
        "rev",
        "REV cell maps (void ratio from exact sphere-box volumes, rotation, displacement, "
        "coordination, Love-Weber stress) or Gaussian coarse-graining, 3D or in a slab");
    a->in.add_to(*s, true);
    a->sel.add_to(*s);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-rev)")->required();
    s->add_option("--method", a->spec.method,
                  "box (REV cells, default) or gaussian (coarse-graining)");
    a->grid.add_to(*s);
    s->add_option("--width", a->spec.width, "gaussian: kernel width (standard deviation) in m");
    s->add_option("--width-d50", a->spec.width_d50, "gaussian: kernel width in d50 (default 1)");
    s->add_option("--particle-density", a->spec.particle_density,
                  "kg/m^3 for particles of unknown mass (default 2650)");
    s->add_option("--vti", a->vti, "also write a VTK image (slab: in its plane coordinates)");
    s->add_option("--csv", a->csv, "also write a CSV: all cells, or the --profile");
    s->add_option("--profile", a->profile, "line x0 y0 z0 x1 y1 z1 for a CSV profile")->expected(6);
    s->add_option("--profile-points", a->profile_points, "points on the profile (default s/2)");
    add_frame_series(*s, a, "rev", &run_rev);
  }
  {
    auto a = std::make_shared<ShearArgs>();
    auto* s = analyze.add_subcommand(
        "shearzone",
        "Shear band inclination (ridge line fit) and thickness (inflection points of the "
        "profile across it) from a REV map of rotation or shear strain in a slab");
    a->in.add_to(*s, true);
    a->sel.add_to(*s, false);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-shearzone)")
        ->required();
    s->add_option("--field", a->field,
                  "rotation (about the slab normal, default) or shear (needs --to)");
    a->grid.add_to(*s);
    s->add_option("--csv", a->csv, "also write the profile across the band as CSV");
    add_frame_series(*s, a, "shearzone", &run_shearzone);
  }
  {
    auto a = std::make_shared<InvArgs>();
    auto* s = analyze.add_subcommand(
        "invariants",
        "Specimen stress (Love-Weber; with walls also seed 003 eq 14) and its invariants p, q, "
        "eta, b, Lode angle, mobilised friction; with --to the deformation gradient and eps_v, "
        "eps_q, b_eps, Biot strain, F = Fv Fd");
    a->in.add_to(*s, true, false);
    s->add_option("--region", a->sel.region,
                  "box x0 y0 z0 x1 y1 z1 (default: the particles; a periodic frame: its cell)")
        ->expected(6);
    s->add_option("-o,--output", a->output, "output HDF5 (format granoscope-invariants)")
        ->required();
    s->add_option("--stress", a->stress, "evaluate this stress s11 s12 ... s33 instead")
        ->expected(9);
    s->add_option("--gradient", a->gradient, "evaluate this F11 F12 ... F33 instead")->expected(9);
    s->add_option("--csv", a->csv, "also write one CSV row of all values");
    add_frame_series(*s, a, "invariants", &run_invariants);
  }
}

}  // namespace gs::cli
