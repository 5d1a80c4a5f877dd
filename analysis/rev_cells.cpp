// REV cell maps (seed 000 §3, seed 004 §4.2.3 and eq 4.1); method and conventions in the header
// and docs/analysis.md.
#include "rev_cells.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "sphere_box_volume.hpp"

namespace gs::analysis {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double ball_measure(int dim, double r) {
  return dim == 2 ? kPi * r * r : 4.0 / 3.0 * kPi * r * r * r;
}

double measure_in_box(int dim, const Eigen::Vector3d& c, double r, const Eigen::Vector3d& lo,
                      const Eigen::Vector3d& hi) {
  return dim == 2 ? disc_rectangle_area(c.head<2>(), r, lo.head<2>(), hi.head<2>())
                  : sphere_box_volume(c, r, lo, hi);
}

std::string axis_name(int d) {
  return std::string(1, static_cast<char>('x' + d));
}

// Per-cell sums; finish() turns them into the fields of one cell.
struct CellSums {
  double volume = 0.0, fraction = 0.0, z_weighted = 0.0, centres = 0.0, matched_volume = 0.0;
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero(), displacement = Eigen::Vector3d::Zero();
  Eigen::Matrix3d stress = Eigen::Matrix3d::Zero();

  void add_particle(double v, double v_ball, const Particle& p, double z, bool centre_inside,
                    const ParticleMotion& m, std::size_t i) {
    volume += v;
    fraction += v / v_ball;
    z_weighted += z * v / v_ball;
    centres += centre_inside ? 1.0 : 0.0;
    rotation += v * p.rotation;
    if (!m.matched.empty() && m.matched[i]) {
      matched_volume += v;
      displacement += v * m.u[i];
    }
  }
};

void finish(const CellSums& s, std::size_t c, double cell_measure, bool with_motion, RevFields& f) {
  f.solid_volume[c] = s.volume;
  f.solid_fraction[c] = s.volume / cell_measure;
  f.void_ratio[c] = s.volume > 0.0 ? (cell_measure - s.volume) / s.volume : kNaN;
  f.particles[c] = s.centres;
  f.coordination[c] = s.fraction > 0.0 ? s.z_weighted / s.fraction : kNaN;
  f.rotation[c] =
      s.volume > 0.0 ? Eigen::Vector3d(s.rotation / s.volume) : Eigen::Vector3d::Constant(kNaN);
  if (with_motion) {
    f.displacement[c] = s.matched_volume > 0.0 ? Eigen::Vector3d(s.displacement / s.matched_volume)
                                               : Eigen::Vector3d::Constant(kNaN);
  }
  f.stress[c] = s.stress / cell_measure;
}

RevFields empty_fields(std::size_t n, bool with_motion) {
  RevFields f;
  f.solid_volume.assign(n, 0.0);
  f.solid_fraction.assign(n, 0.0);
  f.void_ratio.assign(n, 0.0);
  f.particles.assign(n, 0.0);
  f.coordination.assign(n, 0.0);
  f.rotation.assign(n, Eigen::Vector3d::Zero());
  if (with_motion) f.displacement.assign(n, Eigen::Vector3d::Zero());
  f.stress.assign(n, Eigen::Matrix3d::Zero());
  return f;
}

std::vector<double> contact_counts(const Frame& frame, const ContactBranches& b) {
  std::vector<double> z(frame.particles.size(), 0.0);
  for (const auto& br : b.branches) {
    if (br.p2 < 0) continue;
    z[static_cast<std::size_t>(br.p1)] += 1.0;
    z[static_cast<std::size_t>(br.p2)] += 1.0;
  }
  return z;
}

void check_motion(const Frame& frame, const ParticleMotion& m) {
  if (!m.matched.empty() &&
      (m.matched.size() != frame.particles.size() || m.u.size() != frame.particles.size())) {
    throw std::invalid_argument("motion must have one entry per particle");
  }
}

// ---- binning ------------------------------------------------------------------------------

// Items (spheres or branch segments) binned on the grid step in local coordinates. An item of
// half-extent <= reach[d] around its local centre can touch cell i only if its centre lies in
// (plane_lo(d, i) - reach, plane_hi(d, i) + reach): bins i .. i + span[d] of the bin grid that
// starts at lo - reach.
struct Bins {
  std::array<int, 3> nb{1, 1, 1}, span{0, 0, 0};
  std::vector<std::int32_t> order;  // item indices sorted by bin (stable)
  std::vector<std::size_t> start;   // per bin, into order (size bins + 1)

