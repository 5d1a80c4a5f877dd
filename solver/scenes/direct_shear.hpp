// Direct shear under constant normal stress (seed 004 §4.2.2): a shear box of two rigid frames
// (rigid box elements) around a specimen L (x, shear direction) × W (y) × H (z). The lower frame
// (bottom plate and four sides) is fixed; the upper frame (four sides) translates along x at a
// constant velocity; the top platen moves with it along x and is free vertically, servo-
// controlled to hold the normal stress σn. A gap of one largest grain diameter separates the
// frames during shearing "to prevent particles from getting stuck at the lower corners"; while
// the specimen is prepared the gap is closed by four extra walls, removed when shearing starts.
#pragma once

#include <array>
#include <vector>

#include "loading_programme.hpp"
#include "specimen_preparation.hpp"

namespace gs::solver {

struct ShearBoxGeometry {
  double length_m = 0, width_m = 0, height_m = 0;  // L (x), W (y), nominal H (z)
  double gap_m = 0;                                // between the frames (default dmax)
  double wall_thickness_m = 0;
  double frame_top_m = 0;           // top of the upper frame (above the loose cloud)
  double platen_z_m = 0;            // initial underside of the top platen
  double side_friction_deg = 0;     // frame sides
  double platen_friction_deg = -1;  // bottom plate and top platen (negative: the material's)
};

/// Wall indices of the shear box in the simulation's wall list.
struct ShearBoxWalls {
  std::array<std::size_t, 5> lower;   // bottom plate, x−, x+, y−, y+
  std::array<std::size_t, 4> upper;   // x−, x+, y−, y+
  std::array<std::size_t, 4> closer;  // gap closers (preparation only)
  std::size_t platen = 0;
};

/// Wall specs (boxes) of the shear box, appended in the order of ShearBoxWalls.
std::vector<WallSpec> shear_box_walls(const ShearBoxGeometry& g, ShearBoxWalls& index);

/// Gauge for preparing the specimen in the box: the platen alone is servo-controlled.
SpecimenGauge shear_box_gauge(const ShearBoxGeometry& g, const ShearBoxWalls& w);

struct DirectShearSpec {
  double normal_stress_Pa = 1e5;
  double shear_velocity_m_s = 0.01;
  double max_displacement_m = 0;  // ends at this u
  double frame_every_m = 0;       // trajectory frames every Δu
  double servo_gain = 0.25;
  double max_platen_speed_m_s = 0.05;
  double clump_solid_factor = 1;  // a clump member's share of its volume (void ratios)
};

class DirectShear final : public MeasuredProgramme {
 public:
  DirectShear(DirectShearSpec spec, ShearBoxGeometry geometry, ShearBoxWalls walls);
  double measure(const Simulation& sim) const override { return displacement(sim); }
  std::string name() const override { return "direct_shear"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  double displacement(const Simulation& sim) const;  // u of the upper frame, m
  /// Shear stress τ = −Σ F_x(upper frame and platen) / (L·W), Pa.
  double shear_stress(const Simulation& sim) const;
  double normal_stress(const Simulation& sim) const;  // platen force / (L·W), Pa
  double specimen_height(const Simulation& sim) const;

 private:
  DirectShearSpec spec_;
  ShearBoxGeometry g_;
  ShearBoxWalls w_;
  double x0_ = 0, h0_ = 0;
  mutable double peak_ratio_ = 0;
};

}  // namespace gs::solver
