// Kernel coarse-graining of a snapshot in the style of MercuryDPM (Weinhart et al. 2012, after
// Goldhirsch 2010): continuum fields from particles and contacts with a Gaussian kernel phi of
// width w (standard deviation), cut off at 4 w:
//   density        rho(r)   = sum_i m_i phi(r - x_i)
//   solid fraction nu(r)    = sum_i V_i phi(r - x_i)
//   velocity       V(r)     = sum_i m_i v_i phi(r - x_i) / rho
//   kinetic stress sk(r)    = sum_i m_i v'_i v'_i phi(r - x_i),  v'_i = v_i - V(r)
//   contact stress sc_ij(r) = sum_c l_i f_j int_0^1 phi(r - x_c1 - t l) dt
// with the branches l, f and the sign of love_weber_stress.hpp (COMPRESSION POSITIVE, so both
// stresses are positive in a compressed, agitated packing). The line integral over the branch
// uses Gauss–Legendre points along it (2 + ceil(2 |l| / w), at most 16).
//
// Discretisation: fields are given on the points of a RevGrid (make_point_grid). On each axis the
// kernel weight of grid point k is the Gaussian's integral over the grid interval
// [x_k - s/2, x_k + s/2] divided by s (erf differences), renormalised to the cut-off stencil, so
// every particle (and every quadrature point of a branch) deposits exactly its mass (branch
// tensor) on the grid: sum_points rho s^3 = sum_i m_i and sum_points sc s^3 = sum_c l f to
// round-off when the grid covers the stencils. For s << w this is the point value of the
// Gaussian. On a slab grid the kernel is averaged over the slab thickness T across it
// (depth-averaged fields): the normal factor is [Phi((T/2 - z)/w) - Phi((-T/2 - z)/w)] / T. A 2D
// frame gives areal fields (kg/m^2, N/m).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "love_weber_stress.hpp"
#include "rev_cells.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

struct CoarseFields {
  std::vector<double> density;                  // kg/m^3
  std::vector<double> solid_fraction;           // 1
  std::vector<Eigen::Vector3d> velocity;        // m/s; NaN where rho = 0
  std::vector<Eigen::Matrix3d> kinetic_stress;  // Pa, compression positive
  std::vector<Eigen::Matrix3d> contact_stress;  // Pa, compression positive
};

struct CoarseOptions {
  double width = 0.0;                // w, m (> 0)
  double particle_density = 2650.0;  // kg/m^3, for particles of unknown mass (mass = 0)
};

/// Fields on the points of `grid` (make_point_grid). Parallel over blocks of grid planes;
/// results do not depend on the number of threads. Throws std::invalid_argument for w <= 0.
CoarseFields coarse_grain(const Frame& frame, const ContactBranches& branches, const RevGrid& grid,
                          const CoarseOptions& options);

}  // namespace gs::analysis
