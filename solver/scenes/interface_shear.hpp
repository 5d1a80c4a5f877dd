// Interface shear under constant normal stress (seed 004 §4.3–4.4): a specimen L (x, shear
// direction) × W (y) × H (z) held in an upper frame that slides over a fixed rigid surface —
// triangular saw-tooth asperities of normalized roughness R_n = h_g/d50 (§4.3, Fig 4.36), a
// sinusoidal corrugation of depth d and wavelength l (§4.4, Fig 4.72) or a flat plate. The frame
// (its two x sides; smooth) moves along x at a constant velocity, a gap of one largest grain above
// the surface's crests (§4.3.2: "a gap equal to the maximum grain diameter was left between the
// top frame and the rigid surface"); the top platen moves with it and is servo-controlled to hold
// σn. Fixed smooth walls close the y sides over the whole travel and the surface's ends. While
// the specimen is prepared two closers shut the gap; they are removed when shearing starts. What
// leaks under the frame and is pushed off the surface's ends is removed.
//
// The curve gives μeff = T/P (seed 004 Eq 4.6: T the horizontal force on the frame and platen,
// P the platen's normal force), φs = atan μeff (§4.3), the surface's own T/P, the volumetric
// strain εv = Δh/h0 (dilation positive, as Tables 4.5 and 4.8), the void ratio above the crests
// and the particles that left the frame. The summary and results give the peak and residual
// values (results: the sweep table of `simulate`).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "loading_programme.hpp"
#include "specimen_preparation.hpp"