  std::size_t bin(int x, int y, int z) const {
    return static_cast<std::size_t>(x) +
           static_cast<std::size_t>(nb[0]) *
               (static_cast<std::size_t>(y) + static_cast<std::size_t>(nb[1]) * z);
  }
};

Bins make_bins(const RevGrid& g, const std::vector<Eigen::Vector3d>& centre,
               const Eigen::Vector3d& reach) {
  Bins b;
  std::vector<std::array<int, 3>> ib(centre.size());
  for (int d = 0; d < 3; ++d) {
    if (g.n[d] <= 1) continue;  // one cell along this axis: one bin
    b.span[d] = static_cast<int>(std::floor((g.size[d] + 2.0 * reach[d]) / g.step)) + 1;
    b.nb[d] = g.n[d] + b.span[d];
  }
  std::vector<std::size_t> count(static_cast<std::size_t>(b.nb[0]) * b.nb[1] * b.nb[2] + 1, 0);
  for (std::size_t k = 0; k < centre.size(); ++k) {
    for (int d = 0; d < 3; ++d) {
      if (g.n[d] <= 1) {
        ib[k][d] = 0;
        continue;
      }
      const double t = std::floor((centre[k][d] - (g.lo[d] - reach[d])) / g.step);
      ib[k][d] = static_cast<int>(std::clamp(t, 0.0, static_cast<double>(b.nb[d] - 1)));
    }
    ++count[b.bin(ib[k][0], ib[k][1], ib[k][2]) + 1];
  }
  for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
  b.start = count;
  b.order.resize(centre.size());
  for (std::size_t k = 0; k < centre.size(); ++k)
    b.order[count[b.bin(ib[k][0], ib[k][1], ib[k][2])]++] = static_cast<std::int32_t>(k);
  return b;
}

// Calls fn(item) for every item binned where it may touch cell (i, j, k), in a fixed order.
template <class Fn>
void for_candidates(const Bins& b, const std::array<int, 3>& ijk, Fn&& fn) {
  std::array<int, 3> b0{}, b1{};
  for (int d = 0; d < 3; ++d) {
    b0[d] = b.nb[d] > 1 ? ijk[d] : 0;
    b1[d] = b.nb[d] > 1 ? std::min(b.nb[d] - 1, ijk[d] + b.span[d]) : 0;
  }
  for (int z = b0[2]; z <= b1[2]; ++z)
    for (int y = b0[1]; y <= b1[1]; ++y) {
      const std::size_t e = b.start[b.bin(b1[0], y, z) + 1];
      for (std::size_t s = b.start[b.bin(b0[0], y, z)]; s < e; ++s) fn(b.order[s]);
    }
}

// ---- per-sphere octant tables ---------------------------------------------------------------

// Planes of the grid that cut a sphere, per axis: the lower planes of cells ilo0 .. ilo0+nlo-1
// and the upper planes of cells ihi0 .. ihi0+nhi-1 lie strictly inside (-r, r) of the centre.
// Slot 0 of an axis is the offset 0; slots 1.. the |offsets| of those planes. `table` holds the
// octant value for every slot triple (x fastest).
struct SphereTable {
  std::array<int, 3> ilo0{}, nlo{}, ihi0{}, nhi{}, m{1, 1, 1};
  std::size_t offset = 0;
  bool direct = false;  // too many planes: volume per cell from sphere_box_volume
};

constexpr int kMaxTable = 343;

SphereTable sphere_planes(const RevGrid& g, const Eigen::Vector3d& c, double r) {
  SphereTable t;
  for (int d = 0; d < g.dim; ++d) {
    t.ilo0[d] = t.ihi0[d] = 0;
    const int i_min =
        std::max(0, static_cast<int>(std::floor((c[d] - r - g.size[d] - g.lo[d]) / g.step)) - 1);
    const int i_max =
        std::min(g.n[d] - 1, static_cast<int>(std::ceil((c[d] + r - g.lo[d]) / g.step)) + 1);
    for (int i = i_min; i <= i_max; ++i) {
      const double lo = g.plane_lo(d, i) - c[d], hi = g.plane_hi(d, i) - c[d];
      if (lo > -r && lo < r) {
        if (t.nlo[d] == 0) t.ilo0[d] = i;
        ++t.nlo[d];
      }
      if (hi > -r && hi < r) {
        if (t.nhi[d] == 0) t.ihi0[d] = i;
        ++t.nhi[d];
      }
    }
    t.m[d] = 1 + t.nlo[d] + t.nhi[d];
  }
  t.direct = t.m[0] * t.m[1] * t.m[2] > kMaxTable;
  return t;
}

void fill_table(const RevGrid& g, const Eigen::Vector3d& c, double r, const SphereTable& t,
                double* table) {
  std::array<std::array<double, kMaxTable>, 3> alpha{};
  for (int d = 0; d < g.dim; ++d) {
    alpha[d][0] = 0.0;
    for (int k = 0; k < t.nlo[d]; ++k)
      alpha[d][1 + k] = std::abs(g.plane_lo(d, t.ilo0[d] + k) - c[d]);
    for (int k = 0; k < t.nhi[d]; ++k)
      alpha[d][1 + t.nlo[d] + k] = std::abs(g.plane_hi(d, t.ihi0[d] + k) - c[d]);
  }
  std::size_t q = 0;
  for (int k = 0; k < t.m[2]; ++k)
    for (int j = 0; j < t.m[1]; ++j)
      for (int i = 0; i < t.m[0]; ++i)
        table[q++] = g.dim == 2 ? disc_quadrant_area(r, alpha[0][i], alpha[1][j])
                                : sphere_octant_volume(r, alpha[0][i], alpha[1][j], alpha[2][k]);
}

struct SlotTerm {
  int slot;
  double coef;
};

// Terms of the cell interval [lo, hi] on one axis (offsets from the centre) as slots of the
// sphere's table (see half_space_terms); returns the count, 0 when the cell misses the sphere.
// Sets `full` when the interval covers the sphere.
int cell_terms(double lo, double hi, double r, int slot_lo, int slot_hi, SlotTerm out[3],
               bool& full) {
  full = lo <= -r && hi >= r;
  int n = 0;
  double whole = 0.0;  // coefficient of slot 0 (the whole ball counts 2 x the half)
  if (lo <= -r) {
    whole += 2.0;
  } else if (lo < 0.0) {
    whole += 2.0;
    out[n++] = {slot_lo, -1.0};
  } else {
    out[n++] = {slot_lo, 1.0};
  }
  if (hi < r) {
    if (hi >= 0.0) {
      out[n++] = {slot_hi, -1.0};
    } else {
      whole -= 2.0;
      out[n++] = {slot_hi, 1.0};
    }
  }
  if (whole != 0.0) out[n++] = {0, whole};
  return n;
}

}  // namespace

