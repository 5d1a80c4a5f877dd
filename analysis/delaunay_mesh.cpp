// Delaunay meshes of particle centres with CGAL (exact predicates, inexact constructions).
#include "delaunay_mesh.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "thread_rows.hpp"
#ifdef CGAL_LINKED_WITH_TBB
#include <tbb/task_arena.h>
#endif

#ifdef _OPENMP
#include <omp.h>
#endif

namespace gs::analysis {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3>;
using Delaunay3 = CGAL::Delaunay_triangulation_3<K, Tds3>;
#ifdef CGAL_LINKED_WITH_TBB
// The same triangulation built by threads (CGAL's concurrent insertion, TBB): the tetrahedra are
// unique (CGAL inserts with symbolic perturbation), only their order in memory varies.
using PTds3 = CGAL::Triangulation_data_structure_3<Vb3, CGAL::Delaunay_triangulation_cell_base_3<K>,
                                                   CGAL::Parallel_tag>;
using PDelaunay3 = CGAL::Delaunay_triangulation_3<K, PTds3>;
// Below this many points the threads cost more than they save.
constexpr std::size_t kParallelDelaunay = 20000;
#endif
using RVb =
    CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K,
                                                CGAL::Regular_triangulation_vertex_base_3<K>>;
using RCb = CGAL::Regular_triangulation_cell_base_3<K>;
using RTds = CGAL::Triangulation_data_structure_3<RVb, RCb>;
using Regular3 = CGAL::Regular_triangulation_3<K, RTds>;
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2>;
using Delaunay2 = CGAL::Delaunay_triangulation_2<K, Tds2>;

// From this many simplices the counting sorts run on the threads.
constexpr std::size_t kParallelSimplices = 100000;

// The middle of a counting sort done by threads: counts[t][i], thread t's items of key i,
// become the places where thread t writes them (key by key, thread by thread: the threads'
// ranges in order within each key); offset[i] = key i's first place. Returns the total.
template <class Int>
Int counts_to_places(std::vector<std::vector<Int>>& counts, std::size_t keys, Int* offset) {
  Int e = 0;
  for (std::size_t i = 0; i < keys; ++i) {
    offset[i] = e;
    for (auto& c : counts) {
      const Int count = c[i];
      c[i] = e;
      e += count;
    }
  }
  return e;
}

template <class Vec>
[[noreturn]] void throw_duplicate(const std::vector<Vec>& points) {
  std::map<std::vector<double>, std::size_t> seen;
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::vector<double> key(points[i].data(), points[i].data() + points[i].size());
    auto [it, fresh] = seen.emplace(key, i);
    if (!fresh) {
      throw std::invalid_argument("duplicate particle centres (points " +
                                  std::to_string(it->second) + " and " + std::to_string(i) + ")");
    }
  }
  throw std::invalid_argument("duplicate particle centres");
}

template <class Vec>
void check_input(const std::vector<Vec>& points, std::size_t min_points, const char* what) {
  if (points.size() < min_points) {
    throw std::invalid_argument(std::string("Delaunay ") + what + " need at least " +
                                std::to_string(min_points) + " points (" +
                                std::to_string(points.size()) + ")");
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw std::invalid_argument("non-finite particle centre (point " + std::to_string(i) + ")");
    }
  }
}

