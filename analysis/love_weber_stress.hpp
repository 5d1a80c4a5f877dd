// Love–Weber stress of a volume from contact forces and branch vectors (seed 004 eq 4.1,
// after Luding 2004), and the boundary form of Li et al. (seed 003 eq 13–14).
//
// Sign convention: COMPRESSION POSITIVE (soil mechanics, as seed 003 §2.2 and eq 13–14).
// Each contact is a branch from the centre of one particle, with branch vector l and the force f
// exerted BY that particle ON the other body:
//   particle–particle: l = x2 - x1 (minimum image in a periodic cell), f = Fn + Fs of the
//                      snapshot (forces by id1 on id2, docs/format.md);
//   particle–wall:     l = contact point - particle centre, f = force by the particle on the wall.
// Then sigma_ij = (1/V) sum_c w_c l_i f_j, w_c the fraction of the branch inside V. For a
// compressive contact f points along l, so sigma_ii > 0. This equals -(1/V) sum_p sum_c
// (x_c - x_p)_i F_j(on p), seed 004 eq 4.1 written with the forces acting on each particle, with
// its sign turned to compression positive. The tensor is not symmetrised (index i: branch,
// j: force); invariants use its symmetric part.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

struct ContactBranch {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();   // particle centre, m
  Eigen::Vector3d branch = Eigen::Vector3d::Zero();  // l, m
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   // f (N), by the start particle
  std::int32_t p1 = -1;       // particle index (frame.particles) at the start
  std::int32_t p2 = -1;       // particle index at the end; -1 for a wall (boundary) contact
  std::int32_t contact = -1;  // index in frame.contacts
};

struct ContactBranches {
  std::vector<ContactBranch> branches;  // in the order of frame.contacts
  std::size_t particle_contacts = 0;
  std::size_t wall_contacts = 0;
  std::size_t skipped = 0;  // neither id is a particle, or a self contact
};

/// Branches of all contacts of a frame. A contact with one particle id and one other id (a wall,
/// facet or any body that is not a sphere of the frame) is a wall contact.
ContactBranches contact_branches(const Frame& frame);

/// Fraction of the segment start + t l, t in [0, 1], inside the box lo <= x < hi (a segment of
/// zero length counts as inside when its point is).
double segment_box_fraction(const Eigen::Vector3d& start, const Eigen::Vector3d& l,
                            const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

/// Love–Weber stress (compression positive) of the axis-aligned box [lo, hi]: each branch
/// weighted by its fraction inside the box, divided by the box volume.
Eigen::Matrix3d love_weber_stress(const std::vector<ContactBranch>& branches,
                                  const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

/// Love–Weber stress (compression positive) of a whole periodic cell: every branch counts in
/// full (with the minimum image each contact is one branch of the periodic volume), divided by
/// the cell volume |det C| (2D frames: the area of the in-plane cell, N/m per unit depth).
/// Throws std::invalid_argument for a frame without a periodic cell or a degenerate cell.
Eigen::Matrix3d periodic_cell_stress(const Frame& frame, const ContactBranches& b);

/// Seed 003 eq 14 without body forces: sigma_ij = -(1/v) sum_beta x_i^beta F_j^beta over the
/// wall contacts, F the force of the wall on the specimen at the contact point x (compression
/// positive). Equals the Love–Weber stress of all contacts when every particle is in equilibrium.
Eigen::Matrix3d boundary_stress(const Frame& frame, const ContactBranches& b, double volume);

}  // namespace gs::analysis
