// Biaxial compression of a doubly periodic 2D assembly (seed 002 §4, Fig. 7a): the cell's
// height (y) shortens at a constant strain rate while its width (x) is servo-controlled to hold
// the horizontal stress σ11; the stress is the cell's Love–Weber average (seed 002 eq 17, with
// the 1/A the printed equation omits). Quasi-static when the inertial number I = ε̇·d50/
// sqrt(p/ρ) stays below 1e-4; the run warns once when it does not.
#pragma once

#include <vector>

#include "loading_programme.hpp"

namespace gs::solver {

struct PeriodicBiaxialSpec {
  double lateral_stress_Pa = 1e5;     // σ11, compression positive
  double strain_rate_1_s = 0.1;       // ε̇22 (shortening of the initial height)
  double max_strain = 0.03;           // ends at this ε22
  double frame_every_strain = 0.005;  // trajectory frames every Δε22 …
  std::vector<double> frame_strains;  // … and when ε22 passes each of these (sorted)
  double servo_fraction = 0.2;        // CellServo::stiffness_fraction of the width servo
  double max_rate_1_s = 0;            // |L11| limit of the width servo (0: 10·ε̇)
  double inertial_warning = 1e-4;
  double d50_m = 0;  // for the inertial number (0: mean diameter)
};

class PeriodicBiaxial final : public LoadingProgramme {
 public:
  explicit PeriodicBiaxial(PeriodicBiaxialSpec spec);
  std::string name() const override { return "biaxial_periodic"; }
  void start(Simulation& sim) override;
  void control(Simulation&) override {}  // the cell servo acts inside the engine
  bool finished(const Simulation& sim) const override;
  double progress(const Simulation& sim) const override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::int64_t frame_index(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  /// ε22 = (h0 − h)/h0 (shortening positive) and ε11 = (w0 − w)/w0.
  double axial_strain(const Simulation& sim) const;
  double lateral_strain(const Simulation& sim) const;
  /// The cell stress in the plane, compression positive (Pa): σ11, σ22, σ12.
  Eigen::Vector3d stresses(const Simulation& sim) const;

 private:
  PeriodicBiaxialSpec spec_;
  double h0_ = 0, w0_ = 0, a0_ = 0, d50_ = 0;
  mutable double peak_ratio_ = 0, peak_strain_ = 0;
  mutable InertialWarning inertial_warning_;
};

}  // namespace gs::solver
