// REV maps and shear bands of a frame (see rev_map.hpp; methods: docs/analysis.md).
#include "rev_map.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "coarse_graining.hpp"
#include "errors.hpp"
#include "frame_motion.hpp"
#include "love_weber_stress.hpp"
#include "tensor_invariants.hpp"

namespace gs::analysis {
namespace {

/// Invariants of each cell's stress (symmetric part; compression positive).
void add_invariants(MapFields& f, const std::vector<Eigen::Matrix3d>& stress, int dim) {
  std::vector<double> p, q, eta, phi, b, lode;
  for (const auto& s : stress) {
    const auto inv = stress_invariants(s, dim);
    p.push_back(inv.p);
    q.push_back(inv.q);
    eta.push_back(inv.eta);
    phi.push_back(inv.phi_mob_deg);
    b.push_back(inv.b);
    lode.push_back(inv.lode_deg);
  }
  f.scalar.emplace_back("p", p);
  f.scalar.emplace_back("q", q);
  f.scalar.emplace_back("eta", eta);
  f.scalar.emplace_back("phi_mob_deg", phi);
  if (dim == 3) {
    f.scalar.emplace_back("b", b);
    f.scalar.emplace_back("lode_deg", lode);
  }
}

/// In-plane equivalent shear strain sqrt(((exx - eyy)/2)^2 + exy^2) from the REV displacement
/// map by central differences (one-sided at the edges).
std::vector<double> shear_strain_map(const RevGrid& g, const std::vector<Eigen::Vector3d>& u) {
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

}  // namespace

double GridSpec::cell_size(const std::string& file, double d50) const {
  return length_option(file, "--cell", cell, cell_d50, 5.0, d50);
}

double GridSpec::step_size(const std::string& file, double d50) const {
  return length_option(file, "--step", step, step_d50, 1.0, d50);
}

std::vector<VtkArray> MapFields::arrays() const {
  std::vector<VtkArray> a;
  for (const auto& [n, v] : scalar) a.push_back({n, 1, v});
  for (const auto& [n, v] : vector) a.push_back({n, 3, flat_rows(v)});
  for (const auto& [n, v] : tensor) a.push_back({n, 9, flat_rows(v)});
  return a;
}

std::string RevMap::mode() const {
  return grid.dim == 2 ? "2d" : grid.slab ? "slab" : "3d";
}

ParticleMotion particle_motion(const Frame& f, const Frame& to, const std::string& file) {
  const FrameMotion m = motion_between(f, to, file);
  ParticleMotion pm;
  pm.u.assign(f.particles.size(), Eigen::Vector3d::Zero());
  pm.matched.assign(f.particles.size(), 0);
  for (std::size_t k = 0; k < m.index.size(); ++k) {
    pm.u[static_cast<std::size_t>(m.index[k])] = m.u[k];
    pm.matched[static_cast<std::size_t>(m.index[k])] = 1;
  }
  return pm;
}

std::vector<double> rotation_normal(const RevGrid& g, const std::vector<Eigen::Vector3d>& r) {
  const Eigen::Vector3d n = g.axes.row(2);
  std::vector<double> out;
  out.reserve(r.size());
  for (const auto& x : r) out.push_back(x.dot(n));
  return out;
}

RevMap rev_map(const std::string& file, const Frame& f, const Frame* to, double d50,
               const RevMapSpec& spec) {
  if (spec.method != "box" && spec.method != "gaussian")
    throw InputError(file, "--method must be box or gaussian", spec.method);
  const bool gauss = spec.method == "gaussian";
  RevMap out;
  out.method = spec.method;
  out.d50 = d50;
  RevGridSpec g;
  g.cell = gauss ? 0.0 : spec.grid.cell_size(file, d50);
  g.step = spec.grid.step_size(file, d50);
  g.slab = spec.selection.make_slab(file, f, d50);
  g.region = spec.selection.make_region(file);
  if (g.region && g.slab)
    throw InputError(file, "--region is for 3D grids; a slab map spans its plane");
  out.cell = g.cell;
  out.step = g.step;
  out.slab_thickness = g.slab ? g.slab->thickness : 0.0;
  out.width = gauss ? length_option(file, "--width", spec.width, spec.width_d50, 1.0, d50) : 0.0;
  require_positive(file, "--particle-density", spec.particle_density);
  ParticleMotion motion;
  if (to) motion = particle_motion(f, *to, file);
  const auto t0 = std::chrono::steady_clock::now();
  const auto branches = contact_branches(f);
  out.particle_contacts = branches.particle_contacts;
  out.wall_contacts = branches.wall_contacts;
  MapFields& m = out.fields;
  try {
    out.grid = gauss ? make_point_grid(f, g) : make_rev_grid(f, g);
    const RevGrid& grid = out.grid;
    if (!gauss) {
      const auto r = rev_average(f, branches, grid, motion);
      m.scalar = {{"void_ratio", r.void_ratio},
                  {"solid_fraction", r.solid_fraction},
                  {"solid_volume", r.solid_volume},
                  {"particles", r.particles},
                  {"coordination", r.coordination}};
      if (grid.slab || grid.dim == 2)
        m.scalar.emplace_back("rotation_normal", rotation_normal(grid, r.rotation));
      m.vector.emplace_back("rotation", r.rotation);
      if (!r.displacement.empty()) m.vector.emplace_back("displacement", r.displacement);
      m.tensor.emplace_back("stress", r.stress);
      add_invariants(m, r.stress, grid.dim);
    } else {
      const auto c = coarse_grain(f, branches, grid, {out.width, spec.particle_density});
      std::vector<double> e;
      for (double nu : c.solid_fraction) e.push_back(nu > 0.0 ? 1.0 / nu - 1.0 : std::nan(""));
      std::vector<Eigen::Matrix3d> total;
      for (std::size_t k = 0; k < c.contact_stress.size(); ++k)
        total.push_back(c.contact_stress[k] + c.kinetic_stress[k]);
      m.scalar = {{"density", c.density}, {"solid_fraction", c.solid_fraction}, {"void_ratio", e}};
      m.vector.emplace_back("velocity", c.velocity);
      m.tensor = {{"stress", total},
                  {"stress_contact", c.contact_stress},
                  {"stress_kinetic", c.kinetic_stress}};
      add_invariants(m, total, grid.dim);
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::vector<VtkArray> rev_cell_table(const RevMap& map) {
  const RevGrid& g = map.grid;
  std::vector<Eigen::Vector3d> centre, local;
  for (std::size_t c = 0; c < g.count(); ++c) {
    centre.push_back(g.centre(c));
    local.push_back(g.local(centre.back()));
  }
  std::vector<VtkArray> cols{{"centre", 3, flat_rows(centre)}, {"local", 3, flat_rows(local)}};
  for (auto& arr : map.fields.arrays()) cols.push_back(std::move(arr));
  return cols;
}

std::vector<VtkArray> rev_profile(const std::string& file, const RevMap& map,
                                  const std::vector<double>& line, int points) {
  if (line.size() != 6) throw InputError(file, "--profile needs 6 numbers x0 y0 z0 x1 y1 z1");
  const Eigen::Vector3d p0(line[0], line[1], line[2]), p1(line[3], line[4], line[5]);
  if (!p0.allFinite() || !p1.allFinite() || !((p1 - p0).norm() > 0.0))
    throw InputError(file, "--profile needs two distinct finite points");
  const int n = points > 0
                    ? points
                    : static_cast<int>(std::ceil((p1 - p0).norm() / (0.5 * map.grid.step))) + 1;
  if (n < 2 || n > 10000000)
    throw InputError(file, "--profile-points must be in 2..1e7", std::to_string(n));
  std::vector<double> dist;
  std::vector<Eigen::Vector3d> pts;
  std::vector<std::vector<std::pair<std::size_t, double>>> w;
  for (int k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / (n - 1);
    pts.push_back(p0 + t * (p1 - p0));
    dist.push_back(t * (p1 - p0).norm());
    w.push_back(rev_interpolation(map.grid, pts.back()));
  }
  std::vector<VtkArray> cols{{"distance", 1, dist}, {"point", 3, flat_rows(pts)}};
  for (const auto& arr : map.fields.arrays()) {
    VtkArray c{arr.name, arr.components, {}};
    for (const auto& wk : w)
      for (int j = 0; j < arr.components; ++j) {
        double v = wk.empty() ? std::nan("") : 0.0;
        for (const auto& [cell, wt] : wk)
          v += wt * arr.values[cell * static_cast<std::size_t>(arr.components) +
                               static_cast<std::size_t>(j)];
        c.values.push_back(v);
      }
    cols.push_back(std::move(c));
  }
  return cols;
}

ShearZoneMap shear_zone_map(const std::string& file, const Frame& f, const Frame* to, double d50,
                            const ShearZoneSpec& spec) {
  if (spec.field != "rotation" && spec.field != "shear")
    throw InputError(file, "--field must be rotation or shear", spec.field);
  if (spec.field == "shear" && !to)
    throw InputError(file, "--field shear needs a displacement: give --to N");
  ShearZoneMap out;
  out.d50 = d50;
  RevGridSpec g;
  g.cell = out.cell = spec.grid.cell_size(file, d50);
  g.step = out.step = spec.grid.step_size(file, d50);
  if (!f.two_d) {
    SelectionSpec sel = spec.selection;
    sel.slab = true;  // always a slab map: default the front view
    g.slab = sel.make_slab(file, f, d50);
  }
  ParticleMotion motion;
  if (to) motion = particle_motion(f, *to, file);
  ScalarMap& m = out.map;
  try {
    out.grid = make_rev_grid(f, g);
    const RevGrid& grid = out.grid;
    const auto r = rev_average(f, contact_branches(f), grid, motion);
    m.nu = grid.n[0];
    m.nv = grid.n[1];
    m.step = grid.step;
    m.u0 = grid.lo.x() + 0.5 * grid.size.x();
    m.v0 = grid.lo.y() + 0.5 * grid.size.y();
    if (spec.field == "rotation") {
      for (double w : rotation_normal(grid, r.rotation)) m.value.push_back(std::abs(w));
    } else {
      m.value = shear_strain_map(grid, r.displacement);
    }
    out.zone = shear_zone(m);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  return out;
}

}  // namespace gs::analysis
