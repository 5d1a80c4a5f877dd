// Triangle meshes (walls, silo and shear-box geometry): the value type and the STL and Wavefront
// OBJ readers, and an ASCII STL writer (docs/io.md, "Triangle meshes").
//
// Orientation: the facet normal of triangle (v0, v1, v2) is normalize((v1 − v0) × (v2 − v1)),
// the convention of STL's counter-clockwise vertex order and of YADE's utils.facet; readers keep
// the vertex order of the file, so orientation is preserved. The normals written in an STL file
// are ignored on reading (they are redundant with the vertex order and often wrong in the wild).
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace gs {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;      // m (after any scale)
  std::vector<std::array<int, 3>> triangles;  // indices into vertices, in file order
  std::vector<int> group;                     // per triangle: index into group_names
  std::vector<std::string> group_names;       // STL `solid NAME`, OBJ `g` / `o`; "mesh"
};

/// Area of the triangle (a, b, c): |(b − a) × (c − b)| / 2.
double triangle_area(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
/// Area of triangle t of the mesh.
double triangle_area(const TriangleMesh& mesh, std::size_t t);
/// Unit facet normal of triangle t: normalize((v1 − v0) × (v2 − v1)).
Eigen::Vector3d triangle_normal(const TriangleMesh& mesh, std::size_t t);

/// True when the triangle has no usable area: twice its area is at most 1e-14 × (its longest
/// edge)², i.e. its vertices are collinear or coincide up to rounding.
bool degenerate_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c);

/// Throws InputError(source, ...) unless the mesh is usable: at least one triangle, finite
/// coordinates, indices in range, one group per triangle naming an existing group, no
/// degenerate triangle ("triangle N has zero area (v0 | v1 | v2)", N counted from 0).
void validate_mesh(const TriangleMesh& mesh, const std::string& source);

/// STL, ASCII or binary (detected: a file that starts with "solid" is ASCII unless its size is
/// exactly 84 + 50·n for the count n in bytes 80–83, or it holds a NUL byte). Identical vertices
/// (exact equality of the three coordinates) are merged, so triangles that share an edge share
/// its vertex indices. ASCII `solid NAME` blocks become groups (one group per distinct name,
/// "mesh" when unnamed); a binary file is one group "mesh".
TriangleMesh read_stl(const std::filesystem::path& path);

/// Wavefront OBJ: `v x y z [w]` and `f` lines (corners `v`, `v/vt`, `v/vt/vn`, `v//vn`;
/// negative indices count back from the last vertex defined so far); a polygon of k corners
/// becomes the fan (c0, c_i, c_i+1), i = 1 … k−2. `g NAME` and `o NAME` start a group (the
/// default group is "mesh"); every other statement is ignored. Vertices are kept as listed.
TriangleMesh read_obj(const std::filesystem::path& path);

/// The DEM8 benchmark's wall files (../shared/dem8, MercuryDPM's OSBenchmark inputs): a header
/// `vertex1_X[m] vertex1_Y[m] ... vertex3_Z[m]`, then one triangle per line, nine numbers
/// separated by blanks (CRLF ends allowed); `#` lines are skipped. Identical vertices merged as
/// in read_stl; one group "mesh".
TriangleMesh read_triangle_text(const std::filesystem::path& path);

/// read_stl, read_obj or read_triangle_text by extension (.stl, .obj, .txt, any case), every
/// coordinate multiplied by
/// `scale` (e.g. 1e-3 for a mesh drawn in millimetres); the scaled mesh is validated again.
/// Throws std::invalid_argument for a scale that is not finite and > 0.
TriangleMesh read_mesh(const std::filesystem::path& path, double scale = 1.0);

/// ASCII STL, one `solid GROUPNAME` per group that has triangles (groups in index order,
/// triangles in mesh order within each), facet normals from the vertex order, every number with
/// 17 significant digits (reading it back gives the same doubles). Written atomically. Throws
/// InputError naming `path` for a mesh validate_mesh refuses.
void write_stl_ascii(const TriangleMesh& mesh, const std::filesystem::path& path);

}  // namespace gs
