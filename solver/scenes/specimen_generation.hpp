// Seeded random generation of a loose sphere cloud in a box (specimen preparation, seed 004
// §4.1.2 and §4.2.2: "particles were randomly packed inside the box"), by random sequential
// addition: spheres are placed largest first at uniformly random positions, each rejected and
// redrawn while it overlaps a sphere already placed; the same for disks in a doubly periodic
// rectangle (2D specimens, seed 002 §4). Deterministic for a given seed on every platform (own
// uniform variates from std::mt19937_64 bits; the Graded table is built with exp/erfc, so its
// draws are bit-identical wherever the C library's exp and erfc are).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "snapshot.hpp"

namespace gs::solver {

/// Grain-size distribution between dmin and dmax (diameters, m). The mass of a grain is ∝ d^k
/// with k = `mass_exponent`: 3 for spheres, 2 for disks of equal thickness (2D specimens).
///  - Uniform: diameters uniformly distributed by number (seed 004 §4.1.2: "uniform distribution
///    of particle diameters ... from 0.5·d50 to 1.5·d50").
///  - Linear: a straight grading curve, i.e. the mass fraction finer than d grows linearly from
///    dmin to dmax (seed 000 §3: "linear grain distribution curve"); by number the density is
///    ∝ d⁻ᵏ, and d50 (by mass) = (dmin + dmax)/2.
///  - Graded: the grading curve (mass fraction finer than d) is a normal distribution in d of
///    mean fit_mu_m and standard deviation fit_sigma_m truncated to [dmin, dmax], fitted by
///    fit_graded() so that the weight-median diameter D50 is d50_m and D60/D10 is `uniformity`
///    (seed 002 §4, Kuhn 1999: "1002 irregularly arranged circular disks ... largest and smallest
///    having diameters 1.4 and 0.45 times the weight-median diameter D50. The coefficient of
///    uniformity D60/D10 was 1.7"). By number the density is ∝ f_mass(d)/dᵏ.
///  - Piecewise: the grading curve is the broken line through `grading` (d, mass fraction finer)
///    points, from (dmin, 0) to (dmax, 1): any shape that honours given D10, D50, D60 (e.g.
///    through (D10, 0.1), (D50, 0.5), (D60, 0.6)); on each segment the mass density is constant,
///    so the number density is ∝ d⁻ᵏ there (drawn in closed form, segment by its number share).
enum class SizeDistribution { Uniform, Linear, Graded, Piecewise };

/// Number CDF of a fitted Graded distribution on nodes equally spaced in [lo_m, hi_m], built by
/// fit_graded() for the parameters it records (a draw checks that they are still the spec's).
struct GradedTable {
  double dmin_m = 0, dmax_m = 0, d50_m = 0, uniformity = 0, mu_m = 0, sigma_m = 0;
  int mass_exponent = 3;
  double lo_m = 0, hi_m = 0;
  std::vector<double> cdf;  // cdf.front() = 0, cdf.back() = 1, non-decreasing
};

struct SizeSpec {
  double dmin_m = 0, dmax_m = 0;
  SizeDistribution distribution = SizeDistribution::Uniform;
  double d50_m = 0, uniformity = 0;      // Graded: targets D50 (by mass) and D60/D10
  double fit_mu_m = 0, fit_sigma_m = 0;  // Graded: filled by fit_graded()
  int mass_exponent = 3;                 // mass ∝ d^k: 3 spheres, 2 disks
  std::shared_ptr<const GradedTable> graded_table = nullptr;  // Graded: filled by fit_graded()
  /// Piecewise: (d_m, mass fraction finer) points, d and fraction non-decreasing, first
  /// (dmin, 0), last (dmax, 1) (check_piecewise() validates).
  std::vector<std::pair<double, double>> grading = {};
};

/// Throws std::invalid_argument unless `grading` is a valid Piecewise curve for [dmin, dmax].
void check_piecewise(const SizeSpec& size);

/// Fits (fit_mu_m, fit_sigma_m) of a Graded spec to d50_m and `uniformity` (to 1e-12 relative)
/// and tabulates its number CDF for draw_diameter(). Throws std::invalid_argument naming the
/// values when no truncated normal reaches them: d50 outside (dmin, dmax), D60/D10 <= 1, or
/// D60/D10 at or above the limit σ → ∞ (a grading curve of exponential mass density, uniform by
/// mass when d50 = (dmin + dmax)/2), whose value the message reports.
void fit_graded(SizeSpec& size);

/// Mass fraction finer than d (the grading curve), 0 at dmin and 1 at dmax, for each
/// distribution (Graded: of the fitted curve).
double mass_fraction_finer(const SizeSpec& size, double d_m);
/// The diameter finer than which `fraction` of the mass lies (D10 = mass_quantile(s, 0.1)).
double mass_quantile(const SizeSpec& size, double fraction);

/// Uniform variate in [0, 1) from 53 random bits (identical on every standard library).
double uniform01(std::mt19937_64& rng);
/// One diameter drawn from the distribution (inverse transform of one uniform variate; Graded:
/// of the table fit_graded() built, std::invalid_argument when there is none for the spec's
/// current parameters).
double draw_diameter(const SizeSpec& size, std::mt19937_64& rng);

/// Diameters whose total sphere volume first reaches `solid_volume_m3`, sorted largest first
/// (a Graded spec without a current table is fitted on a copy first).
std::vector<double> draw_diameters(const SizeSpec& size, double solid_volume_m3,
                                   std::mt19937_64& rng);
/// The diameter at number quantile u ∈ [0, 1] of the distribution (the inverse transform
/// draw_diameter applies to one uniform variate).
double diameter_at(const SizeSpec& size, double u);
/// Exactly n diameters, sorted largest first, stratified by number: the i-th from the quantile
/// (i + U_i)/n with U_i uniform, so the sample's grading curve follows the distribution's to
/// within 1/n by number (a Graded spec without a current table is fitted on a copy first).
std::vector<double> draw_diameter_count(const SizeSpec& size, std::size_t n, std::mt19937_64& rng);

/// Places spheres of the given diameters without overlap inside the box [lo, hi] (each sphere
/// wholly inside). Ids are 0..n−1 in the order given. Throws std::invalid_argument naming the
/// sphere that could not be placed after `max_attempts` draws (box too small for the volume).
std::vector<Particle> random_sequential_packing(const std::vector<double>& diameters,
                                                const Eigen::Vector3d& lo,
                                                const Eigen::Vector3d& hi, std::mt19937_64& rng,
                                                int max_attempts = 20000);

/// Places disks of the given diameters (centres at z = z_m) by random sequential addition in the
/// doubly periodic rectangle [0, lx) × [0, ly): no disk overlaps any periodic image of another
/// (minimum-image distance; a cell of at least 2·dmax per side makes that image the only one
/// that can touch). Ids are 0..n−1 in the order given. Throws std::invalid_argument when a side
/// is below 2·dmax and, naming the disk, when one found no free place after `max_attempts`.
std::vector<Particle> random_disk_packing_periodic(const std::vector<double>& diameters,
                                                   double lx_m, double ly_m, double z_m,
                                                   std::mt19937_64& rng, int max_attempts = 20000);

/// Void ratio e = V_box / V_solid − 1 of spheres in a box volume (overlaps not subtracted, as
/// YADE's porosity()).
double void_ratio(const std::vector<double>& radii, double box_volume_m3);
/// 2D void ratio e = A / Σπr² − 1 of disks in an area (overlaps not subtracted).
double disk_void_ratio(const std::vector<double>& radii, double area_m2);

}  // namespace gs::solver
