// Plane-strain compression (seed 000 §3; Kozicki & Tejchman): specimen b × h × l with x the
// width b (flexible lateral membranes at σc, flexible_membrane.hpp), z the height h (bottom cap
// fixed, top cap moving down at a constant strain rate) and y the depth l (front and back planes
// fixed: plane strain). Caps and membranes are frictionless in the seed; the walls take the
// friction the scene gives them. The membrane's rays are refreshed every `refresh_steps` steps,
// so the loaded boundary follows the specimen as a shear zone forms.
//
// The membrane is clamped to the caps, as a rubber membrane is to the platens of the apparatus:
// over a height `clamp_height_m` next to each cap the lateral boundary is a short rigid,
// frictionless wall that moves with its cap (walls 6-9: x− and x+ at the bottom, then at the
// top). Without the clamps nothing holds the ends of the specimen laterally — the caps are
// frictionless — and a dense specimen sways as a whole into a parallelogram, shedding all its
// strength (moment equilibrium then forces σ1 → σc), instead of forming a shear zone.
//
// The top cap rides on a lateral sledge, as in the biaxial apparatus of Vardoulakis and of
// Tejchman: the top cap and its clamps move freely along x (no lateral force on them), while the
// bottom is held. A single inclined shear zone moves the block above it sideways; with both ends
// held laterally it must cross the specimen twice (crossed or reflected bands). The sledge has no
// inertia: its x velocity is a servo that cancels the lateral force the grains exert on the top
// clamps (gain `sledge_gain`, like the stress servos), capped at the cap's axial speed.
// `top_cap = "fixed"` holds both ends.
#pragma once

#include "flexible_membrane.hpp"
#include "loading_programme.hpp"

namespace gs::solver {

struct PlaneStrainSpec {
  double confining_Pa = 2e5;
  double strain_rate_1_s = 0.1;
  double max_strain = 0.1;
  double frame_every_strain = 0.01;
  double membrane_bin_m = 0;      // ray spacing (0: d50 / 2)
  double membrane_stencil_m = 0;  // slope stencil half-width (0: d50)
  std::int64_t refresh_steps = 20;
  double clamp_height_m = 0;  // membrane clamped to the caps over this height (0: d50)
  bool top_sledge = true;     // top cap free along x (false: held)
  double sledge_gain = 0.25;  // fraction of the lateral force removed per step
  double inertial_warning = 1e-4;
  double d50_m = 0;               // 0: mean diameter
  double core_inset_m = 0;        // core void ratio: box inset by this from the boundaries
  double clump_solid_factor = 1;  // a clump member's share of its volume (void ratios)
};

/// The four clamp walls (boxes, switched off until the loading starts), appended after the six
/// cuboid planes.
std::vector<WallSpec> membrane_clamps();

class PlaneStrainCompression final : public MeasuredProgramme {
 public:
  explicit PlaneStrainCompression(PlaneStrainSpec spec);
  double measure(const Simulation& sim) const override { return axial_strain(sim); }
  std::string name() const override { return "plane_strain"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  double axial_strain(const Simulation& sim) const;
  /// The membrane loads the current state would get (not applied).
  MembraneLoads membrane(const Simulation& sim) const;
  /// Specimen volume: between the membranes, plus the clamped ends.
  double volume(const Simulation& sim) const;
  /// Lateral (x) displacement of the top cap since the start of loading, m.
  double top_shift(const Simulation& sim) const;

 private:
  void refresh(Simulation& sim);

  PlaneStrainSpec spec_;
  double clamp_ = 0, b0_ = 0;  // clamp height and the width between the clamps
  double h0_ = 0, v0_ = 0, d50_ = 0, top_x0_ = 0;
  std::int64_t start_step_ = 0;
  mutable double max_phi_deg_ = 0;
  mutable InertialWarning inertial_warning_;
};

}  // namespace gs::solver
