// Delaunay meshes of particle centres (CGAL, exact predicates): the mesh of the simplex strain
// (tet_strain) and of the Helmholtz–Hodge decomposition (hhd, seed 000 §4.1: "the centre of each
// sphere was a node in the Delaunay triangulation"). 3D tetrahedra, 2D triangles, the vertices on
// the convex hull, and the vertex 1-rings (Delaunay edges).
//
// Degenerate input is rejected with std::invalid_argument: fewer than d+1 points, all points
// coplanar (3D) or collinear (2D), non-finite coordinates, and duplicate centres (the message
// names the first duplicate pair: a vector given twice at one node is ambiguous, so duplicates
// are never merged silently).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace gs::analysis {

/// Simplices of a d-dimensional Delaunay mesh and its hull vertices.
struct DelaunayMesh {
  int dim = 3;
  /// Indices into the input points: 4 per tetrahedron (positively oriented), or 3 per triangle
  /// (counterclockwise) with the fourth slot -1.
  std::vector<std::array<std::int32_t, 4>> simplices;
  std::vector<std::uint8_t> on_hull;  // per input point: 1 on the convex hull
};

/// 3D Delaunay tetrahedra with hull vertices.
DelaunayMesh delaunay_mesh(const std::vector<Eigen::Vector3d>& points);
/// 2D Delaunay triangles of (x, y) with hull vertices.
DelaunayMesh delaunay_mesh(const std::vector<Eigen::Vector2d>& points);

/// Delaunay tetrahedra of the points, positively oriented.
std::vector<std::array<std::int32_t, 4>> delaunay_tetrahedra(
    const std::vector<Eigen::Vector3d>& points);

/// Regular (weighted Delaunay) tetrahedra with weights radii^2; same errors, plus radii of the
/// wrong size or not positive and finite. Hidden points take part in no tetrahedron.
std::vector<std::array<std::int32_t, 4>> regular_tetrahedra(
    const std::vector<Eigen::Vector3d>& points, const std::vector<double>& radii);

/// Delaunay triangles of the (x, y) coordinates, counterclockwise.
std::vector<std::array<std::int32_t, 3>> delaunay_triangles(
    const std::vector<Eigen::Vector2d>& points);

/// Shape quality q = 6 sqrt(2) V / l_rms^3 of a tetrahedron of volume V, l_rms the root-mean-square
/// edge length: 1 for the regular tetrahedron, -> 0 for slivers.
double tetrahedron_quality(const std::array<Eigen::Vector3d, 4>& x, double volume);
/// q = 4 sqrt(3) A / (3 l_rms^2) of a triangle of area A: 1 equilateral, -> 0 flat.
double triangle_quality(const std::array<Eigen::Vector2d, 3>& x, double area);

/// The point indices in Hilbert-curve order (CGAL's hilbert_sort; 2D: of the (x, y)
/// coordinates): consecutive indices are spatial neighbours, so numbering a mesh's unknowns in
/// this order keeps sparse-matrix rows and the vectors they touch close in memory.
std::vector<std::int32_t> hilbert_order(const std::vector<Eigen::Vector3d>& points, int dim);

/// The simplices at each vertex of a mesh of `dim`-simplices, in simplex order: vertex i's are
/// simplex[e] (where it is vertex[e], 0..dim) for e in [offset[i], offset[i+1]). `n_points` >=
/// every vertex index + 1.
struct VertexSimplices {
  std::vector<std::int64_t> offset;
  std::vector<std::int32_t> simplex;
  std::vector<std::int8_t> vertex;
};
VertexSimplices vertex_simplices(int dim, const std::vector<std::array<std::int32_t, 4>>& simplices,
                                 std::size_t n_points);

/// Vertex 1-rings of a mesh of `dim`-simplices (the Delaunay edges) in compressed rows: the
/// neighbours of vertex i are index[offset[i] .. offset[i+1]), sorted ascending. `n_points` >=
/// every vertex index + 1.
struct VertexRings {
  std::vector<std::int64_t> offset;
  std::vector<std::int32_t> index;
  std::size_t size(std::size_t i) const {
    return static_cast<std::size_t>(offset[i + 1] - offset[i]);
  }
};
VertexRings vertex_rings(int dim, const std::vector<std::array<std::int32_t, 4>>& simplices,
                         std::size_t n_points);

}  // namespace gs::analysis
