// Wall loads from particle–wall contacts (seed 004 §5.3.1): the force the granular material
// exerts on each wall, its distribution along the wall, and the silo resultants
//   P   the vertical force on the bottom (sum over bottom-wall contacts),
//   T   the vertical friction force on a side wall (vertical components of normal + tangential
//       contact forces), N the horizontal force on it, phi_w = atan(T / N) the mobilised wall
//       friction angle,
//   G   the weight of the material, with G = sum_side T + P in equilibrium.
// "Vertical" is the `up` direction (default +z). A plane wall (normal b pointing into the
// material) is a bottom wall when b . up > 0.9, a top wall when b . up < -0.9, a side wall when
// |b . up| < 0.1. Signs: N_w = -F . b (compression positive), T_w = -F . up on side walls
// (downward drag on the wall positive; on other walls T_w is the magnitude of the tangential
// force), phi_w = atan(T_w / N_w), P = -F_bottom . up.
// Distribution: contacts binned along an axis in the wall plane (side walls: up; others: the
// lab axis closest to the wall plane's first direction), sigma_n = sum(-F . b) / (bin x width),
// tau = sum(-F . axis) / (bin x width), width the extent of the material across the axis in the
// wall plane (or given). Box walls get totals only. A body in wall contacts that the snapshot does
// not list among its walls (YADE facets or boxes exported without walls) is taken as a plane
// through its mean contact point, its normal the mean direction from the contact points to the
// particle centres (`inferred`).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "love_weber_stress.hpp"
#include "snapshot.hpp"

namespace gs::analysis {

struct WallOptions {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double bin = 0.0;       // m, > 0
  double width = 0.0;     // m; 0: extent of the particles across the binning axis (2D: 1 m)
  double gravity = 9.81;  // m/s^2, for G
  double particle_density = 2650.0;  // kg/m^3, for particles of unknown mass
};

struct WallLoad {
  std::int64_t id = 0;
  std::string role;                                    // "bottom", "top", "side", "other", "box"
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // plane walls: b
  Eigen::Vector3d force = Eigen::Vector3d::Zero();     // sum over its contacts, by the material, N
  Eigen::Vector3d recorded = Eigen::Vector3d::Zero();  // Wall::force of the snapshot
  bool inferred = false;  // body not among the snapshot's walls: plane fitted to its contacts
  std::size_t contacts = 0;
  double N = 0.0, T = 0.0, phi_deg = 0.0;          // see header (NaN for box walls)
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // binning axis
  double width = 0.0;
  std::vector<double> position, sigma_n, tau, count;  // bin centres (m along axis), Pa, Pa, -
};

struct WallLoads {
  std::vector<WallLoad> walls;
  double G = 0.0, P = 0.0, T = 0.0, N = 0.0, phi_deg = 0.0;  // T, N: sums over side walls
};

/// Throws std::invalid_argument for a bad bin, width, up vector or no wall contact.
WallLoads wall_loads(const Frame& frame, const ContactBranches& branches,
                     const WallOptions& options);

/// The options of `analyze walls` as given: the bin in m or in d50 (default 5 d50), the
/// width when given.
struct WallSpec {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::optional<double> bin, bin_d50, width;  // m, d50, m
  double gravity = 9.81, particle_density = 2650.0;
};

struct WallReport {
  WallOptions options;  // as resolved (bin in m)
  WallLoads loads;
};

/// `analyze walls` as one call (CLI and Python). Throws InputError naming `file` and the
/// option (--bin, --width, --gravity, --particle-density) or the problem (no wall contact).
WallReport wall_report(const std::string& file, const Frame& frame, double d50,
                       const WallSpec& spec);

}  // namespace gs::analysis
