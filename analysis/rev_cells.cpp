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

  CellSums& operator+=(const CellSums& o) {
    volume += o.volume;
    fraction += o.fraction;
    z_weighted += o.z_weighted;
    centres += o.centres;
    matched_volume += o.matched_volume;
    rotation += o.rotation;
    displacement += o.displacement;
    stress += o.stress;
    return *this;
  }

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

constexpr int kMaxTable = 4096;

// The planes of all cells along one axis, sorted and distinct: elementary intervals
// [p[e], p[e + 1]); cell i covers the intervals first[i] .. last[i] - 1.
struct AxisPlanes {
  std::vector<double> p;
  std::vector<int> first, last;
  int intervals() const { return static_cast<int>(p.size()) - 1; }
  /// The interval holding x (p[e] <= x < p[e + 1]), or -1.
  int containing(double x) const {
    const auto e = std::upper_bound(p.begin(), p.end(), x) - p.begin() - 1;
    return e >= 0 && e < intervals() ? static_cast<int>(e) : -1;
  }
};

AxisPlanes axis_planes(const RevGrid& g, int d) {
  AxisPlanes a;
  if (d >= g.dim) {  // 2D frame: one unbounded interval
    a.p = {-kInf, kInf};
    a.first = {0};
    a.last = {1};
    return a;
  }
  for (int i = 0; i < g.n[d]; ++i) {
    a.p.push_back(g.plane_lo(d, i));
    a.p.push_back(g.plane_hi(d, i));
  }
  std::sort(a.p.begin(), a.p.end());
  a.p.erase(std::unique(a.p.begin(), a.p.end()), a.p.end());
  for (int i = 0; i < g.n[d]; ++i) {
    a.first.push_back(
        static_cast<int>(std::lower_bound(a.p.begin(), a.p.end(), g.plane_lo(d, i)) - a.p.begin()));
    a.last.push_back(
        static_cast<int>(std::lower_bound(a.p.begin(), a.p.end(), g.plane_hi(d, i)) - a.p.begin()));
  }
  return a;
}

// Sums along axis d of an array of shape dims (x fastest) over each cell's intervals; the result
// has g.n[d] entries along that axis (dims is updated).
std::vector<CellSums> window_sums(const std::vector<CellSums>& in, std::array<int, 3>& dims, int d,
                                  const AxisPlanes& a) {
  std::array<int, 3> od = dims;
  od[d] = static_cast<int>(a.first.size());
  std::vector<CellSums> out(static_cast<std::size_t>(od[0]) * od[1] * od[2]);
  const std::array<int, 3> stride_in{1, dims[0], dims[0] * dims[1]};
  const std::array<int, 3> stride_out{1, od[0], od[0] * od[1]};
  const int o1 = (d + 1) % 3, o2 = (d + 2) % 3;
  const auto rows = static_cast<std::ptrdiff_t>(od[o1]) * od[o2];
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t rr = 0; rr < rows; ++rr) {
    const int u = static_cast<int>(rr % od[o1]), v = static_cast<int>(rr / od[o1]);
    const std::size_t bin = static_cast<std::size_t>(u * stride_in[o1] + v * stride_in[o2]);
    const std::size_t bout = static_cast<std::size_t>(u * stride_out[o1] + v * stride_out[o2]);
    for (int i = 0; i < od[d]; ++i) {
      CellSums& s = out[bout + static_cast<std::size_t>(i * stride_out[d])];
      for (int e = a.first[static_cast<std::size_t>(i)]; e < a.last[static_cast<std::size_t>(i)];
           ++e)
        s += in[bin + static_cast<std::size_t>(e * stride_in[d])];
    }
  }
  dims = od;
  return out;
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