namespace gs::solver {

struct InterfaceSurfaceSpec {
  std::string kind = "saw_tooth";  // "saw_tooth", "sinusoid" or "flat"
  // Saw-tooth (§4.3): h_g = roughness · d50; isosceles teeth at tooth_slope_deg, pitch
  // s_g = tooth_spacing_ratio · h_g (2 with 45°: contiguous triangles, no land).
  double roughness = 0;
  double d50_m = 0;
  double tooth_slope_deg = 45;
  double tooth_spacing_ratio = 2;
  // Sinusoid (§4.4): h(x) = d/2 · sin(2πx/l), d = depth_ratio · l (0: the flat plate, so that
  // a sweep over d/l starts at Table 4.8's d/l = 0).
  double depth_ratio = 0;
  double wavelength_m = 0;
  int segments_per_wavelength = 32;
  double friction_deg = -1;  // the surface's (negative: the material's)
  // "merged" (one contact per tooth face or strip, a plane wall's stiffness) or "yade" (YADE's
  // facets: one contact per triangle, Kn = 4/3·Ec·R; docs/physics.md).
  std::string contact = "merged";
};

struct InterfaceShearGeometry {
  double length_m = 0, width_m = 0, height_m = 0;  // L, W, nominal H above the mean surface
  double gap_m = -1;            // between the crests and the frame (negative: dmax)
  double wall_thickness_m = 0;  // of the box walls
  double platen_z_m = 0;        // initial underside of the platen
  double frame_top_m = 0;
  double travel_m = 0;  // the frame's travel (max displacement): the surface is longer
  double frame_friction_deg = 0;
  double platen_friction_deg = -1;  // negative: the material's
  // Set by interface_surface_walls: the surface's crest, mean and trough heights, its extent.
  double crest_z_m = 0, mean_z_m = 0, trough_z_m = 0;
  double surface_x0_m = 0, surface_x1_m = 0;
  std::size_t surface_triangles = 0;
  double clump_solid_factor = 1;  // a clump member's share of its volume (void ratios)
};

/// Wall indices in the simulation's wall list.
struct InterfaceShearWalls {
  std::size_t surface_begin = 0, surface_end = 0;  // the surface's walls [begin, end)
  std::array<std::size_t, 2> frame{};              // x−, x+ (move with the frame)
  std::array<std::size_t, 2> closer{};             // gap closers (preparation only)
  std::array<std::size_t, 2> side{};               // y−, y+ (fixed, smooth)
  std::size_t platen = 0;
};

/// The surface's walls alone (indices 0 … of `index.surface_*`), setting the geometry's crest,
/// mean and trough heights, extent and triangle count: what the specimen's cloud is placed
/// above. Throws std::invalid_argument naming the key and value: a roughness that gives teeth
/// below 1e-3·d50, teeth wider than their spacing, a depth ratio outside [0, 1), a bad
/// wavelength, non-positive dimensions.
std::vector<WallSpec> interface_surface_walls(const InterfaceSurfaceSpec& surface,
                                              InterfaceShearGeometry& g, double dmax_m,
                                              InterfaceShearWalls& index);

/// The frame, closers, y sides and platen appended to `walls` (the surface's, from
/// interface_surface_walls with the same geometry, whose platen_z_m and frame_top_m are now set).
void append_interface_box_walls(InterfaceShearGeometry& g, double dmax_m,
                                std::vector<WallSpec>& walls, InterfaceShearWalls& index);

/// Both: the surface's walls, then the box's.
std::vector<WallSpec> interface_shear_walls(const InterfaceSurfaceSpec& surface,
                                            InterfaceShearGeometry& g, double dmax_m,
                                            InterfaceShearWalls& index);

/// Preparation gauge: the platen is servo-controlled, the void ratio is that of the box between
/// the crests and the platen.
SpecimenGauge interface_shear_gauge(const InterfaceShearGeometry& g, const InterfaceShearWalls& w);

struct InterfaceShearSpec {
  double normal_stress_Pa = 1e5;
  double shear_velocity_m_s = 0.01;
  double max_displacement_m = 0;
  double frame_every_m = 0;
  double servo_gain = 0.25;
  double max_platen_speed_m_s = 0.05;
  double residual_fraction = 0.1;     // the residual: mean over the last 10 % of the travel
  double peak_fraction = 0.05;        // the peak: the largest mean over 5 % of the travel
  double internal_friction_deg = 42;  // φi of Eq 4.7 (the thesis's φi,max)
  double flat_friction = -1;          // μw of Eq 4.7 (< 0: no a_w)
  /// The frame in z while shearing: held at its height (false), or free (true: it rises
  /// when grains push its lower edges up, a servo holding its vertical force at zero; §4.3.2
  /// "the upper frame was free to move").
  bool frame_free = false;
};

class InterfaceShear final : public MeasuredProgramme {
 public:
  InterfaceShear(InterfaceShearSpec spec, InterfaceShearGeometry g, InterfaceShearWalls w);
  double measure(const Simulation& sim) const override { return displacement(sim); }
  std::string name() const override { return "interface_shear"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::vector<std::pair<std::string, double>> results(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  double displacement(const Simulation& sim) const;  // u of the frame, m
  /// T: −Σ F_x on the frame and the platen (N); P: the platen's normal force (N).
  double frame_shear_force(const Simulation& sim) const;
  double platen_force(const Simulation& sim) const;
  /// The frame's vertical load: Σ F_z of its walls (N, up: grains pushing its lower edges).
  double frame_vertical_force(const Simulation& sim) const;
  /// Σ F over the surface's walls (N).
  Eigen::Vector3d surface_force(const Simulation& sim) const;
  /// Platen underside above the mean surface (m).
  double specimen_height(const Simulation& sim) const;
  /// Void ratio of the box between the crests and the platen under the frame.
  double void_ratio(const Simulation& sim) const;

 private:
  void record(double u, double mu, double eps_v) const;
  InterfaceShearSpec spec_;
  InterfaceShearGeometry g_;
  InterfaceShearWalls w_;
  double x0_ = 0, h0_ = 0, e0_ = 0, frame_z0_ = 0;
  // The peak: the largest mean μ over a window `peak_fraction` of the travel wide (one noisy
  // row does not make a peak), the window moved along the travel by a tenth of its width: μ is
  // summed in sub-bins of that tenth, and each window is kWindowBins consecutive sub-bins. The
  // residual: the mean over the last `residual_fraction`.
  static constexpr int kWindowBins = 10;
  double sub_bin_width() const {
    return spec_.peak_fraction * spec_.max_displacement_m / kWindowBins;
  }
  void close_sub_bin() const;  // the sub-bin in progress into the ring; its window's mean
  double window_mean(bool with_current, std::int64_t& last) const;
  double window_centre(std::int64_t last) const;
  mutable std::int64_t bin_ = -1;  // the sub-bin in progress
  mutable double bin_sum_ = 0, bin_n_ = 0;
  mutable std::array<double, kWindowBins> ring_sum_{}, ring_n_{};  // sub-bin j at j % kWindowBins
  mutable double peak_ = -1e300, peak_u_ = 0;
  mutable double res_sum_ = 0, res_n_ = 0, eps_res_sum_ = 0;
  mutable double last_eps_ = 0;
};

}  // namespace gs::solver
