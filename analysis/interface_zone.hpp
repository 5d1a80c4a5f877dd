// The interface shear zone of seed 004 §4.3–4.4 from a snapshot of an interface shear test
// (granoscope's `scene.test = "interface_shear"`, or any specimen sheared along x over a surface
// below it, z up): profiles against the height above the surface's mean level of the particles'
// mean cumulative rotation about the depth axis y (the shear-zone indicator of §4.2.3) and, from a
// reference frame, of their mean horizontal displacement (the slip, Figs 4.40–4.41).
//  * The profiles are taken over the specimen inside the frame: the x extent of the particles in
//    its upper half (what moves with the frame; grains leaked under it stay low), inset by
//    `x_inset` at both ends; bins of `bin` m from the lowest centre up, heights their centres
//    minus `surface_z`.
//  * The zone (§4.2.3: "an inflection point in the distribution of sphere rotation around the
//    maximum defined the lower and the upper boundary"): the rotation profile smoothed by
//    [1 2 1]/4; from its largest |mean|, the first sign change of the second difference upwards
//    is the upper boundary and downwards the lower one — the surface (height 0) when there is
//    none above it. The thickness is upper − lower (NaN without an upper boundary).
//  * Slip: u_top is the mean x displacement of the top bin's particles (the frame's travel as
//    the specimen feels it), u_surface that of the lowest bin whose centre is at or above the
//    surface level, and slip_ratio = u_surface / u_top (1: the block slides on the surface, as
//    §4.3.3 finds for R_n ≤ 0.1; 0: the grains at the surface stay in the grooves).
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

struct InterfaceZoneOptions {
  double surface_z = 0;              // m, the surface's mean level
  double bin = 0;                    // m, > 0
  double x_inset = 0;                // m, ≥ 0
  const Frame* reference = nullptr;  // for the displacements (particles matched by id)
};

struct InterfaceZone {
  std::vector<double> height;        // bin centres above the surface, m
  std::vector<double> rotation;      // mean cumulative rotation about y, rad
  std::vector<double> displacement;  // mean x displacement since the reference, m (NaN: none)
  std::vector<double> count;         // particles per bin
  double x_lo = 0, x_hi = 0;         // the profiles' x range, m
  double peak_height = NAN;          // height of the largest smoothed |rotation|, m
  double lower = NAN, upper = NAN, thickness = NAN;  // zone boundaries above the surface, m
  double u_top = NAN, u_surface = NAN, slip_ratio = NAN;
};

/// The options as `analyze interface` names them: the surface level (m; unset: what the run
/// recorded, `recorded_surface`), the bin in m or d50 (default 1 d50), the inset in d50.
struct InterfaceSpec {
  std::optional<double> surface_z, bin, bin_d50;
  double inset_d50 = 2.0;
};

/// The options of `spec` for a frame of d50 `d50`; throws InputError (naming `file`) for a bad
/// option or no surface level at all.
InterfaceZoneOptions interface_zone_options(const std::string& file, double d50,
                                            const InterfaceSpec& spec,
                                            std::optional<double> recorded_surface);

/// The surface level an interface shear run recorded in its metadata
/// ("interface_shear.surface_mean_z_m"), if any.
std::optional<double> recorded_surface(
    const std::vector<std::pair<std::string, std::string>>& parameters);

/// Throws std::invalid_argument for a bin that is not positive, a negative inset, a frame with
/// no particles, or an x range emptied by the inset.
InterfaceZone interface_zone(const Frame& frame, const InterfaceZoneOptions& options);

}  // namespace gs::analysis