// ---- grid -----------------------------------------------------------------------------------

void RevGrid::box(std::size_t c, Eigen::Vector3d& blo, Eigen::Vector3d& bhi) const {
  const auto i = ijk(c);
  for (int d = 0; d < 3; ++d) {
    blo[d] = plane_lo(d, i[d]);
    bhi[d] = plane_hi(d, i[d]);
  }
  if (dim == 2) {
    blo.z() = -kInf;
    bhi.z() = kInf;
  }
}

Eigen::Vector3d RevGrid::centre(std::size_t c) const {
  Eigen::Vector3d blo, bhi;
  box(c, blo, bhi);
  Eigen::Vector3d u = 0.5 * (blo + bhi);
  if (dim == 2) u.z() = 0.0;
  return global(u);
}

RevGrid make_rev_grid(const Frame& frame, const RevGridSpec& spec) {
  if (!(spec.cell >= 0.0) || !std::isfinite(spec.cell))
    throw std::invalid_argument("REV cell size must be > 0 (" + std::to_string(spec.cell) + ")");
  if (!(spec.step > 0.0) || !std::isfinite(spec.step))
    throw std::invalid_argument("REV step must be > 0 (" + std::to_string(spec.step) + ")");
  if (frame.particles.empty()) throw std::invalid_argument("the frame has no particles");
  RevGrid g;
  g.step = spec.step;
  Eigen::Vector3d elo = Eigen::Vector3d::Constant(kInf), ehi = Eigen::Vector3d::Constant(-kInf);
  int axes_used = 3;
  if (frame.two_d) {
    if (spec.slab) throw std::invalid_argument("a slab needs a 3D frame (two_d is set)");
    g.dim = 2;
    axes_used = 2;
    for (const auto& p : frame.particles) {
      elo = elo.cwiseMin(p.position - Eigen::Vector3d::Constant(p.radius));
      ehi = ehi.cwiseMax(p.position + Eigen::Vector3d::Constant(p.radius));
    }
  } else if (spec.slab) {
    g.slab = true;
    g.axes = slab_axes(*spec.slab);
    g.origin = spec.slab->origin;
    axes_used = 2;
    const double half = 0.5 * spec.slab->thickness;
    for (const auto& p : frame.particles) {
      const Eigen::Vector3d u = g.local(p.position);
      if (std::abs(u.z()) >= half + p.radius) continue;
      elo = elo.cwiseMin(u - Eigen::Vector3d::Constant(p.radius));
      ehi = ehi.cwiseMax(u + Eigen::Vector3d::Constant(p.radius));
    }
    if (!(elo.x() < ehi.x())) throw std::invalid_argument("no particle cuts the slab");
    g.lo.z() = -half;
    g.size.z() = spec.slab->thickness;
  } else if (spec.region) {
    elo = spec.region->first;
    ehi = spec.region->second;
    if (!elo.allFinite() || !ehi.allFinite() || !(elo.array() < ehi.array()).all())
      throw std::invalid_argument("region must have lo < hi on every axis");
  } else {
    const auto [blo, bhi] = particle_bounds(frame);
    elo = blo;
    ehi = bhi;
  }
  for (int d = 0; d < axes_used; ++d) {
    const double ext = ehi[d] - elo[d];
    if (!(ext >= spec.cell)) {
      throw std::invalid_argument("the region along " + axis_name(d) + " (" + std::to_string(ext) +
                                  " m) is smaller than one cell (" + std::to_string(spec.cell) +
                                  " m)");
    }
    const double cells = std::floor((ext - spec.cell) / spec.step * (1.0 + 1e-12)) + 1.0;
    if (cells > 1e7) throw std::invalid_argument("REV step too small for the region");
    g.n[d] = static_cast<int>(cells);
    const double used = spec.cell + (g.n[d] - 1) * spec.step;
    g.lo[d] = elo[d] + 0.5 * (ext - used);
    g.size[d] = spec.cell;
  }
  if (static_cast<double>(g.n[0]) * g.n[1] * g.n[2] > 5e8)
    throw std::invalid_argument("too many REV cells; increase the step");
  return g;
}

