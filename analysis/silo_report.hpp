// The silo report of seed 004 §5.3 from a snapshot of a silo (granoscope's `scene.test = "silo"`
// or any run with two side walls across a horizontal axis and a bottom): the resultant wall
// forces of §5.3.1 and the wall stress profiles σ11 (horizontal normal) and σ21 (vertical shear)
// against the height (Figs 5.8–5.11, 5.55–5.61).
//  * Walls are told apart by their orientation, so that saw-tooth walls (one wall per tooth face
//    in the snapshot) count: a side wall is a plane or facet wall whose normal b (into the
//    material) has |b·up| < 0.99 and |b·across| ≥ 0.1 — the left wall when b·across > 0, the
//    right one otherwise (the front and back planes, normal ⟂ across, are neither); the bottom is
//    every box wall and every plane or facet wall with b·up ≥ 0.99.
//  * P = −Σ F·up over the bottom (F the force of the material on a wall, normal and tangential
//    parts), T = −Σ F·up over a side wall (positive: the material drags it down), N = −Σ F·b̂
//    with b̂ = ±across the side's inward horizontal (positive: pushed outwards), φ_w = atan(T/N),
//    G the weight of the particles whose centre is above the bottom's top (boxes: the highest top
//    face; planes: their point), and the balance (P + T_left + T_right)/G (= 1 at rest).
//  * Profiles: the particle–wall contacts of each side, binned by the height of their contact
//    point (bins of `bin` m from the bottom's top up), σ11 = Σ(−F·b̂)/(bin·depth),
//    σ21 = Σ(−F·up)/(bin·depth), depth the extent of the particles along up × across (their
//    centres ± radii) unless given.
//  * The same profiles from the Love–Weber stress (seed 004 eq 4.1; love_weber_stress.hpp) in
//    near-wall cells: boxes `rev_width` wide from each wall's base plane, one per profile bin,
//    through the particles' depth, in the (across, depth, up) frame. σ11 is the across–across
//    component (compression positive, as the wall's), σ21 the symmetric across–up part with the
//    wall's sign (the material dragging the wall down positive: +σ on the left, −σ on the
//    right). A row of grains in equilibrium between the walls gives the wall's σ11 exactly.
//  * Wall shear zones at a height (§5.3.1, Table 5.4; the procedure of §4.2.3): the particles'
//    rotation about the depth axis (cumulative, from the snapshot) averaged in bins across the
//    silo (`zone_bin` wide) within a horizontal band (`zone_band` thick) centred at `zone_height`
//    above the bottom (default: half the height of the fill), smoothed by [1 2 1]/4, or with
//    `zone_window` > 0 averaged in the seed's REV cells instead (§4.2.3, §5.3.1: cells
//    `zone_window` wide across, moved by `zone_bin`, from flush with the left wall to flush with
//    the right one; a grain counts in each cell that holds its centre; no further smoothing),
//    the profile's points then the cells' centres; from the largest mean |rotation| in the half
//    next to a wall, the first sign change of the second difference towards the middle (linear
//    interpolation) is the zone's inner boundary, and its distance from the wall's base plane
//    (the extreme wall point across) the zone's thickness (NaN when the profile has no such
//    point). A profile that falls convexly from the wall has no inflection but its noise's, so
//    the report also gives each zone's extent: the core's level, the median of the profile over
//    the middle third of the width, and from the wall's peak the first point towards the middle
//    (linear interpolation between the profile's points) where the profile falls below
//    `zone_extent_factor` times that level (NaN when it does not).
//  * Void ratio across the width (§5.3.1; at 10, 25 and 40 cm of the seed's 0.5 m silo): in
//    horizontal bands (`layer_band` thick, clipped to the fill: from the bottom to the highest
//    grain's top) centred at fractions of the fill's height (`layer_fractions`), boxes `layer_bin`
//    wide from one wall's base plane to the other's, through the particles' depth; e = V_box /
//    V_solid − 1 with the exact sphere–box volumes. The boxes next to a saw-tooth wall hold teeth,
//    which count as void. In the same boxes: the mean downward displacement since a reference
//    frame (matched by particle id) and the mean |rotation| about the depth axis of the grains
//    whose centre lies in the box (Figs 5.15–5.16).
//  * Flow pattern (§5.3.2; mass, funnel or mixed flow) from the frame's velocities: the fill
//    cut into `flow_bands` horizontal bands; in each, the mean downward velocity of the grains
//    in a column `flow_wall_width` wide at each wall's base plane (wide enough to reach past the
//    teeth) against the fastest column of that width across the band. A wall moves in a band
//    when its column goes down faster than `flow_threshold` times the fastest column. The
//    transition height of a wall is the lowest band from which the wall moves in every band
//    up to the one below the free surface at that wall (the highest band its column has grains
//    in: a crater over an eccentric outlet leaves the bands above it empty, not stagnant; NaN:
//    stagnant up to there, or no grains at the wall); a wall is in mass flow when its transition
//    lies in the lowest quarter of the fill (only the dead zones at a flat bottom), funnel flow
//    when it has none, mixed flow in between; the silo's pattern is the slower wall's, or the
//    other wall's where one has no grains in its column (swept bare: no dead zone there). A
//    frame whose fastest column moves slower than 1e-6 m/s is at rest.
//  * Contact orientation in the left half (Fig 5.27): particle–particle contacts whose point
//    lies in the left half and above the bottom, their normals projected on the across–up
//    plane; the rose of `fabric_bins` bins (angle from the left wall's inward normal, towards
//    up) and the major principal direction of the planar fabric tensor Σ n⊗n / N, as the angle
//    from the wall normal in (−90°, 90°].
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "snapshot.hpp"

