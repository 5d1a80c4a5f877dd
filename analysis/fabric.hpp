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
// Particle-orientation fabric for non-spherical bodies (clumps of spheres, seed 003 §2.4): the
// long axis m of each clump (principal direction of the largest second moment of its members'
// volumes about the clump centroid), Phi_ij = <m_i m_j> over the clumps, and its anisotropy
// 15/2 (Phi - I/3) (2D: 4 (Phi - I/2)).
#pragma once

#include <Eigen/Core>
#include <cstddef>
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

struct OrientationFabric {
  std::size_t bodies = 0;  // clumps with at least two members
  Eigen::Matrix3d Phi = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
  double D_norm = 0.0;
  std::vector<std::int64_t> clump;        // clump ids
  std::vector<Eigen::Vector3d> axis;      // long axis per clump (unit; sign arbitrary)
  std::vector<Eigen::Vector3d> centroid;  // volume centroid per clump
};

/// Orientation fabric of the clumps of a frame (bodies = 0 when there are none).
OrientationFabric orientation_fabric(const Frame& frame);

}  // namespace gs::analysis
