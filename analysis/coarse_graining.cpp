// Gaussian coarse-graining (MercuryDPM style); kernel and discretisation in the header.
#include "coarse_graining.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace gs::analysis {
namespace {

constexpr double kCut = 4.0;  // kernel cut-off in widths
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double normal_cdf(double x) {
  return 0.5 * std::erfc(-x / std::numbers::sqrt2);
}

// Gauss–Legendre nodes and weights on [0, 1] (Golub–Welsch is overkill for n <= 16: Newton on
// the Legendre polynomial from Chebyshev starts).
void gauss_legendre(int n, std::vector<double>& t, std::vector<double>& w) {
  t.assign(static_cast<std::size_t>(n), 0.0);
  w.assign(static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    t[static_cast<std::size_t>(i)] = 0.5 * (1.0 - x);
    w[static_cast<std::size_t>(i)] = 1.0 / ((1.0 - x * x) * dp * dp);
  }
}

// Kernel weights of the grid points along one axis for a kernel centred at c.
struct Axis {
  double lo = 0.0, s = 1.0, w = 1.0, reach = 0.0, norm = 1.0;
  int n = 1;
  int first(double c) const { return static_cast<int>(std::ceil((c - reach - lo) / s)); }
  int last(double c) const { return static_cast<int>(std::floor((c + reach - lo) / s)); }
  /// The Gaussian's cumulative distribution at y, cut to [c - 4w, c + 4w]: the weight (1/m) of
  /// point k is (edge(x_k + s/2) - edge(x_k - s/2)) / (s norm), so that the weights of all
  /// points sum to 1/s; neighbouring points share an edge.
  double edge(double y, double c) const {
    return normal_cdf((std::clamp(y, c - kCut * w, c + kCut * w) - c) / w);
  }
};

struct Stencil {
  int k0 = 0, k1 = -1;  // clipped to the grid (and to the block along the block axis)
  double g[256];
};

void fill(const Axis& ax, double c, int clip0, int clip1, Stencil& st) {
  st.k0 = std::max(ax.first(c), clip0);
  st.k1 = std::min(ax.last(c), clip1);
  const double scale = 1.0 / (ax.s * ax.norm);
  double lower = ax.edge(ax.lo + (st.k0 - 0.5) * ax.s, c);
  for (int k = st.k0; k <= st.k1; ++k) {
    const double upper = ax.edge(ax.lo + (k + 0.5) * ax.s, c);
    st.g[k - st.k0] = (upper - lower) * scale;
    lower = upper;
  }
}

}  // namespace