// ---- averages -------------------------------------------------------------------------------

RevFields rev_average(const Frame& frame, const ContactBranches& branches, const RevGrid& g,
                      const ParticleMotion& motion) {
  check_motion(frame, motion);
  const bool with_motion = !motion.matched.empty();
  const std::size_t ncell = g.count();
  RevFields f = empty_fields(ncell, with_motion);
  const std::vector<double> z = contact_counts(frame, branches);

  // Spheres that can touch a cell, in local coordinates.
  Eigen::Vector3d glo, ghi;
  for (int d = 0; d < 3; ++d) {
    glo[d] = g.plane_lo(d, 0);
    ghi[d] = g.plane_hi(d, g.n[d] - 1);
  }
  std::vector<std::int32_t> sphere;
  std::vector<Eigen::Vector3d> sc;
  double rmax = 0.0;
  for (std::size_t i = 0; i < frame.particles.size(); ++i) {
    const auto& p = frame.particles[i];
    const Eigen::Vector3d u = g.local(p.position);
    bool hit = true;
    for (int d = 0; d < g.dim; ++d)
      hit = hit && u[d] - p.radius < ghi[d] && u[d] + p.radius > glo[d];
    if (!hit) continue;
    sphere.push_back(static_cast<std::int32_t>(i));
    sc.push_back(u);
    rmax = std::max(rmax, p.radius);
  }
  const Bins sbins = make_bins(g, sc, Eigen::Vector3d::Constant(rmax));

  // Octant tables, one per sphere (pooled).
  std::vector<SphereTable> tables(sphere.size());
  const auto ns = static_cast<std::ptrdiff_t>(sphere.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t k = 0; k < ns; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    tables[ks] =
        sphere_planes(g, sc[ks], frame.particles[static_cast<std::size_t>(sphere[ks])].radius);
  }
  std::size_t pool_size = 0;
  for (auto& t : tables) {
    t.offset = pool_size;
    if (!t.direct) pool_size += static_cast<std::size_t>(t.m[0] * t.m[1] * t.m[2]);
  }
  std::vector<double> pool(pool_size);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t k = 0; k < ns; ++k) {
    const auto ks = static_cast<std::size_t>(k);
    if (!tables[ks].direct)
      fill_table(g, sc[ks], frame.particles[static_cast<std::size_t>(sphere[ks])].radius,
                 tables[ks], pool.data() + tables[ks].offset);
  }

  // Branch segments in local coordinates, binned by their mid-points.
  const auto& br = branches.branches;
  std::vector<Eigen::Vector3d> bstart(br.size()), bvec(br.size()), bmid(br.size());
  std::vector<Eigen::Matrix3d> lf(br.size());
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < br.size(); ++k) {
    bstart[k] = g.local(br[k].start);
    bvec[k] = g.axes * br[k].branch;
    bmid[k] = bstart[k] + 0.5 * bvec[k];
    half = half.cwiseMax(0.5 * bvec[k].cwiseAbs());
    lf[k] = br[k].branch * br[k].force.transpose();
  }
  const Bins bbins = make_bins(g, bmid, half);

  const double cell_measure = g.measure();
  const auto nc = static_cast<std::ptrdiff_t>(ncell);