// Tetrahedra in a canonical form and order, whatever order the triangulation holds them in:
// each rotated by an even permutation (orientation kept) so that its smallest vertex comes first
// and the smallest of the other three second; then sorted (counting sort on the first vertex,
// each thread counting and placing a contiguous range, then a sort of the few sharing it; the
// tetrahedra are distinct, so the order is the same for any number of threads).
void canonical_order(std::vector<std::array<std::int32_t, 4>>& t, std::size_t n_points) {
  using Tet = std::array<std::int32_t, 4>;
  const auto nt = static_cast<std::ptrdiff_t>(t.size());
  const int threads = t.size() >= kParallelSimplices ? max_threads() : 1;
  std::vector<std::vector<std::size_t>> fill(static_cast<std::size_t>(threads));
  std::vector<std::size_t> start(n_points + 1, 0);
  // (not initialised: every place is written once, on the thread that fills it)
  const auto sorted = std::make_unique_for_overwrite<Tet[]>(t.size());
#pragma omp parallel num_threads(threads)
  {
    const int th = thread_number();
    const auto [lo, hi] = thread_share(nt, th, threads);
    auto& mine = fill[static_cast<std::size_t>(th)];
    mine.assign(n_points, 0);
    for (auto kk = lo; kk < hi; ++kk) {
      auto& s = t[static_cast<std::size_t>(kk)];
      const auto first = static_cast<std::size_t>(std::min_element(s.begin(), s.end()) - s.begin());
      if (first != 0) {  // two transpositions: (0 first) and the two other places
        std::size_t o[2], q = 0;
        for (std::size_t a = 1; a < 4; ++a)
          if (a != first) o[q++] = a;
        std::swap(s[0], s[first]);
        std::swap(s[o[0]], s[o[1]]);
      }
      while (s[1] > s[2] || s[1] > s[3]) {  // 3-cycle of the last three
        const std::int32_t x = s[1];
        s[1] = s[2];
        s[2] = s[3];
        s[3] = x;
      }
      ++mine[static_cast<std::size_t>(s[0])];
    }
#pragma omp barrier
#pragma omp single
    start[n_points] = counts_to_places(fill, n_points, start.data());  // (implicit barrier)
    for (auto kk = lo; kk < hi; ++kk) {
      const Tet& s = t[static_cast<std::size_t>(kk)];
      sorted[mine[static_cast<std::size_t>(s[0])]++] = s;
    }
#pragma omp barrier
    const auto np = static_cast<std::ptrdiff_t>(n_points);
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < np; ++i)
      std::sort(sorted.get() + start[static_cast<std::size_t>(i)],
                sorted.get() + start[static_cast<std::size_t>(i) + 1]);
#pragma omp for schedule(static)
    for (std::ptrdiff_t kk = 0; kk < nt; ++kk)
      t[static_cast<std::size_t>(kk)] = sorted[static_cast<std::size_t>(kk)];
  }
}

template <class Triangulation>
DelaunayMesh mesh_of(const Triangulation& dt, const std::vector<Eigen::Vector3d>& points) {
  if (dt.number_of_vertices() != points.size()) throw_duplicate(points);
  if (dt.dimension() < 3) {
    throw std::invalid_argument("all particle centres are coplanar (dimension " +
                                std::to_string(dt.dimension()) + ")");
  }
  DelaunayMesh m;
  m.dim = 3;
  // (room for the finite and infinite cells: their count is O(1), the finite one a pass)
  m.simplices.reserve(dt.number_of_cells());
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    m.simplices.push_back(
        {c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(), c->vertex(3)->info()});
  }
  canonical_order(m.simplices, points.size());
  m.on_hull.assign(points.size(), 0);
  std::vector<typename Triangulation::Vertex_handle> hull;
  dt.finite_adjacent_vertices(dt.infinite_vertex(), std::back_inserter(hull));
  for (const auto& v : hull) m.on_hull[static_cast<std::size_t>(v->info())] = 1;
  return m;
}

}  // namespace

