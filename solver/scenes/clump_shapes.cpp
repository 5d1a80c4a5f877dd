#include "clump_shapes.hpp"

#include <CGAL/Cartesian.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Min_sphere_of_spheres_d.h>
#include <CGAL/Min_sphere_of_spheres_d_traits_3.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/convex_hull_3.h>

#include <cmath>
#include <stdexcept>

#include "specimen_generation.hpp"

namespace gs::solver {

namespace {

std::vector<Eigen::Vector3d> fibonacci_sphere(int n) {
  std::vector<Eigen::Vector3d> u(static_cast<std::size_t>(n));
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1 - 2 * (i + 0.5) / n, s = std::sqrt(1 - z * z);
    u[static_cast<std::size_t>(i)] = {s * std::cos(golden * i), s * std::sin(golden * i), z};
  }
  return u;
}

double feret(const std::vector<ClumpMember>& m, const Eigen::Vector3d& u) {
  double hi = -HUGE_VAL, lo = HUGE_VAL;
  for (const auto& s : m) {
    const double p = s.offset.dot(u);
    hi = std::max(hi, p + s.radius);
    lo = std::min(lo, p - s.radius);
  }
  return hi - lo;
}

/// Local refinement of an extreme caliper width around direction u (coordinate search on the
/// sphere, step halved down to 1e-9 rad).
double refine(const std::vector<ClumpMember>& m, Eigen::Vector3d u, bool maximise) {
  const double sign = maximise ? 1 : -1;
  double best = feret(m, u);
  for (double step = 0.02; step > 1e-9; step *= 0.5) {
    bool moved = true;
    while (moved) {
      moved = false;
      const Eigen::Vector3d a = u.unitOrthogonal(), b = u.cross(a);
      for (const Eigen::Vector3d& d : {a, Eigen::Vector3d(-a), b, Eigen::Vector3d(-b)}) {
        const Eigen::Vector3d v = (u + step * d).normalized();
        const double w = feret(m, v);
        if (sign * (w - best) > 0) {
          best = w;
          u = v;
          moved = true;
        }
      }
    }
  }
  return best;
}

}  // namespace

std::vector<ClumpMember> dimer_clump(double member_radius, double spacing_ratio) {
  if (!(member_radius > 0)) throw std::invalid_argument("dimer: radius must be positive");
  const double h = 0.5 * spacing_ratio * member_radius;
  return {{{-h, 0, 0}, member_radius}, {{h, 0, 0}, member_radius}};
}

std::vector<ClumpMember> asymmetric_clump4(double diameter) {
  if (!(diameter > 0)) throw std::invalid_argument("clump diameter must be positive");
  std::vector<ClumpMember> m = {{{0.0, 0.0, 0.0}, 0.264},
                                {{0.329, 0.0, 0.0}, 0.266},
                                {{0.323, 0.314, 0.0}, 0.260},
                                {{0.034, 0.226, 0.281}, 0.268}};
  // In units of its own largest Feret diameter (0.9999 D as rounded): scale to `diameter`.
  const double d = clump_shape(m, 4000, 16).max_feret;
  for (auto& s : m) {
    s.offset *= diameter / d;
    s.radius *= diameter / d;
  }
  const Eigen::Vector3d c = union_mass_properties(m, 1.0).centroid;
  for (auto& s : m) s.offset -= c;
  return m;
}