#pragma omp parallel for schedule(dynamic, 32)
  for (std::ptrdiff_t ci = 0; ci < nc; ++ci) {
    const auto c = static_cast<std::size_t>(ci);
    const auto ijk = g.ijk(c);
    Eigen::Vector3d blo, bhi;
    g.box(c, blo, bhi);
    CellSums s;
    for_candidates(sbins, ijk, [&](std::int32_t k) {
      const auto ks = static_cast<std::size_t>(k);
      const auto pi = static_cast<std::size_t>(sphere[ks]);
      const Particle& p = frame.particles[pi];
      const double r = p.radius;
      const Eigen::Vector3d& u = sc[ks];
      const SphereTable& t = tables[ks];
      SlotTerm terms[3][3];
      int nt[3] = {1, 1, 1};
      terms[2][0] = {0, 1.0};  // 2D: no third axis
      bool full = true, inside = true;
      for (int d = 0; d < g.dim; ++d) {
        const int i = ijk[d];
        const double lo = g.plane_lo(d, i) - u[d], hi = g.plane_hi(d, i) - u[d];
        if (!(lo < r && hi > -r)) return;
        inside = inside && lo <= 0.0 && hi > 0.0;
        bool fd = false;
        nt[d] = cell_terms(lo, hi, r, 1 + (i - t.ilo0[d]), 1 + t.nlo[d] + (i - t.ihi0[d]), terms[d],
                           fd);
        full = full && fd;
      }
      double v = 0.0;
      const double vb = ball_measure(g.dim, r);
      if (full) {
        v = vb;
      } else if (t.direct) {
        v = measure_in_box(g.dim, u, r, blo, bhi);
      } else {
        const double* tab = pool.data() + t.offset;
        const auto mx = static_cast<std::size_t>(t.m[0]), my = static_cast<std::size_t>(t.m[1]);
        for (int a = 0; a < nt[2]; ++a)
          for (int b = 0; b < nt[1]; ++b) {
            const double cab = terms[2][a].coef * terms[1][b].coef;
            const std::size_t row = mx * (static_cast<std::size_t>(terms[1][b].slot) +
                                          my * static_cast<std::size_t>(terms[2][a].slot));
            for (int e = 0; e < nt[0]; ++e)
              v += cab * terms[0][e].coef * tab[row + static_cast<std::size_t>(terms[0][e].slot)];
          }
      }
      if (v <= 0.0) return;
      s.add_particle(v, vb, p, z[pi], inside, motion, pi);
    });
    for_candidates(bbins, ijk, [&](std::int32_t k) {
      const auto kb = static_cast<std::size_t>(k);
      const double w = segment_box_fraction(bstart[kb], bvec[kb], blo, bhi);
      if (w > 0.0) s.stress.noalias() += w * lf[kb];
    });
    finish(s, c, cell_measure, with_motion, f);
  }
  return f;
}

