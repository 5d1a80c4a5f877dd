// The model silo of seed 004 §5.2 (Table 5.1, Figs 5.2–5.4): a flat-bottomed rectangular silo
// of width b_s (x), depth d_s (y) and height h_s (z), its two side walls (x = 0 and x = b_s)
// covered with triangular saw-tooth asperities of height h_g = R_n·d50 at a spacing s_g = 4·h_g
// and slope α_g = 45° (Fig 5.3), filled by gravity in layers ([fill]) and then emptied in one of
// two modes:
//  * quasi-static (Fig 5.2a): the whole bottom plate moves down at a constant velocity until it
//    has travelled u (30 mm in the seed); the side walls reach below the bottom's start by u so
//    that the material stays between them;
//  * gravitational (Fig 5.2b, Fig 5.4): the filled silo rests for settle_s (0.5 s), then an
//    outlet of width b in the bottom opens, centred ('1') or at the right wall ('2', '3'), and the
//    run goes on until the silo is empty, or the flow has stopped (the heaps a flat bottom keeps
//    beside the outlet, or an arch over it: nothing has left for stop_after_s), or a time limit;
//    particles that fall below the bottom are removed and counted.
// The curve (curve.csv) gives the resultant wall forces of seed 004 §5.3.1, normalised by the
// weight G of the material in the silo: P the vertical force on the bottom (normal and tangential
// parts), T the vertical force on each side wall (positive down), N the horizontal force on each
// side wall (positive outwards), with the balance (P + T_left + T_right)/G (= 1 at rest:
// G = 2T + P) and the mobilised wall friction angle φ_w = atan(T/N) of each side wall.
// What the seed leaves open is chosen here and said in docs/silo.md: the front and back walls
// (frictionless planes by default: the seed's 7.5 mm deep slice stands for a deep silo), the
// bottom's friction (the material's), the teeth's back face (45° as the ramp: symmetric
// triangular grooves), the speed of the bottom, the time step and density (scene keys).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loading_programme.hpp"

namespace gs::solver {

struct SiloSpec {
  double width_m = 0.2;                // b_s, x
  double height_m = 0.5;               // h_s, z: the side walls' height above the bottom
  double depth_m = 0.0075;             // d_s, y
  double roughness = 1.0;              // R_n = h_g/d50; 0: flat side walls (planes)
  double d50_m = 0;                    // 0: the [fill] grading's d50 (by mass)
  double tooth_slope_deg = 45;         // α_g, both faces of a tooth
  double tooth_spacing_ratio = 4;      // s_g/h_g (the seed's s_g = 4·h_g for every R_n)
  double wall_friction_deg = 18;       // μ_w of the side walls
  double front_back_friction_deg = 0;  // the planes y = 0 and y = d_s
  double bottom_friction_deg = -1;     // negative: the material's
  std::string mode = "quasi_static";   // or "gravitational"
  double flow_damping = 0.01;          // λ_d once the flow starts (seed 004 §5.3.2)
  // Quasi-static mode.
  double bottom_velocity_m_s = 0.005;
  double bottom_travel_m = 0.03;  // u at the end
  double frame_every_m = 0.0025;  // a frame every Δu (the seed's snapshots: 2.5, 5, … mm)
  // Gravitational mode.
  double settle_s = 0.5;
  std::string outlet = "centre";  // "centre" (type '1') or "right" (types '2', '3')
  double outlet_width_m = 0.03;   // b
  double max_discharge_s = 30;    // the run ends this long after the opening at the latest
  double end_fraction = 0.99;     // … or once this fraction of the mass has left
  double stop_after_s = 1.0;      // … or once nothing has left for this long (0: never)
  double frame_every_s = 0.05;
};

/// Wall indices of the silo in the simulation's wall list.
struct SiloWalls {
  std::size_t left_begin = 0, left_end = 0, right_begin = 0, right_end = 0;  // [begin, end)
  std::vector<std::size_t> bottom;  // the bottom plate, or its parts beside the outlet
  std::size_t outlet = SIZE_MAX;    // the plate under the outlet (gravitational mode)
  std::size_t front = 0, back = 0;
  double tooth_height_m = 0, tooth_spacing_m = 0;
  double floor_z_m = 0;  // the side walls' lower end (below 0 in the quasi-static mode)
  double dmax_m = 0;     // the largest grain
};

/// The silo's walls (side walls as merged meshes of groups "left" and "right", the bottom as
/// boxes below z = 0, front and back planes), in the order of `index`. `d50_m` sets the teeth
/// (h_g = R_n·d50), `dmax_m` the thickness of the plates and how far the side walls reach
/// below the bottom. Throws std::invalid_argument naming the key and value: a non-positive size,
/// teeth below 1e-3·d50 (R_n > 0) or too wide for the silo, an outlet outside the bottom.
std::vector<WallSpec> silo_walls(const SiloSpec& spec, double d50_m, double dmax_m,
                                 SiloWalls& index);

/// Resultant wall forces (N) of seed 004 §5.3.1 in a simulation of the silo.
struct SiloForces {
  double weight = 0;  // G: the weight of the particles in the silo (not removed, above the floor)
  double bottom = 0;  // P, vertical, positive down on the bottom
  double t_left = 0, t_right = 0;  // T, vertical, positive down on the wall
  double n_left = 0, n_right = 0;  // N, horizontal, positive outwards
};
SiloForces silo_forces(const Simulation& sim, const SiloWalls& walls);

class SiloFlow final : public LoadingProgramme {
 public:
  /// Throws std::invalid_argument naming the key for a bad mode, outlet or rate.
  SiloFlow(SiloSpec spec, SiloWalls walls);
  std::string name() const override { return "silo"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  bool finished(const Simulation& sim) const override;
  double progress(const Simulation& sim) const override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::int64_t frame_index(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  /// The bottom's travel u (m) since the start (quasi-static mode).
  double travel(const Simulation& sim) const;
  /// Mass that has left the silo since the start, and its fraction of the mass at the start.
  double discharged_mass(const Simulation& sim) const { return sim.removed_mass() - removed0_; }
  /// Void ratio in the gauge box fixed when the flow starts: the silo's interior one largest
  /// grain clear of the teeth's tips, the bottom and the fill's surface (the mean top of its
  /// highest 5 % of grains), over the whole depth; spheres cut by the box count with the part
  /// inside it.
  double void_ratio(const Simulation& sim) const;

 private:
  bool quasi_static() const { return spec_.mode == "quasi_static"; }
  SiloSpec spec_;
  SiloWalls w_;
  double t0_ = 0, z0_ = 0, mass0_ = 0, removed0_ = 0, e0_ = 0;
  Eigen::Vector3d gauge_lo_ = Eigen::Vector3d::Zero(), gauge_hi_ = Eigen::Vector3d::Zero();
  bool opened_ = false;
  // The time the discharged mass last grew (the opening's until something leaves), and that mass.
  double last_out_t_ = NAN, last_out_mass_ = 0;
  bool stalled(const Simulation& sim) const;
};

}  // namespace gs::solver
