// Wall surfaces as triangle meshes (docs/scenes.md, "Wall surfaces"): the saw-tooth asperities
// of seed 004 (§4.3 interface shear, §5.2 silo walls, Fig 5.2: groove height h_g, spacing s_g,
// inclination α_g; normalized roughness R_n = h_g/d50), the sinusoidal corrugation of seed 004
// §4.4 (wavelength l, depth d) and a closed box.
//
// Patch frame (saw-tooth and sinusoid). A wall is a rectangular patch over the base plane
// through `origin`: e_u = `along` (normalized) is the profile direction — across the ridges,
// i.e. the shearing or flow direction —, e_n = `normal` (normalized, perpendicular to e_u) points
// into the granular material, and e_v = e_n × e_u runs along the ridges (so e_u, e_v, e_n is
// right-handed). A point of the surface is origin + u·e_u + v·e_v + h(u)·e_n for u ∈ [0, L],
// v ∈ [0, W]; the profile h(u) is the height above the base plane. Ridges are straight along
// e_v, so each strip between two consecutive profile nodes is one quad, split into two
// triangles along its diagonal from (u_i, 0) to (u_i+1, W). Every facet normal
// normalize((v1 − v0) × (v2 − v1)) points to the material side (the side e_n points to), as in
// the YADE facets reference silo. The patch ends at u = 0 and u = L are at height 0, in the base
// plane (but see SawToothSpec::end_face); the ends at v = 0 and v = W are open (the adjoining side
// walls close them).
#pragma once

#include <Eigen/Core>
#include <string>

#include "triangle_mesh.hpp"

namespace gs::solver {

/// Saw-tooth asperities: teeth of height h_g repeated every s_g along e_u. Tooth k starts at
/// u_k = k·s_g: a ramp rises at α_g to the tip (u_k + a, h_g), a = h_g / tan α_g, then the back
/// face descends at `back_slope_deg` (90°: a step normal to the base plane, the default) to
/// (u_k + a + c, 0), c = h_g / tan(back slope), and a flat land at height 0 runs to u_k+1. So
/// s_g is the pitch (tip to tip), a + c ≤ s_g is the tooth's base, and s_g = a + c (within
/// 1e-9·s_g; the tip then lies on the pitch) gives the plain saw-tooth without land. Teeth are
/// placed while they fit wholly in [0, L] (L = n·s_g gives n teeth); any rest is land. The ramp
/// rises along +e_u; reverse `along` to mirror.
struct SawToothSpec {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d along = Eigen::Vector3d::UnitX();   // e_u
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // e_n, into the material
  double length_m = 0;                                // L along e_u
  double width_m = 0;                                 // W along e_v
  double height_m = 0;                                // h_g = R_n · d50
  double spacing_m = 0;                               // s_g (pitch)
  double slope_deg = 45;       // α_g, the ramp's inclination to the base plane, in (0, 90)
  double back_slope_deg = 90;  // the back face's inclination, in [α_g, 90]
  // The vertical back face of a last tooth that ends exactly at u = L lies in the plane u = L;
  // false leaves it out, for an adjoining wall that covers it (the bottom of the YADE facets
  // silo), so that the two do not overlap.
  bool end_face = true;
  std::string group = "saw_tooth";
};

/// Sinusoidal corrugation h(u) = d/2 · sin(2πu/l) (d: depth, trough to crest; l: wavelength).
/// Profile nodes at u_i = i·l/N (N = `segments_per_wavelength` ≥ 2) up to L, plus u = L when L is
/// not a whole number of segments (the last segment is then shorter). The height at u = 0 and at
/// whole wavelengths is 0 (the base plane is the corrugation's mid-plane).
struct SinusoidSpec {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d along = Eigen::Vector3d::UnitX();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double length_m = 0;
  double width_m = 0;
  double depth_m = 0;       // d ≥ 0 (0: flat)
  double wavelength_m = 0;  // l
  int segments_per_wavelength = 32;
  std::string group = "sinusoid";
};

/// Saw-tooth wall (one group, `spec.group`). Throws std::invalid_argument naming the parameter
/// and its value for h_g ≤ 0, s_g ≤ 0, α_g outside (0, 90), a back slope outside [α_g, 90],
/// a tooth base a + c wider than s_g, L < a + c (no tooth fits), W ≤ 0, or a bad frame.
TriangleMesh saw_tooth_wall(const SawToothSpec& spec);

/// Sinusoidal wall (one group, `spec.group`). Throws std::invalid_argument for l ≤ 0, d < 0,
/// N < 2, L ≤ 0, W ≤ 0 or a bad frame.
TriangleMesh sinusoidal_wall(const SinusoidSpec& spec);

enum class BoxFacing { Inward, Outward };

/// The box [lo, hi]: 8 vertices, 12 triangles, one group per face ("x_min", "x_max", "y_min",
/// "y_max", "z_min", "z_max", each of 2 triangles). Inward (the default): every facet normal
/// points into the box, the side the particles of a container are on, as for the patches
/// above; Outward for an obstacle. Closed: every edge is shared by exactly two triangles.
/// Throws std::invalid_argument unless lo < hi in every coordinate (all finite).
TriangleMesh box_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                      BoxFacing facing = BoxFacing::Inward);

}  // namespace gs::solver