namespace {

/// Grid of cells of side spec.cell (> 0), or of points (spec.cell = 0, `points`).
RevGrid make_grid(const Frame& frame, const RevGridSpec& spec, bool points) {
  if (points) {
    if (spec.cell != 0.0)
      throw std::invalid_argument("a grid of points has cell size 0 (" + std::to_string(spec.cell) +
                                  ")");
  } else if (!(spec.cell > 0.0) || !std::isfinite(spec.cell)) {
    throw std::invalid_argument("REV cell size must be > 0 (" + std::to_string(spec.cell) + ")");
  }
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
  } else {
    const auto [blo, bhi] = particle_bounds(frame);
    elo = blo;
    ehi = bhi;
  }
  if (spec.region) {  // slab: in-plane (local x, y) bounds; 2D frame: x, y; 3D: the box
    for (int d = 0; d < axes_used; ++d) {
      elo[d] = spec.region->first[d];
      ehi[d] = spec.region->second[d];
      if (!std::isfinite(elo[d]) || !std::isfinite(ehi[d]) || !(elo[d] < ehi[d]))
        throw std::invalid_argument("region must have lo < hi on every axis");
    }
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
    const double m = std::round(spec.cell / spec.step);
    if (m >= 1.0 && std::abs(spec.cell - m * spec.step) <= 1e-12 * spec.cell)
      g.cell_steps[d] = static_cast<int>(m);
  }
  if (static_cast<double>(g.n[0]) * g.n[1] * g.n[2] > 5e8)
    throw std::invalid_argument("too many REV cells; increase the step");
  return g;
}

/// REV averages divide by the cell measure: a grid of points has none.
void check_cells(const RevGrid& g) {
  if (!(g.measure() > 0.0))
    throw std::invalid_argument(
        "REV averages need cells of size > 0 (a grid of points is for "
        "coarse-graining)");
}

}  // namespace

RevGrid make_rev_grid(const Frame& frame, const RevGridSpec& spec) {
  return make_grid(frame, spec, false);
}

RevGrid make_point_grid(const Frame& frame, const RevGridSpec& spec) {
  return make_grid(frame, spec, true);
}

// ---- averages -------------------------------------------------------------------------------

RevFields rev_average(const Frame& frame, const ContactBranches& branches, const RevGrid& g,
                      const ParticleMotion& motion) {
  check_cells(g);
  check_motion(frame, motion);
  const bool with_motion = !motion.matched.empty();
  const std::vector<double> z = contact_counts(frame, branches);
  const std::array<AxisPlanes, 3> ax{axis_planes(g, 0), axis_planes(g, 1), axis_planes(g, 2)};
  const std::array<int, 3> ne{ax[0].intervals(), ax[1].intervals(), ax[2].intervals()};
  const auto box = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>(i + ne[0] * (j + ne[1] * k));
  };
  std::vector<CellSums> elem(static_cast<std::size_t>(ne[0]) * ne[1] * ne[2]);

  // Spheres: exact volume in each elementary box they touch.
  struct Reach {
    std::array<int, 3> e0{}, e1{}, k0{}, k1{};  // intervals e0..e1; interior planes k0..k1-1
    std::size_t offset = 0, count = 0;
  };
  const std::size_t np = frame.particles.size();
  std::vector<Reach> reach(np);
  std::vector<Eigen::Vector3d> local(np);
  const auto nps = static_cast<std::ptrdiff_t>(np);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t ii = 0; ii < nps; ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    const double r = frame.particles[i].radius;
    local[i] = g.local(frame.particles[i].position);
    Reach& q = reach[i];
    q.count = 1;
    for (int d = 0; d < 3; ++d) {
      const auto& p = ax[static_cast<std::size_t>(d)].p;
      if (d >= g.dim) {  // 2D frame: no third axis
        q.e0[d] = q.e1[d] = q.k0[d] = q.k1[d] = 0;
        continue;
      }
      const double c = local[i][d];
      q.k0[d] = static_cast<int>(std::upper_bound(p.begin(), p.end(), c - r) - p.begin());
      q.k1[d] = static_cast<int>(std::lower_bound(p.begin(), p.end(), c + r) - p.begin());
      q.e0[d] = std::max(q.k0[d] - 1, 0);
      q.e1[d] = std::min(q.k1[d] - 1, ne[d] - 1);
      if (q.e1[d] < q.e0[d]) q.count = 0;
      if (q.count) q.count *= static_cast<std::size_t>(q.e1[d] - q.e0[d] + 1);
    }
  }
  std::size_t total = 0;
  for (auto& q : reach) {
    q.offset = total;
    total += q.count;
  }
  std::vector<std::pair<std::uint32_t, double>> deposit(total);