ClumpShape clump_shape(const std::vector<ClumpMember>& members, int directions,
                       int surface_points) {
  if (members.empty()) throw std::invalid_argument("clump shape: no members");
  ClumpShape s;
  s.volume = union_mass_properties(members, 1.0).volume;
  // Caliper widths: the extremes over a Fibonacci sphere, each refined locally.
  const auto dirs = fibonacci_sphere(directions);
  std::size_t imax = 0, imin = 0;
  double wmax = -HUGE_VAL, wmin = HUGE_VAL;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    const double w = feret(members, dirs[i]);
    if (w > wmax) wmax = w, imax = i;
    if (w < wmin) wmin = w, imin = i;
  }
  s.max_feret = refine(members, dirs[imax], true);
  s.min_feret = refine(members, dirs[imin], false);
  s.aspect_ratio = s.max_feret / s.min_feret;
  // Smallest enclosing sphere of the member spheres (exact arithmetic on doubles).
  using Traits = CGAL::Min_sphere_of_spheres_d_traits_3<CGAL::Cartesian<double>, double>;
  std::vector<Traits::Sphere> balls;
  for (const auto& m : members)
    balls.emplace_back(Traits::Point(m.offset.x(), m.offset.y(), m.offset.z()), m.radius);
  CGAL::Min_sphere_of_spheres_d<Traits> ms(balls.begin(), balls.end());
  s.enclosing_radius = ms.radius();
  // Convex hull of points on the members' surfaces.
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<K::Point_3> pts;
  const auto surf = fibonacci_sphere(surface_points);
  for (const auto& m : members)
    for (const auto& u : surf) {
      const Eigen::Vector3d x = m.offset + m.radius * u;
      pts.emplace_back(x.x(), x.y(), x.z());
    }
  CGAL::Polyhedron_3<K> hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  double v6 = 0;  // Σ over the hull's faces of det(p0, p1, p2) (triangulated fans)
  for (auto f = hull.facets_begin(); f != hull.facets_end(); ++f) {
    auto h = f->facet_begin();
    const K::Point_3 p0 = h->vertex()->point();
    ++h;
    for (auto next = std::next(h); next != f->facet_begin(); h = next, ++next) {
      const K::Point_3 p1 = h->vertex()->point(), p2 = next->vertex()->point();
      const Eigen::Vector3d a(p0.x(), p0.y(), p0.z()), b(p1.x(), p1.y(), p1.z()),
          c(p2.x(), p2.y(), p2.z());
      v6 += a.dot(b.cross(c));
    }
  }
  s.hull_volume = std::abs(v6) / 6;
  s.convexity_sphere = 4.0 / 3.0 * M_PI * std::pow(s.enclosing_radius, 3) / s.volume;
  s.convexity_hull = s.hull_volume / s.volume;
  return s;
}

Eigen::Quaterniond random_orientation(std::mt19937_64& rng) {
  const double u1 = uniform01(rng), u2 = uniform01(rng), u3 = uniform01(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return Eigen::Quaterniond(b * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2),
                            a * std::cos(2 * M_PI * u2), b * std::sin(2 * M_PI * u3));
}

ClumpReplacement replace_by_clumps(const std::vector<Particle>& spheres,
                                   const std::vector<ClumpMember>& shape, double density,
                                   ClumpMassModel model, std::mt19937_64& rng,
                                   std::int64_t first_id, std::uint32_t first_index) {
  if (shape.empty()) throw std::invalid_argument("clump replacement: empty template");
  const MassProperties unit = union_mass_properties(shape, 1.0);
  ClumpReplacement out;
  std::int64_t id = first_id;
  for (const auto& s : spheres) {
    const double scale = std::cbrt(4.0 / 3.0 * M_PI * std::pow(s.radius, 3) / unit.volume);
    const Eigen::Quaterniond q = random_orientation(rng);
    std::vector<std::uint32_t> index;
    std::vector<Eigen::Vector3d> pos;
    std::vector<double> rad;
    for (const auto& m : shape) {
      Particle p;
      p.id = id++;
      p.position = s.position + q * ((m.offset - unit.centroid) * scale);
      p.radius = m.radius * scale;
      p.velocity = s.velocity;
      index.push_back(first_index + static_cast<std::uint32_t>(out.members.size()));
      pos.push_back(p.position);
      rad.push_back(p.radius);
      out.members.push_back(p);
    }
    out.clumps.push_back(make_clump_body(index, pos, rad, density, model));
  }
  return out;
}

}  // namespace gs::solver