DelaunayMesh delaunay_mesh(const std::vector<Eigen::Vector3d>& points) {
  check_input(points, 4, "tetrahedra");
  std::vector<std::pair<K::Point_3, std::int32_t>> pts;
  pts.reserve(points.size());
  Eigen::AlignedBox3d box;
  for (std::size_t i = 0; i < points.size(); ++i) {
    pts.emplace_back(K::Point_3(points[i].x(), points[i].y(), points[i].z()),
                     static_cast<std::int32_t>(i));
    box.extend(points[i]);
  }
#ifdef CGAL_LINKED_WITH_TBB
  const int threads = max_threads();
  if (threads > 1 && points.size() >= kParallelDelaunay) {
    PDelaunay3::Lock_data_structure lock(
        CGAL::Bbox_3(box.min().x(), box.min().y(), box.min().z(), box.max().x(), box.max().y(),
                     box.max().z()),
        20);  // (a 20³ grid of locks: 5 % faster than 50³ at 5.6e4 points, 2 threads)
    std::optional<PDelaunay3> dt;
    tbb::task_arena arena(threads);
    arena.execute([&] { dt.emplace(pts.begin(), pts.end(), K(), &lock); });  // spatially sorted
    return mesh_of(*dt, points);  // (outside the arena: its loops are OpenMP's)
  }
#endif
  const Delaunay3 dt(pts.begin(), pts.end());  // spatially sorted insertion
  return mesh_of(dt, points);
}

DelaunayMesh delaunay_mesh(const std::vector<Eigen::Vector2d>& points) {
  check_input(points, 3, "triangles");
  std::vector<std::pair<K::Point_2, std::int32_t>> pts;
  pts.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pts.emplace_back(K::Point_2(points[i].x(), points[i].y()), static_cast<std::int32_t>(i));
  }
  const Delaunay2 dt(pts.begin(), pts.end());
  if (dt.number_of_vertices() != points.size()) throw_duplicate(points);
  if (dt.dimension() < 2) {
    throw std::invalid_argument("all particle centres are collinear (dimension " +
                                std::to_string(dt.dimension()) + ")");
  }
  DelaunayMesh m;
  m.dim = 2;
  m.simplices.reserve(dt.number_of_faces());
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
    m.simplices.push_back({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info(), -1});
  }
  m.on_hull.assign(points.size(), 0);
  auto c = dt.incident_vertices(dt.infinite_vertex()), done = c;
  do {
    if (!dt.is_infinite(c)) m.on_hull[static_cast<std::size_t>(c->info())] = 1;
  } while (++c != done);
  return m;
}

std::vector<std::array<std::int32_t, 4>> delaunay_tetrahedra(
    const std::vector<Eigen::Vector3d>& points) {
  return delaunay_mesh(points).simplices;
}

std::vector<std::array<std::int32_t, 3>> delaunay_triangles(
    const std::vector<Eigen::Vector2d>& points) {
  const auto m = delaunay_mesh(points);
  std::vector<std::array<std::int32_t, 3>> tris;
  tris.reserve(m.simplices.size());
  for (const auto& s : m.simplices) tris.push_back({s[0], s[1], s[2]});
  return tris;
}

std::vector<std::array<std::int32_t, 4>> regular_tetrahedra(
    const std::vector<Eigen::Vector3d>& points, const std::vector<double>& radii) {
  if (radii.size() != points.size()) {
    throw std::invalid_argument("one radius per point needed (" + std::to_string(radii.size()) +
                                " for " + std::to_string(points.size()) + ")");
  }
  for (std::size_t i = 0; i < radii.size(); ++i) {
    if (!(radii[i] > 0.0) || !std::isfinite(radii[i])) {
      throw std::invalid_argument("radius not positive (point " + std::to_string(i) + ")");
    }
  }
  // The Delaunay checks (count, finite, duplicates; coplanar below) with the same messages.
  check_input(points, 4, "tetrahedra");
  {
    std::vector<std::vector<double>> keys;
    keys.reserve(points.size());
    for (const auto& p : points) keys.push_back({p.x(), p.y(), p.z()});
    std::sort(keys.begin(), keys.end());
    if (std::adjacent_find(keys.begin(), keys.end()) != keys.end()) throw_duplicate(points);
  }
  std::vector<std::pair<K::Weighted_point_3, std::int32_t>> pts;
  pts.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    pts.emplace_back(K::Weighted_point_3(K::Point_3(points[i].x(), points[i].y(), points[i].z()),
                                         radii[i] * radii[i]),
                     static_cast<std::int32_t>(i));
  }
  const Regular3 rt(pts.begin(), pts.end());
  if (rt.dimension() < 3) {
    throw std::invalid_argument("all particle centres are coplanar (dimension " +
                                std::to_string(rt.dimension()) + ")");
  }
  std::vector<std::array<std::int32_t, 4>> tets;
  tets.reserve(rt.number_of_finite_cells());
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    tets.push_back(
        {c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(), c->vertex(3)->info()});
  }
  return tets;
}