RevFields rev_average_brute_force(const Frame& frame, const ContactBranches& branches,
                                  const RevGrid& g, const ParticleMotion& motion,
                                  const std::vector<std::size_t>& cells) {
  check_motion(frame, motion);
  const bool with_motion = !motion.matched.empty();
  RevFields f = empty_fields(g.count(), with_motion);
  const std::vector<double> z = contact_counts(frame, branches);
  std::vector<std::size_t> todo = cells;
  if (todo.empty())
    for (std::size_t c = 0; c < g.count(); ++c) todo.push_back(c);
  std::vector<Eigen::Vector3d> local(frame.particles.size());
  for (std::size_t i = 0; i < local.size(); ++i) local[i] = g.local(frame.particles[i].position);
  const double cell_measure = g.measure();
  for (const std::size_t c : todo) {
    Eigen::Vector3d blo, bhi;
    g.box(c, blo, bhi);
    CellSums s;
    for (std::size_t i = 0; i < frame.particles.size(); ++i) {
      const Particle& p = frame.particles[i];
      const double v = measure_in_box(g.dim, local[i], p.radius, blo, bhi);
      if (v <= 0.0) continue;
      bool inside = true;
      for (int d = 0; d < g.dim; ++d)
        inside = inside && local[i][d] >= blo[d] && local[i][d] < bhi[d];
      s.add_particle(v, ball_measure(g.dim, p.radius), p, z[i], inside, motion, i);
    }
    for (const auto& b : branches.branches) {
      const double w = segment_box_fraction(g.local(b.start), g.axes * b.branch, blo, bhi);
      if (w > 0.0) s.stress.noalias() += w * b.branch * b.force.transpose();
    }
    finish(s, c, cell_measure, with_motion, f);
  }
  return f;
}

std::vector<std::pair<std::size_t, double>> rev_interpolation(const RevGrid& g,
                                                              const Eigen::Vector3d& x) {
  const Eigen::Vector3d u = g.local(x);
  const int axes = g.dim == 2 || g.slab ? 2 : 3;
  std::array<int, 3> i0{0, 0, 0};
  std::array<double, 3> t{0.0, 0.0, 0.0};
  for (int d = 0; d < axes; ++d) {
    const double c0 = g.plane_lo(d, 0) + 0.5 * g.size[d];  // centre of the first cell
    const double q = (u[d] - c0) / g.step;
    if (!(q >= -1e-9 && q <= g.n[d] - 1 + 1e-9)) return {};
    i0[d] = std::clamp(static_cast<int>(std::floor(q)), 0, std::max(0, g.n[d] - 2));
    t[d] = g.n[d] > 1 ? std::clamp(q - i0[d], 0.0, 1.0) : 0.0;
  }
  std::vector<std::pair<std::size_t, double>> out;
  for (int c = 0; c < (1 << axes); ++c) {
    double w = 1.0;
    std::array<int, 3> i = i0;
    for (int d = 0; d < axes; ++d) {
      const int bit = (c >> d) & 1;
      w *= bit ? t[d] : 1.0 - t[d];
      i[d] = std::min(i0[d] + bit, g.n[d] - 1);
    }
    if (w == 0.0) continue;
    out.emplace_back(static_cast<std::size_t>(i[0]) +
                         static_cast<std::size_t>(g.n[0]) *
                             (static_cast<std::size_t>(i[1]) +
                              static_cast<std::size_t>(g.n[1]) * static_cast<std::size_t>(i[2])),
                     w);
  }
  return out;
}

}  // namespace gs::analysis
