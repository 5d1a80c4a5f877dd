// Seeded random generation of a loose sphere cloud in a box (specimen preparation, seed 004
// §4.1.2 and §4.2.2: "particles were randomly packed inside the box"), by random sequential
// addition: spheres are placed largest first at uniformly random positions, each rejected and
// redrawn while it overlaps a sphere already placed. Deterministic for a given seed on every
// platform (own uniform variates from std::mt19937_64 bits).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "snapshot.hpp"

namespace gs::solver {

/// Grain-size distribution between dmin and dmax (diameters, m).
///  - Uniform: diameters uniformly distributed by number (seed 004 §4.1.2: "uniform distribution
///    of particle diameters ... from 0.5·d50 to 1.5·d50").
///  - Linear: a straight grading curve, i.e. the mass fraction finer than d grows linearly from
///    dmin to dmax (seed 000 §3: "linear grain distribution curve"); by number the density is
///    ∝ d⁻³, and d50 (by mass) = (dmin + dmax)/2.
enum class SizeDistribution { Uniform, Linear };

struct SizeSpec {
  double dmin_m = 0, dmax_m = 0;
  SizeDistribution distribution = SizeDistribution::Uniform;
};

/// Uniform variate in [0, 1) from 53 random bits (identical on every standard library).
double uniform01(std::mt19937_64& rng);
/// One diameter drawn from the distribution (inverse transform of one uniform variate).
double draw_diameter(const SizeSpec& size, std::mt19937_64& rng);

/// Diameters whose total sphere volume first reaches `solid_volume_m3`, sorted largest first.
std::vector<double> draw_diameters(const SizeSpec& size, double solid_volume_m3,
                                   std::mt19937_64& rng);

/// Places spheres of the given diameters without overlap inside the box [lo, hi] (each sphere
/// wholly inside). Ids are 0..n−1 in the order given. Throws std::invalid_argument naming the
/// sphere that could not be placed after `max_attempts` draws (box too small for the volume).
std::vector<Particle> random_sequential_packing(const std::vector<double>& diameters,
                                                const Eigen::Vector3d& lo,
                                                const Eigen::Vector3d& hi, std::mt19937_64& rng,
                                                int max_attempts = 20000);

/// Void ratio e = V_box / V_solid − 1 of spheres in a box volume (overlaps not subtracted, as
/// YADE's porosity()).
double void_ratio(const std::vector<double>& radii, double box_volume_m3);

}  // namespace gs::solver