namespace gs::analysis {

struct SiloReportOptions {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d across = Eigen::Vector3d::UnitX();  // from the left wall to the right one
  double bin = 0;                                     // m, > 0
  double depth = 0;                                   // m; 0: the particles' extent
  double gravity = 9.81;
  double zone_bin = 0;                  // m; 0: no shear-zone profile
  double zone_band = 0;                 // m, > 0 with zone_bin
  double zone_window = 0;               // m: the REV cell across, moved by zone_bin (seed 004
                                        // §4.2, §5.3: 5·d50 moved by d50); 0: bins of zone_bin
  double zone_height = 0;               // m above the bottom; 0: half the fill's height
  double zone_extent_factor = 2;        // the zones' extent: where the rotation falls below
                                        // this multiple of the core's (> 1)
  std::vector<double> layer_fractions;  // of the fill's height; empty: no void-ratio layers
  double layer_bin = 0;                 // m, > 0 with layer_fractions
  double layer_band = 0;                // m, > 0 with layer_fractions
  int fabric_bins = 0;                  // rose bins over 360°; 0: no contact-orientation fabric
  double rev_width = 0;                 // m; 0: no Love–Weber near-wall cells
  int flow_bands = 0;                   // 0: no flow pattern
  double flow_wall_width = 0;           // m, > 0 with flow_bands
  double flow_threshold = 0.1;          // of the fastest column's downward velocity
};

enum class FlowPattern : int { Rest = 0, Funnel = 1, Mixed = 2, Mass = 3 };
const char* flow_pattern_name(FlowPattern p);

/// Void ratio, displacement and rotation across the silo at one height (Figs 5.15–5.17).
struct SiloLayer {
  double height = 0;                       // m above the bottom (band centre)
  std::vector<double> across, void_ratio;  // box centres (m along across), e (NaN: no solid)
  // Means over the grains whose centre is in a box (NaN: none): the downward displacement since
  // the reference frame (NaN without one, or for grains it does not hold) and |rotation| about
  // the depth axis (the snapshot's cumulative rotation).
  std::vector<double> displacement_down, rotation;
};

struct SiloProfile {
  std::vector<double> height;  // bin centres above the bottom, m
  std::vector<double> sigma11_left, sigma21_left, sigma11_right, sigma21_right;  // Pa
  std::vector<double> contacts_left, contacts_right;
  // Love–Weber stress in the near-wall cells (with rev_width > 0), Pa: σ11 the horizontal
  // normal stress, σ21 the symmetric part of the across–up shear, signed as the wall's (the
  // material dragging the wall down positive).
  std::vector<double> lw_sigma11_left, lw_sigma21_left, lw_sigma11_right, lw_sigma21_right;
};

struct SiloFrameReport {
  double time = 0;
  double G = 0, P = 0, T_left = 0, T_right = 0, N_left = 0, N_right = 0;  // N
  double phi_left_deg = 0, phi_right_deg = 0, balance = 0;
  std::size_t side_walls_left = 0, side_walls_right = 0, bottom_walls = 0;
  double bottom_level = 0;  // m along up
  SiloProfile profile;
  // Shear zones (with zone_bin > 0): the rotation profile across, and each wall zone's thickness.
  double zone_height = 0;                          // m above the bottom
  std::vector<double> zone_across, zone_rotation;  // bin centres (m along across), mean |rot|
  double zone_left = NAN, zone_right = NAN;        // m
  double zone_core = NAN;                          // rad: the core's mean |rotation| level
  double zone_extent_left = NAN, zone_extent_right = NAN;  // m from the walls' base planes
  double fill_height = 0;  // m: the highest particle top above the bottom
  double width = 0;        // m: between the side walls' base planes
  std::vector<SiloLayer> layers;
  // Left half contact orientation (with fabric_bins > 0).
  std::vector<double> rose_angle_deg, rose_density;  // bin centres from the wall normal; 1/rad
  double fabric_angle_deg = NAN;                     // major direction from the wall normal
  double fabric_anisotropy = NAN;                    // (F1 − F2) / (F1 + F2) of the planar tensor
  std::size_t fabric_contacts = 0;
  // Flow pattern (with flow_bands > 0).
  FlowPattern flow = FlowPattern::Rest;
  double transition_left = NAN, transition_right = NAN;  // m above the bottom
  double flow_speed = 0;                                 // m/s, the fastest column's
};

/// Throws std::invalid_argument when the frame has no left or right side wall or no bottom,
/// for a bad bin, depth or direction (up and across not orthogonal unit-able vectors), or when
/// its walls carry forces but the frame holds no particle–wall contact for the profiles.
/// `reference`: the frame the layers' displacements are measured from (none: NaN).
SiloFrameReport silo_report(const Frame& frame, const SiloReportOptions& options,
                            const Frame* reference = nullptr);

}  // namespace gs::analysis
