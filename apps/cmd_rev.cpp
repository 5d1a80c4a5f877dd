// `granoscope analyze rev` (REV cell maps or Gaussian coarse-graining), `analyze shearzone`
// (inclination and thickness of a shear band from a REV map) and `analyze invariants` (specimen
// stress and deformation invariants). Methods and seed equations: docs/analysis.md. Outputs:
// HDF5 (root attribute format = granoscope-rev / -shearzone / -invariants, for `granoscope
// figures`), optionally VTI and CSV; every file written under a temporary name and renamed.

#include <CLI/CLI.hpp>
#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "analyze_common.hpp"
#include "coarse_graining.hpp"
#include "commands.hpp"
#include "errors.hpp"
#include "field_output.hpp"
#include "frame_motion.hpp"
#include "love_weber_stress.hpp"
#include "rev_cells.hpp"
#include "shear_zone.hpp"
#include "specimen_stress.hpp"
#include "tensor_invariants.hpp"

namespace gs::cli {
namespace {

namespace ga = gs::analysis;

std::vector<double> flat(const std::vector<Eigen::Vector3d>& v) {
  std::vector<double> out;
  out.reserve(3 * v.size());
  for (const auto& x : v) out.insert(out.end(), {x.x(), x.y(), x.z()});
  return out;
}

std::vector<double> flat(const std::vector<Eigen::Matrix3d>& m) {
  std::vector<double> out;
  out.reserve(9 * m.size());
  for (const auto& a : m)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out.push_back(a(i, j));  // row-major sigma_ij
  return out;
}

std::vector<double> flat(const Eigen::Matrix3d& m) {
  return flat(std::vector<Eigen::Matrix3d>{m});
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Per-particle displacement from --frame to --to (matched by id).
ga::ParticleMotion particle_motion(const Frame& f, const Frame& to, const std::string& file) {
  const FrameMotion m = motion_between(f, to, file);
  ga::ParticleMotion pm;
  pm.u.assign(f.particles.size(), Eigen::Vector3d::Zero());
  pm.matched.assign(f.particles.size(), 0);
  for (std::size_t k = 0; k < m.index.size(); ++k) {
    pm.u[static_cast<std::size_t>(m.index[k])] = m.u[k];
    pm.matched[static_cast<std::size_t>(m.index[k])] = 1;
  }
  return pm;
}

// ---- rev ---------------------------------------------------------------------------------

struct RevArgs {
  FrameArgs in;
  SelectionArgs sel;
  std::string output, vti, csv, method = "box";
  GridArgs grid;
  std::optional<double> width, width_d50;
  double particle_density = 2650.0;
  std::vector<double> profile;
  int profile_points = 0;
};

/// Named cell fields of a map, in output order.
struct MapFields {
  std::vector<std::pair<std::string, std::vector<double>>> scalar;
  std::vector<std::pair<std::string, std::vector<Eigen::Vector3d>>> vector;
  std::vector<std::pair<std::string, std::vector<Eigen::Matrix3d>>> tensor;

  std::vector<VtkArray> arrays() const {
    std::vector<VtkArray> a;
    for (const auto& [n, v] : scalar) a.push_back({n, 1, v});
    for (const auto& [n, v] : vector) a.push_back({n, 3, flat(v)});
    for (const auto& [n, v] : tensor) a.push_back({n, 9, flat(v)});
    return a;
  }
};

/// Invariants of each cell's stress (symmetric part; compression positive).
void add_invariants(MapFields& f, const std::vector<Eigen::Matrix3d>& stress, int dim,
                    const std::string& prefix) {
  std::vector<double> p, q, eta, phi, b, lode;
  for (const auto& s : stress) {
    const auto inv = ga::stress_invariants(s, dim);
    p.push_back(inv.p);
    q.push_back(inv.q);
    eta.push_back(inv.eta);
    phi.push_back(inv.phi_mob_deg);
    b.push_back(inv.b);
    lode.push_back(inv.lode_deg);
  }
  f.scalar.emplace_back(prefix + "p", p);
  f.scalar.emplace_back(prefix + "q", q);
  f.scalar.emplace_back(prefix + "eta", eta);
  f.scalar.emplace_back(prefix + "phi_mob_deg", phi);
  if (dim == 3) {
    f.scalar.emplace_back(prefix + "b", b);
    f.scalar.emplace_back(prefix + "lode_deg", lode);
  }
}

/// Rotation about the map normal (slab normal; z for 2D frames): the in-plane rotation.
std::vector<double> rotation_normal(const ga::RevGrid& g, const std::vector<Eigen::Vector3d>& r) {
  const Eigen::Vector3d n = g.axes.row(2);
  std::vector<double> out;
  for (const auto& x : r) out.push_back(x.dot(n));
  return out;
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

void write_rev_csv(const RevArgs& a, const ga::RevGrid& g, const MapFields& f) {
  std::vector<VtkArray> cols;
  if (a.profile.size() == 6) {  // profile along a line, interpolated between cell centres
    const Eigen::Vector3d p0(a.profile[0], a.profile[1], a.profile[2]),
        p1(a.profile[3], a.profile[4], a.profile[5]);
    if (!p0.allFinite() || !p1.allFinite() || !((p1 - p0).norm() > 0.0))
      throw InputError(a.in.input, "--profile needs two distinct finite points");
    const int n = a.profile_points > 0
                      ? a.profile_points
                      : static_cast<int>(std::ceil((p1 - p0).norm() / (0.5 * g.step))) + 1;
    if (n < 2 || n > 10000000)
      throw InputError(a.in.input, "--profile-points must be in 2..1e7", std::to_string(n));
    std::vector<double> dist;
    std::vector<Eigen::Vector3d> pts;
    std::vector<std::vector<std::pair<std::size_t, double>>> w;
    for (int k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) / (n - 1);
      pts.push_back(p0 + t * (p1 - p0));
      dist.push_back(t * (p1 - p0).norm());
      w.push_back(ga::rev_interpolation(g, pts.back()));
    }
    cols.push_back({"distance", 1, dist});
    cols.push_back({"point", 3, flat(pts)});
    for (const auto& arr : f.arrays()) {
      VtkArray c{arr.name, arr.components, {}};
      for (const auto& wk : w)
        for (int j = 0; j < arr.components; ++j) {
          double v = wk.empty() ? std::nan("") : 0.0;
          for (const auto& [cell, wt] : wk)
            v += wt * arr.values[cell * static_cast<std::size_t>(arr.components) +
                                 static_cast<std::size_t>(j)];
          c.values.push_back(v);
        }
      cols.push_back(c);
    }
  } else {
    std::vector<Eigen::Vector3d> centre, local;
    for (std::size_t c = 0; c < g.count(); ++c) {
      centre.push_back(g.centre(c));
      local.push_back(g.local(centre.back()));
    }
    cols.push_back({"centre", 3, flat(centre)});
    cols.push_back({"local", 3, flat(local)});
    for (const auto& arr : f.arrays()) cols.push_back(arr);
  }
  write_csv_table(a.csv, cols);
}

void run_rev(const RevArgs& a) {
  if (a.method != "box" && a.method != "gaussian")
    throw InputError(a.in.input, "--method must be box or gaussian", a.method);
  if (!a.profile.empty() && a.csv.empty())
    throw InputError(a.in.input, "--profile writes a CSV: give --csv FILE");
  const Frame f = a.in.load();
  const double d50 = a.in.d50_of(f);
  const bool gauss = a.method == "gaussian";
  ga::RevGridSpec spec;
  spec.cell = gauss ? 0.0 : a.grid.cell_size(a.in.input, d50);
  spec.step = a.grid.step_size(a.in.input, d50);
  spec.slab = a.sel.make_slab(a.in.input, f, d50);
  spec.region = a.sel.make_region(a.in.input);
  if (spec.region && spec.slab)
    throw InputError(a.in.input, "--region is for 3D grids; a slab map spans its plane");
  const double width =
      gauss ? length_option(a.in.input, "--width", a.width, a.width_d50, 1.0, d50) : 0.0;
  require_positive(a.in.input, "--particle-density", a.particle_density);
  ga::ParticleMotion motion;
  if (const auto to = a.in.load_to()) motion = particle_motion(f, *to, a.in.input);
  const auto t0 = std::chrono::steady_clock::now();
  ga::RevGrid g;
  MapFields out;
  const auto branches = ga::contact_branches(f);
  try {
    g = gauss ? ga::make_point_grid(f, spec) : ga::make_rev_grid(f, spec);
    if (!gauss) {
      const auto r = ga::rev_average(f, branches, g, motion);
      out.scalar = {{"void_ratio", r.void_ratio},
                    {"solid_fraction", r.solid_fraction},
                    {"solid_volume", r.solid_volume},
                    {"particles", r.particles},
                    {"coordination", r.coordination}};
      if (g.slab || g.dim == 2)
        out.scalar.emplace_back("rotation_normal", rotation_normal(g, r.rotation));
      out.vector.emplace_back("rotation", r.rotation);
      if (!r.displacement.empty()) out.vector.emplace_back("displacement", r.displacement);
      out.tensor.emplace_back("stress", r.stress);
      add_invariants(out, r.stress, g.dim, "");
    } else {
      const auto c = ga::coarse_grain(f, branches, g, {width, a.particle_density});
      std::vector<double> e;
      for (double nu : c.solid_fraction) e.push_back(nu > 0.0 ? 1.0 / nu - 1.0 : std::nan(""));
      std::vector<Eigen::Matrix3d> total;
      for (std::size_t k = 0; k < c.contact_stress.size(); ++k)
        total.push_back(c.contact_stress[k] + c.kinetic_stress[k]);
      out.scalar = {
          {"density", c.density}, {"solid_fraction", c.solid_fraction}, {"void_ratio", e}};
      out.vector.emplace_back("velocity", c.velocity);
      out.tensor = {{"stress", total},
                    {"stress_contact", c.contact_stress},
                    {"stress_kinetic", c.kinetic_stress}};
      add_invariants(out, total, g.dim, "");
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(a.in.input, e.what());
  }
  const double seconds = seconds_since(t0);
  H5FieldFile h(a.output, "granoscope-rev");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("frame_to", static_cast<long long>(a.in.to.value_or(-1)));
  h.attr("method", a.method);
  h.attr("mode", g.dim == 2 ? "2d" : g.slab ? "slab" : "3d");
  h.attr("d50", d50);
  h.attr("cell", spec.cell);
  h.attr("step", spec.step);
  h.attr("width", width);
  h.attr("slab_thickness", spec.slab ? spec.slab->thickness : 0.0);
  h.attr("stress_convention", "compression positive; stress_ij = (1/V) sum w l_i f_j");
  h.attr("seconds", seconds);
  write_grid(h, g);
  for (const auto& [n, v] : out.scalar) h.write("/cells/" + n, v);
  for (const auto& [n, v] : out.vector) h.write("/cells/" + n, v);
  for (const auto& [n, v] : out.tensor) h.write("/cells/" + n, v);
  h.commit();
  if (!a.vti.empty()) {
    const Eigen::Vector3d first = g.lo + 0.5 * g.size;
    write_vti_image(a.vti, g.dim == 2 ? Eigen::Vector3d(first.x(), first.y(), 0.0) : first,
                    Eigen::Vector3d::Constant(g.step), g.n, out.arrays());
  }
  if (!a.csv.empty()) write_rev_csv(a, g, out);
  std::cout << "rev (" << a.method << ", "
            << (g.dim == 2 ? "2D"
                : g.slab   ? "slab"
                           : "3D")
            << "): " << g.n[0] << " x " << g.n[1] << " x " << g.n[2] << " cells, "
            << f.particles.size() << " particles, " << branches.particle_contacts << " + "
            << branches.wall_contacts << " wall contacts, " << seconds << " s\n";
}

// ---- shearzone ---------------------------------------------------------------------------

struct ShearArgs {
  FrameArgs in;
  SelectionArgs sel;
  std::string output, csv, field = "rotation";
  GridArgs grid;
};

/// In-plane equivalent shear strain sqrt(((exx - eyy)/2)^2 + exy^2) from the REV displacement
/// map by central differences (one-sided at the edges).
std::vector<double> shear_strain_map(const ga::RevGrid& g, const std::vector<Eigen::Vector3d>& u) {
  const int nu = g.n[0], nv = g.n[1];
  std::vector<Eigen::Vector2d> ul(u.size());
  for (std::size_t c = 0; c < u.size(); ++c) ul[c] = (g.axes * u[c]).head<2>();
  auto at = [&](int i, int j) { return ul[static_cast<std::size_t>(i + nu * j)]; };
  std::vector<double> out(u.size());
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int i0 = std::max(i - 1, 0), i1 = std::min(i + 1, nu - 1);
      const int j0 = std::max(j - 1, 0), j1 = std::min(j + 1, nv - 1);
      const Eigen::Vector2d dx = (at(i1, j) - at(i0, j)) / ((i1 - i0) * g.step);
      const Eigen::Vector2d dy = (at(i, j1) - at(i, j0)) / ((j1 - j0) * g.step);
      const double exx = dx.x(), eyy = dy.y(), exy = 0.5 * (dy.x() + dx.y());
      out[static_cast<std::size_t>(i + nu * j)] = std::hypot(0.5 * (exx - eyy), exy);
    }
  return out;
}

void run_shearzone(const ShearArgs& a) {
  if (a.field != "rotation" && a.field != "shear")
    throw InputError(a.in.input, "--field must be rotation or shear", a.field);
  if (a.field == "shear" && !a.in.to)
    throw InputError(a.in.input, "--field shear needs a displacement: give --to N");
  const Frame f = a.in.load();
  const double d50 = a.in.d50_of(f);
  ga::RevGridSpec spec;
  spec.cell = a.grid.cell_size(a.in.input, d50);
  spec.step = a.grid.step_size(a.in.input, d50);
  if (!f.two_d) {
    SelectionArgs sel = a.sel;
    sel.slab = true;  // always a slab map: default the front view
    spec.slab = sel.make_slab(a.in.input, f, d50);
  }
  ga::ParticleMotion motion;
  if (const auto to = a.in.load_to()) motion = particle_motion(f, *to, a.in.input);
  ga::RevGrid g;
  ga::ScalarMap m;
  ga::ShearZone z;
  try {
    g = ga::make_rev_grid(f, spec);
    const auto r = ga::rev_average(f, ga::contact_branches(f), g, motion);
    m.nu = g.n[0];
    m.nv = g.n[1];
    m.step = g.step;
    m.u0 = g.lo.x() + 0.5 * g.size.x();
    m.v0 = g.lo.y() + 0.5 * g.size.y();
    if (a.field == "rotation") {
      for (double w : rotation_normal(g, r.rotation)) m.value.push_back(std::abs(w));
    } else {
      m.value = shear_strain_map(g, r.displacement);
    }
    z = ga::shear_zone(m);
  } catch (const std::invalid_argument& e) {
    throw InputError(a.in.input, e.what());
  }
  H5FieldFile h(a.output, "granoscope-shearzone");
  h.attr("source", a.in.input);
  h.attr("frame", static_cast<long long>(a.in.frame_index()));
  h.attr("frame_to", static_cast<long long>(a.in.to.value_or(-1)));
  h.attr("field", a.field);
  h.attr("d50", d50);
  h.attr("cell", spec.cell);
  h.attr("step", spec.step);
  h.attr("angle_deg", z.angle_deg);
  h.attr("inclination_deg", z.inclination_deg);
  h.attr("thickness_m", z.thickness);
  h.attr("thickness_mm", 1e3 * z.thickness);
  h.attr("thickness_d50", z.thickness / d50);
  h.attr("lower_m", z.lower_d);
  h.attr("upper_m", z.upper_d);
  h.attr("peak_value", z.peak_value);
  h.attr("by_rows", static_cast<long long>(z.by_rows ? 1 : 0));
  write_grid(h, g);
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
    s->add_option("--method", a->method, "box (REV cells, default) or gaussian (coarse-graining)");
    a->grid.add_to(*s);
    s->add_option("--width", a->width, "gaussian: kernel width (standard deviation) in m");
    s->add_option("--width-d50", a->width_d50, "gaussian: kernel width in d50 (default 1)");
    s->add_option("--particle-density", a->particle_density,
                  "kg/m^3 for particles of unknown mass (default 2650)");
    s->add_option("--vti", a->vti, "also write a VTK image (slab: in its plane coordinates)");
    s->add_option("--csv", a->csv, "also write a CSV: all cells, or the --profile");
    s->add_option("--profile", a->profile, "line x0 y0 z0 x1 y1 z1 for a CSV profile")->expected(6);
    s->add_option("--profile-points", a->profile_points, "points on the profile (default s/2)");
    s->callback([a] { run_rev(*a); });
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
    s->callback([a] { run_shearzone(*a); });
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
    s->callback([a] { run_invariants(*a); });
  }
}

}  // namespace gs::cli