CoarseFields coarse_grain(const Frame& frame, const ContactBranches& branches, const RevGrid& g,
                          const CoarseOptions& opt) {
  const double w = opt.width;
  if (!(w > 0.0) || !std::isfinite(w))
    throw std::invalid_argument("kernel width must be > 0 (" + std::to_string(w) + ")");
  if (!(opt.particle_density > 0.0) || !std::isfinite(opt.particle_density))
    throw std::invalid_argument("particle density must be > 0");
  const int na = (g.dim == 2 || g.slab) ? 2 : 3;  // kernel axes on the grid
  const int ba = na - 1;                          // block axis
  std::array<Axis, 3> axes;
  for (int d = 0; d < na; ++d) {
    Axis& a = axes[static_cast<std::size_t>(d)];
    a.lo = g.plane_lo(d, 0) + 0.5 * g.size[d];
    a.s = g.step;
    a.w = w;
    a.reach = kCut * w + 0.5 * g.step;
    a.norm = std::erf(kCut / std::numbers::sqrt2);
    a.n = g.n[d];
  }
  const int span = static_cast<int>(std::floor(2.0 * axes[0].reach / g.step)) + 2;
  if (span > 250) {
    throw std::invalid_argument("kernel width " + std::to_string(w) + " m spans " +
                                std::to_string(span) + " grid steps; increase the step");
  }
  const double half_t = g.slab ? 0.5 * g.size.z() : 0.0;
  auto depth = [&](double z) {  // slab: kernel averaged over the thickness
    return g.slab ? (normal_cdf((half_t - z) / w) - normal_cdf((-half_t - z) / w)) / g.size.z()
                  : 1.0;
  };

  // Particles: local centre, mass, volume, momentum, m v v.
  struct PItem {
    Eigen::Vector3d u;
    double m, v;
    Eigen::Vector3d mv;
    Eigen::Matrix3d mvv;
  };
  std::vector<PItem> pitems;
  for (const auto& p : frame.particles) {
    const Eigen::Vector3d u = g.local(p.position);
    if (g.slab && std::abs(u.z()) > half_t + kCut * w) continue;
    const double vol = g.dim == 2 ? std::numbers::pi * p.radius * p.radius
                                  : 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius, 3);
    const double m = p.mass > 0.0 ? p.mass : opt.particle_density * vol;
    pitems.push_back({u, m, vol, m * p.velocity, m * p.velocity * p.velocity.transpose()});
  }
  // Branches: local start and vector, global l f, quadrature.
  struct BItem {
    Eigen::Vector3d u, l;
    Eigen::Matrix3d lf;
    int nq;
  };
  std::vector<BItem> bitems;
  for (const auto& b : branches.branches) {
    const Eigen::Vector3d l = g.axes * b.branch;
    const int nq = std::min(16, 2 + static_cast<int>(std::ceil(2.0 * l.norm() / w)));
    bitems.push_back({g.local(b.start), l, b.branch * b.force.transpose(), nq});
  }
  std::vector<std::vector<double>> gl_t(17), gl_w(17);
  for (int n = 1; n <= 16; ++n)
    gauss_legendre(n, gl_t[static_cast<std::size_t>(n)], gl_w[static_cast<std::size_t>(n)]);

  // Items sorted by their first stencil index along the block axis (fixed summation order).
  auto order_by = [&](std::size_t count, auto&& lo_of) {
    std::vector<std::pair<int, std::uint32_t>> key(count);
    for (std::size_t i = 0; i < count; ++i) key[i] = {lo_of(i), static_cast<std::uint32_t>(i)};
    std::sort(key.begin(), key.end());
    return key;
  };
  const Axis& bax = axes[static_cast<std::size_t>(ba)];
  const auto porder =
      order_by(pitems.size(), [&](std::size_t i) { return bax.first(pitems[i].u[ba]); });
  const auto border = order_by(bitems.size(), [&](std::size_t i) {
    return bax.first(std::min(bitems[i].u[ba], bitems[i].u[ba] + bitems[i].l[ba]));
  });
  double lmax = 0.0;
  for (const auto& b : bitems) lmax = std::max(lmax, std::abs(b.l[ba]));
  const int bspan = span + static_cast<int>(std::ceil(lmax / g.step)) + 1;

  const std::size_t np = g.count();
  std::vector<double> rho(np, 0.0), nu(np, 0.0);
  std::vector<Eigen::Vector3d> mom(np, Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> mvv(np, Eigen::Matrix3d::Zero()), sc(np, Eigen::Matrix3d::Zero());
  const std::size_t sx = static_cast<std::size_t>(g.n[0]), sy = static_cast<std::size_t>(g.n[1]);
  auto point = [&](int i, int j, int k) {
    return static_cast<std::size_t>(i) +
           sx * (static_cast<std::size_t>(j) + sy * static_cast<std::size_t>(k));
  };

  const int nb = g.n[ba];
  const int block = std::max(8, span);
  const int nblocks = (nb + block - 1) / block;
#pragma omp parallel
  {
    Stencil st[3];
    std::vector<double> kern;
#pragma omp for schedule(dynamic, 1)
    for (int blk = 0; blk < nblocks; ++blk) {
      const int b0 = blk * block, b1 = std::min(nb, b0 + block) - 1;
      std::array<int, 3> c0{0, 0, 0}, c1{g.n[0] - 1, g.n[1] - 1, g.n[2] - 1};
      c0[static_cast<std::size_t>(ba)] = b0;
      c1[static_cast<std::size_t>(ba)] = b1;
      // Particles whose stencil may reach this block, in the global order.
      auto first_at = [](const auto& ord, int key) {
        return std::lower_bound(ord.begin(), ord.end(), std::make_pair(key, std::uint32_t{0}));
      };
      for (auto it = first_at(porder, b0 - span); it != porder.end() && it->first <= b1; ++it) {
        const PItem& p = pitems[it->second];
        bool empty = false;
        for (int d = 0; d < na; ++d) {
          fill(axes[static_cast<std::size_t>(d)], p.u[d], c0[static_cast<std::size_t>(d)],
               c1[static_cast<std::size_t>(d)], st[d]);
          empty = empty || st[d].k1 < st[d].k0;
        }
        if (empty) continue;
        const double dz = depth(p.u.z());
        if (na == 2) st[2] = Stencil{0, 0, {dz}};
        for (int k = st[2].k0; k <= st[2].k1; ++k)
          for (int j = st[1].k0; j <= st[1].k1; ++j) {
            const double gjk = st[1].g[j - st[1].k0] * st[2].g[k - st[2].k0];
            for (int i = st[0].k0; i <= st[0].k1; ++i) {
              const double phi = st[0].g[i - st[0].k0] * gjk;
              const std::size_t q = point(i, j, k);
              rho[q] += phi * p.m;
              nu[q] += phi * p.v;
              mom[q].noalias() += phi * p.mv;
              mvv[q].noalias() += phi * p.mvv;
            }
          }
      }
      // Branches: K(point) = sum_q w_q phi(point - x(t_q)), then sc += K l f.
      for (auto it = first_at(border, b0 - bspan); it != border.end() && it->first <= b1; ++it) {
        const BItem& b = bitems[it->second];
        const auto& tq = gl_t[static_cast<std::size_t>(b.nq)];
        const auto& wq = gl_w[static_cast<std::size_t>(b.nq)];
        std::array<int, 3> u0{0, 0, 0}, u1{0, 0, 0};  // union of the stencils over t
        bool empty = false;
        for (int d = 0; d < na; ++d) {
          const auto& ax = axes[static_cast<std::size_t>(d)];
          const double a = std::min(b.u[d], b.u[d] + b.l[d]), e = std::max(b.u[d], b.u[d] + b.l[d]);
          u0[static_cast<std::size_t>(d)] = std::max(ax.first(a), c0[static_cast<std::size_t>(d)]);
          u1[static_cast<std::size_t>(d)] = std::min(ax.last(e), c1[static_cast<std::size_t>(d)]);
          empty = empty || u1[static_cast<std::size_t>(d)] < u0[static_cast<std::size_t>(d)];
        }
        if (empty) continue;
        const std::size_t ux = static_cast<std::size_t>(u1[0] - u0[0] + 1),
                          uy = static_cast<std::size_t>(u1[1] - u0[1] + 1),
                          uz = static_cast<std::size_t>(u1[2] - u0[2] + 1);
        kern.assign(ux * uy * uz, 0.0);
        for (int q = 0; q < b.nq; ++q) {
          const Eigen::Vector3d x = b.u + tq[static_cast<std::size_t>(q)] * b.l;
          bool none = false;
          for (int d = 0; d < na; ++d) {
            fill(axes[static_cast<std::size_t>(d)], x[d], u0[static_cast<std::size_t>(d)],
                 u1[static_cast<std::size_t>(d)], st[d]);
            none = none || st[d].k1 < st[d].k0;
          }
          if (none) continue;
          if (na == 2) st[2] = Stencil{0, 0, {depth(x.z())}};
          const double wt = wq[static_cast<std::size_t>(q)];
          for (int k = st[2].k0; k <= st[2].k1; ++k)
            for (int j = st[1].k0; j <= st[1].k1; ++j) {
              const double gjk = wt * st[1].g[j - st[1].k0] * st[2].g[k - st[2].k0];
              double* row = kern.data() + ux * (static_cast<std::size_t>(j - u0[1]) +
                                                uy * static_cast<std::size_t>(k - u0[2]));
              for (int i = st[0].k0; i <= st[0].k1; ++i)
                row[i - u0[0]] += st[0].g[i - st[0].k0] * gjk;
            }
        }
        std::size_t q = 0;
        for (int k = u0[2]; k <= u1[2]; ++k)
          for (int j = u0[1]; j <= u1[1]; ++j)
            for (int i = u0[0]; i <= u1[0]; ++i, ++q)
              if (kern[q] != 0.0) sc[point(i, j, k)].noalias() += kern[q] * b.lf;
      }
    }
  }
  CoarseFields f;
  f.density = rho;
  f.solid_fraction = nu;
  f.velocity.resize(np);
  f.kinetic_stress.resize(np);
  f.contact_stress = sc;
  for (std::size_t q = 0; q < np; ++q) {
    if (rho[q] > 0.0) {
      f.velocity[q] = mom[q] / rho[q];
      f.kinetic_stress[q] = mvv[q] - rho[q] * f.velocity[q] * f.velocity[q].transpose();
    } else {
      f.velocity[q] = Eigen::Vector3d::Constant(kNaN);
      f.kinetic_stress[q].setZero();
    }
  }
  return f;
}

}  // namespace gs::analysis