double tetrahedron_quality(const std::array<Eigen::Vector3d, 4>& x, double volume) {
  double l2 = 0.0;
  for (std::size_t a = 0; a < 4; ++a)
    for (std::size_t b = a + 1; b < 4; ++b) l2 += (x[b] - x[a]).squaredNorm();
  const double lrms = std::sqrt(l2 / 6.0);
  return lrms > 0.0 ? 6.0 * std::sqrt(2.0) * volume / (lrms * lrms * lrms) : 0.0;
}

double triangle_quality(const std::array<Eigen::Vector2d, 3>& x, double area) {
  double l2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) l2 += (x[(a + 1) % 3] - x[a]).squaredNorm();
  const double lrms2 = l2 / 3.0;
  return lrms2 > 0.0 ? 4.0 * std::sqrt(3.0) * area / (3.0 * lrms2) : 0.0;
}

std::vector<std::int32_t> hilbert_order(const std::vector<Eigen::Vector3d>& points, int dim) {
  std::vector<std::size_t> order(points.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  if (dim == 2) {
    std::vector<K::Point_2> p;
    p.reserve(points.size());
    for (const auto& x : points) p.emplace_back(x.x(), x.y());
    using Traits =
        CGAL::Spatial_sort_traits_adapter_2<K, CGAL::Pointer_property_map<K::Point_2>::type>;
    CGAL::hilbert_sort(order.begin(), order.end(), Traits(CGAL::make_property_map(p)));
  } else {
    std::vector<K::Point_3> p;
    p.reserve(points.size());
    for (const auto& x : points) p.emplace_back(x.x(), x.y(), x.z());
    using Traits =
        CGAL::Spatial_sort_traits_adapter_3<K, CGAL::Pointer_property_map<K::Point_3>::type>;
    const Traits traits(CGAL::make_property_map(p));
#ifdef CGAL_LINKED_WITH_TBB
    const int threads = max_threads();
    if (threads > 1 && points.size() >= kParallelDelaunay) {
      // CGAL's parallel median split makes the same cuts as the sequential one (disjoint ranges
      // sorted side by side): the same order.
      tbb::task_arena arena(threads);
      arena.execute(
          [&] { CGAL::hilbert_sort<CGAL::Parallel_tag>(order.begin(), order.end(), traits); });
      return std::vector<std::int32_t>(order.begin(), order.end());
    }
#endif
    CGAL::hilbert_sort(order.begin(), order.end(), traits);
  }
  return std::vector<std::int32_t>(order.begin(), order.end());
}

VertexSimplices vertex_simplices(int dim, const std::vector<std::array<std::int32_t, 4>>& simplices,
                                 std::size_t n_points) {
  const int nv = dim + 1;
  // A counting sort by vertex, stable: each thread counts the vertices of a contiguous range of
  // simplices, then writes them from its own starts (after the ranges before it), so each
  // vertex's simplices come in simplex order whatever the number of threads.
  const int threads = simplices.size() >= kParallelSimplices ? max_threads() : 1;
  const auto ns = static_cast<std::ptrdiff_t>(simplices.size());
  std::vector<std::vector<std::int64_t>> start(static_cast<std::size_t>(threads));
  VertexSimplices v;
  v.offset.assign(n_points + 1, 0);
#pragma omp parallel num_threads(threads)
  {
    const int t = thread_number();
    auto& mine = start[static_cast<std::size_t>(t)];
    mine.assign(n_points, 0);
    const auto [lo, hi] = thread_share(ns, t, threads);
    for (auto k = lo; k < hi; ++k)
      for (int a = 0; a < nv; ++a)
        ++mine[static_cast<std::size_t>(
            simplices[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)])];
#pragma omp barrier
#pragma omp single
    {
      const std::int64_t e = counts_to_places(start, n_points, v.offset.data());
      v.offset[n_points] = e;
      v.simplex.resize(static_cast<std::size_t>(e));
      v.vertex.resize(static_cast<std::size_t>(e));
    }  // (implicit barrier)
    for (auto k = lo; k < hi; ++k)
      for (int a = 0; a < nv; ++a) {
        const auto i = static_cast<std::size_t>(
            simplices[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)]);
        const auto e = static_cast<std::size_t>(mine[i]++);
        v.simplex[e] = static_cast<std::int32_t>(k);
        v.vertex[e] = static_cast<std::int8_t>(a);
      }
  }
  return v;
}

