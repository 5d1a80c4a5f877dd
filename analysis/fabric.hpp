// Contact-normal fabric after Kanatani (seed 003 §4.1, eq 18–21):
//   M_ij = (1/N_p) sum_k n_i^k n_j^k    (eq 20; the sum runs over the contact points C^AB and
//                                        C^BA separately, i.e. twice per contact, as seed 003
//                                        counts them, so omega = M_ii = 2 N_contacts / N_p is the
//                                        usual coordination number)
//   D_ij = 15/2 (M_ij / omega - delta_ij / 3)   (eq 21, 3D)
// so that E(n) = (1 + D_ij n_i n_j) / (4 pi) (eq 18) has the second moment M / omega. In 2D the
// same construction with E(theta) = (1 + D_ij n_i n_j) / (2 pi) gives D = 4 (M/omega - delta/2).
// |D| = sqrt(D_ij D_ij); for N uniformly random normals its expectation is about sqrt(37.5 / N)
// in 3D and sqrt(8 / N) in 2D (sampling error).
//
// Particle-orientation fabric D^p for non-spherical bodies (the two-sphere clumps of seed 003
// §2.4; D^p is defined in §4.3 by E^p(n) = (1 + D^p_ij n_i n_j) / E_0, "determined using the
// similar methodology" as the contact fabric, i.e. eq 20–21 with the long axes m of the bodies in
// place of the contact normals): Phi_ij = <m_i m_j> over the clumps (eq 20 with N_c = N_p, each
// axis once; m and -m give the same term, so Phi has trace 1 = omega), and
// D^p = 15/2 (Phi - I/3) (eq 21; 2D: 4 (Phi - I/2)). The long axis m comes from
//  - the clump bodies when the frame has them (Frame::clumps): the principal axis of the smallest
//    principal moment of inertia (the long axis of an elongated body);
//  - else the members (imported data with clump_id and no bodies): the principal direction of
//    the largest second moment of the members' volumes about their volume centroid.
// For a two-sphere clump both give the line through the two centres.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

struct Fabric {
  int dim = 3;
  std::size_t particles = 0;  // N_p
  std::size_t contacts = 0;   // pair contacts (each gives two contact points)
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  double omega = 0.0;
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
  double D_norm = 0.0;
  Eigen::Vector3d D_principal = Eigen::Vector3d::Zero();   // decreasing
  Eigen::Matrix3d D_directions = Eigen::Matrix3d::Zero();  // columns
};

/// Fabric of the given contact normals (any sign) among `particles` particles; 2D uses the
/// (x, y) components. Throws std::invalid_argument for no particle or no contact.
Fabric contact_fabric(const std::vector<Eigen::Vector3d>& normals, std::size_t particles, int dim);

enum class OrientationSource {
  None,     // no clumps in the frame
  Bodies,   // from the clump bodies' principal frames
  Members,  // from the members' volume second moments
};

const char* orientation_source_name(OrientationSource s);

struct OrientationFabric {
  OrientationSource source = OrientationSource::None;
  std::size_t bodies = 0;  // clumps with a long axis (members: at least two; bodies: a distinct
                           // smallest principal moment)
  Eigen::Matrix3d Phi = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
  double D_norm = 0.0;
  std::vector<std::int64_t> clump;        // clump ids
  std::vector<Eigen::Vector3d> axis;      // long axis per clump (unit; sign arbitrary)
  std::vector<Eigen::Vector3d> centroid;  // volume centroid (members) / centre of mass (bodies)
};

/// The long axis of a clump body: the principal axis (a column of the orientation's rotation
/// matrix) of the smallest principal moment of inertia; nullopt when that moment is not
/// distinctly the smallest (relative gap < 1e-9: no long axis, e.g. a one-sphere clump).
std::optional<Eigen::Vector3d> clump_long_axis(const Clump& clump);

/// Orientation fabric from the clump bodies (2D: axes projected on the x-y plane).
OrientationFabric body_orientation_fabric(const std::vector<Clump>& clumps, int dim);
/// Orientation fabric from the members (particles with clump_id >= 0) of the frame.
OrientationFabric member_orientation_fabric(const Frame& frame);
/// Bodies when the frame has clump bodies, else members (bodies = 0 when there are no clumps).
OrientationFabric orientation_fabric(const Frame& frame);

}  // namespace gs::analysis