#pragma omp parallel
  {
    std::vector<double> table, alpha[3];
#pragma omp for schedule(dynamic, 256)
    for (std::ptrdiff_t ii = 0; ii < nps; ++ii) {
      const auto i = static_cast<std::size_t>(ii);
      const Reach& q = reach[i];
      if (q.count == 0) continue;
      const double r = frame.particles[i].radius;
      const Eigen::Vector3d& c = local[i];
      std::array<int, 3> m{1, 1, 1};
      for (int d = 0; d < g.dim; ++d) {
        alpha[d].assign(1, 0.0);  // slot 0: the offset 0; slot 1 + t: interior plane k0 + t
        for (int k = q.k0[d]; k < q.k1[d]; ++k)
          alpha[d].push_back(
              std::abs(ax[static_cast<std::size_t>(d)].p[static_cast<std::size_t>(k)] - c[d]));
        m[d] = static_cast<int>(alpha[d].size());
      }
      const bool direct = m[0] * m[1] * m[2] > kMaxTable;
      if (!direct) {
        table.resize(static_cast<std::size_t>(m[0] * m[1] * m[2]));
        std::size_t t = 0;
        for (int k = 0; k < m[2]; ++k)
          for (int j = 0; j < m[1]; ++j)
            for (int a = 0; a < m[0]; ++a)
              table[t++] = g.dim == 2
                               ? disc_quadrant_area(r, alpha[0][static_cast<std::size_t>(a)],
                                                    alpha[1][static_cast<std::size_t>(j)])
                               : sphere_octant_volume(r, alpha[0][static_cast<std::size_t>(a)],
                                                      alpha[1][static_cast<std::size_t>(j)],
                                                      alpha[2][static_cast<std::size_t>(k)]);
      }
      std::size_t out = q.offset;
      for (int ek = q.e0[2]; ek <= q.e1[2]; ++ek)
        for (int ej = q.e0[1]; ej <= q.e1[1]; ++ej)
          for (int ei = q.e0[0]; ei <= q.e1[0]; ++ei) {
            const std::array<int, 3> e{ei, ej, ek};
            SlotTerm terms[3][3];
            int nt[3] = {1, 1, 1};
            terms[2][0] = {0, 1.0};
            bool full = true;
            Eigen::Vector3d blo, bhi;
            for (int d = 0; d < g.dim; ++d) {
              const auto& p = ax[static_cast<std::size_t>(d)].p;
              blo[d] = p[static_cast<std::size_t>(e[d])];
              bhi[d] = p[static_cast<std::size_t>(e[d] + 1)];
              // A plane that is not interior to the sphere by the index tests above (k0, k1)
              // has no slot in the table: treat it as beyond the sphere. Deciding by the
              // offset instead (p - c < r) can disagree by one rounding for a plane tangent to
              // the sphere, and read a slot of the next table row.
              const double lo_off = e[d] < q.k0[d] ? -kInf : blo[d] - c[d];
              const double hi_off = e[d] + 1 >= q.k1[d] ? kInf : bhi[d] - c[d];
              bool fd = false;
              nt[d] = cell_terms(lo_off, hi_off, r, 1 + e[d] - q.k0[d], 2 + e[d] - q.k0[d],
                                 terms[d], fd);
              full = full && fd;
            }
            double v = 0.0;
            if (full) {
              v = ball_measure(g.dim, r);
            } else if (direct) {
              if (g.dim == 2) blo.z() = -kInf, bhi.z() = kInf;
              v = measure_in_box(g.dim, c, r, blo, bhi);
            } else {
              const auto mx = static_cast<std::size_t>(m[0]), my = static_cast<std::size_t>(m[1]);
              for (int a = 0; a < nt[2]; ++a)
                for (int b = 0; b < nt[1]; ++b) {
                  const double cab = terms[2][a].coef * terms[1][b].coef;
                  const std::size_t row = mx * (static_cast<std::size_t>(terms[1][b].slot) +
                                                my * static_cast<std::size_t>(terms[2][a].slot));
                  for (int t = 0; t < nt[0]; ++t)
                    v += cab * terms[0][t].coef *
                         table[row + static_cast<std::size_t>(terms[0][t].slot)];
                }
            }
            deposit[out++] = {box(ei, ej, ek), v};
          }
    }
  }
  for (std::size_t i = 0; i < np; ++i) {  // fixed order: deterministic sums
    const Particle& p = frame.particles[i];
    const double vb = ball_measure(g.dim, p.radius);
    const Reach& q = reach[i];
    for (std::size_t k = q.offset; k < q.offset + q.count; ++k)
      if (deposit[k].second > 0.0)
        elem[deposit[k].first].add_particle(deposit[k].second, vb, p, z[i], false, motion, i);
    std::array<int, 3> e{0, 0, 0};
    bool in = true;
    for (int d = 0; d < g.dim; ++d) {
      e[d] = ax[static_cast<std::size_t>(d)].containing(local[i][d]);
      in = in && e[d] >= 0;
    }
    if (in) elem[box(e[0], e[1], e[2])].centres += 1.0;
  }

  // Branches: pieces between the planes, each in one elementary box.
  const auto& br = branches.branches;
  const auto nb = static_cast<std::ptrdiff_t>(br.size());
  std::vector<std::size_t> boffset(br.size() + 1, 0);
  for (std::size_t k = 0; k < br.size(); ++k) {
    const Eigen::Vector3d a = g.local(br[k].start), l = g.axes * br[k].branch;
    std::size_t cuts = 0;
    for (int d = 0; d < g.dim; ++d) {
      const auto& p = ax[static_cast<std::size_t>(d)].p;
      const double lo = std::min(a[d], a[d] + l[d]), hi = std::max(a[d], a[d] + l[d]);
      cuts += static_cast<std::size_t>(std::lower_bound(p.begin(), p.end(), hi) -
                                       std::upper_bound(p.begin(), p.end(), lo));
    }
    boffset[k + 1] = boffset[k] + cuts + 1;
  }
  std::vector<std::pair<std::uint32_t, double>> piece(boffset.back(), {0u, 0.0});