VertexRings vertex_rings(int dim, const std::vector<std::array<std::int32_t, 4>>& simplices,
                         std::size_t n_points) {
  const int nv = dim + 1;
  // The simplices at each vertex, then each vertex's ring from them on the threads: the other
  // vertices, deduplicated with a marker, sorted.
  const VertexSimplices at = vertex_simplices(dim, simplices, n_points);
  const std::vector<std::int64_t>& offset = at.offset;
  const auto n = static_cast<std::ptrdiff_t>(n_points);
  const int threads = max_threads();
  std::vector<std::vector<std::int32_t>> part(static_cast<std::size_t>(threads));
  VertexRings r;
  r.offset.assign(n_points + 1, 0);
#pragma omp parallel num_threads(threads)
  {
    const int t = thread_number();
    const auto [lo, hi] = thread_share(n, t, threads);
    auto& out = part[static_cast<std::size_t>(t)];
    // (room for one entry per simplex at a vertex, ~1.7 times a Delaunay ring: no regrowth;
    // pages never written are never touched)
    out.reserve(static_cast<std::size_t>(offset[static_cast<std::size_t>(hi)] -
                                         offset[static_cast<std::size_t>(lo)]));
    std::vector<std::ptrdiff_t> mark(n_points, -1);
    std::vector<std::int32_t> ring;
    for (std::ptrdiff_t i = lo; i < hi; ++i) {
      const auto e0 = offset[static_cast<std::size_t>(i)],
                 e1 = offset[static_cast<std::size_t>(i) + 1];
      ring.resize(static_cast<std::size_t>(nv * (e1 - e0)));
      // Every candidate written, kept (the count advanced) when new: no branch to mispredict.
      std::size_t q = 0;
      for (auto e = e0; e < e1; ++e) {
        const auto& s =
            simplices[static_cast<std::size_t>(at.simplex[static_cast<std::size_t>(e)])];
        for (int b = 0; b < nv; ++b) {
          const std::int32_t j = s[static_cast<std::size_t>(b)];
          auto& mj = mark[static_cast<std::size_t>(j)];
          ring[q] = j;
          q += static_cast<std::size_t>(j != i && mj != i);
          mj = i;
        }
      }
      std::sort(ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(q));
      out.insert(out.end(), ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(q));
      r.offset[static_cast<std::size_t>(i) + 1] = static_cast<std::int64_t>(q);
    }
#pragma omp barrier
#pragma omp single
    {
      for (std::size_t i = 0; i < n_points; ++i) r.offset[i + 1] += r.offset[i];
      r.index.resize(static_cast<std::size_t>(r.offset[n_points]));
    }  // (implicit barrier; each thread's rings then copied to their place)
    std::copy(
        out.begin(), out.end(),
        r.index.begin() + static_cast<std::ptrdiff_t>(r.offset[static_cast<std::size_t>(lo)]));
  }
  return r;
}

}  // namespace gs::analysis
