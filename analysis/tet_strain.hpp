// Local strain from a Delaunay mesh of particle centres: 3D tetrahedra and 2D triangles.
// Per simplex the displacement gradient H = du/dX of the linear interpolant of its vertex
// displacements (Bagi 1996; seed 002 eq 4 is the 2D triangle form, the 3D form is the same
// construction, as in SPAM's FfieldBagi); per particle the volume-weighted average of H over its
// incident simplices; small-strain parts eps = sym H, omega = skew H.
//
// Sliver criterion (documented in docs/strain.md): quality q = 6*sqrt(2)*V / l_rms^3 (tet) or
// q = 4*sqrt(3)*A / (3*l_rms^2) (triangle), l_rms the root-mean-square edge length; q = 1 for
// the regular simplex and q -> 0 for slivers. Simplices with q < min_quality are flagged and take
// no part in the particle and assembly averages (their own gradient is still reported). Flat
// boundary slivers of the convex hull are the usual case.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "delaunay_mesh.hpp"  // delaunay_tetrahedra, regular_tetrahedra, delaunay_triangles

namespace gs::analysis {

struct SimplexStrainOptions {
  double min_quality = 0.02;  // simplices below are flagged slivers, excluded from averages
  /// 3D only, optional: particle radii; the mesh is then the regular (weighted Delaunay)
  /// triangulation with weights r^2 (radical / power tessellation dual). A particle hidden by
  /// overlapping neighbours gets no tetrahedron and particle_valid = 0.
  std::vector<double> radii;
};

/// Result for a d-dimensional mesh (d = 3: tets, 4 vertices; d = 2: triangles, 3 vertices;
/// unused vertex slots are -1). Gradients are 3x3; in 2D the third row and column are zero.
struct SimplexStrain {
  int dim = 3;
  std::vector<std::array<std::int32_t, 4>> simplices;  // indices into the input points
  std::vector<double> measure;                         // volume (3D) or area (2D), > 0
  std::vector<double> quality;                         // see header comment
  std::vector<std::uint8_t> sliver;                    // 1: excluded from averages
  std::vector<Eigen::Matrix3d> gradient;               // H per simplex
  std::vector<Eigen::Matrix3d> particle_gradient;      // volume-weighted over good simplices
  std::vector<std::uint8_t> particle_valid;  // 0: no good incident simplex (gradient zero)
  Eigen::Matrix3d mean_gradient = Eigen::Matrix3d::Zero();  // measure-weighted, good simplices
  double total_measure = 0.0;
  // Time split of the last computation in seconds (bench/).
  double seconds_delaunay = 0.0, seconds_gradients = 0.0, seconds_averaging = 0.0;
};

/// Displacement gradient of one tetrahedron: H with u(X) = u0 + H (X - X0) through the four
/// vertices. Throws std::invalid_argument when the tetrahedron is flat.
Eigen::Matrix3d tet_gradient(const std::array<Eigen::Vector3d, 4>& x,
                             const std::array<Eigen::Vector3d, 4>& u);

/// 3D: Delaunay of `reference`, gradient of `displacement` (same size; a velocity gives the
/// velocity gradient). OpenMP over simplices; deterministic.
SimplexStrain tet_strain(const std::vector<Eigen::Vector3d>& reference,
                         const std::vector<Eigen::Vector3d>& displacement,
                         const SimplexStrainOptions& options = {});

/// 2D (x, y only): Delaunay triangles, gradient per triangle by Bagi's eq 4 (seed 002).
SimplexStrain triangle_strain(const std::vector<Eigen::Vector2d>& reference,
                              const std::vector<Eigen::Vector2d>& displacement,
                              const SimplexStrainOptions& options = {});

/// Derived small-strain measures of a gradient H (3x3; a 2D gradient has zero third row/col).
struct StrainMeasures {
  Eigen::Matrix3d strain;    // (H + H^T) / 2
  Eigen::Matrix3d rotation;  // (H - H^T) / 2
  double volumetric = 0.0;   // trace(strain) (area strain in 2D)
  // 3D: von Mises equivalent strain sqrt(2/3 e:e), e = eps - tr/3 I.
  // 2D: maximum tensor shear strain sqrt(e:e / 2), e = eps - tr/2 I (in-plane).
  double equivalent_shear = 0.0;
};
StrainMeasures strain_measures(const Eigen::Matrix3d& h, int dim = 3);

}  // namespace gs::analysis