#pragma omp parallel
  {
    std::vector<double> ts;
#pragma omp for schedule(dynamic, 1024)
    for (std::ptrdiff_t kk = 0; kk < nb; ++kk) {
      const auto k = static_cast<std::size_t>(kk);
      const Eigen::Vector3d a = g.local(br[k].start), l = g.axes * br[k].branch;
      ts.assign({0.0, 1.0});
      for (int d = 0; d < g.dim; ++d) {
        if (l[d] == 0.0) continue;
        const auto& p = ax[static_cast<std::size_t>(d)].p;
        const double lo = std::min(a[d], a[d] + l[d]), hi = std::max(a[d], a[d] + l[d]);
        for (auto it = std::upper_bound(p.begin(), p.end(), lo); it != p.end() && *it < hi; ++it)
          ts.push_back((*it - a[d]) / l[d]);
      }
      std::sort(ts.begin(), ts.end());
      std::size_t out = boffset[k];
      for (std::size_t t = 0; t + 1 < ts.size(); ++t) {
        const double w = ts[t + 1] - ts[t];
        if (!(w > 0.0)) continue;
        const Eigen::Vector3d mid = a + 0.5 * (ts[t] + ts[t + 1]) * l;
        std::array<int, 3> e{0, 0, 0};
        bool in = true;
        for (int d = 0; d < g.dim; ++d) {
          e[d] = ax[static_cast<std::size_t>(d)].containing(l[d] == 0.0 ? a[d] : mid[d]);
          in = in && e[d] >= 0;
        }
        if (in) piece[out++] = {box(e[0], e[1], e[2]), w};
      }
    }
  }
  for (std::size_t k = 0; k < br.size(); ++k) {
    const Eigen::Matrix3d lf = br[k].branch * br[k].force.transpose();
    for (std::size_t t = boffset[k]; t < boffset[k + 1]; ++t)
      if (piece[t].second > 0.0) elem[piece[t].first].stress.noalias() += piece[t].second * lf;
  }

  // Cells: sums of their elementary boxes, axis by axis.
  std::array<int, 3> dims = ne;
  for (int d = 0; d < 3; ++d) elem = window_sums(elem, dims, d, ax[static_cast<std::size_t>(d)]);
  RevFields f = empty_fields(g.count(), with_motion);
  const double cell_measure = g.measure();
  for (std::size_t c = 0; c < g.count(); ++c) finish(elem[c], c, cell_measure, with_motion, f);
  return f;
}

RevFields rev_average_brute_force(const Frame& frame, const ContactBranches& branches,
                                  const RevGrid& g, const ParticleMotion& motion,
                                  const std::vector<std::size_t>& cells) {
  check_cells(g);
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
