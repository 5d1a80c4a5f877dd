// Drained triaxial compression of a cuboid (seed 004 §4.1): six smooth rigid planes; the four
// side planes are servo-controlled to hold σ2 = σ3 = σc, the top and bottom planes move towards
// the centre at a constant axial strain rate (each at ε̇·h0/2). Quasi-static when the inertial
// number I = ε̇·d50/sqrt(p/ρ) stays below 1e-4 (Roux and Chevoir 2005); it is monitored in the
// curve and the run warns once when it is exceeded.
#pragma once

#include "loading_programme.hpp"

namespace gs::solver {

struct TriaxialSpec {
  double confining_Pa = 2e5;         // σc
  double strain_rate_1_s = 0.1;      // axial ε̇ (engineering, of the initial height)
  double max_strain = 0.2;           // ends at this ε1
  double frame_every_strain = 0.01;  // trajectory frames every Δε1
  double servo_gain = 0.25;
  double max_wall_speed_m_s = 0.1;
  double inertial_warning = 1e-4;
  double d50_m = 0;               // for the inertial number (0: mean diameter)
  double core_inset_m = 0;        // core void ratio: box inset by this from the boundaries
  double clump_solid_factor = 1;  // a clump member's share of its volume (void ratios)
};

class TriaxialCompression final : public MeasuredProgramme {
 public:
  explicit TriaxialCompression(TriaxialSpec spec);
  double measure(const Simulation& sim) const override { return axial_strain(sim); }
  std::string name() const override { return "triaxial"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  /// Principal stresses from the walls (compression positive, Pa): axial σ1, lateral σ2 (y),
  /// σ3 (x) — the walls are smooth, so their normals are the principal directions.
  Eigen::Vector3d wall_stresses(const Simulation& sim) const;
  double axial_strain(const Simulation& sim) const;
  double volumetric_strain(const Simulation& sim) const;  // (V − V0)/V0, dilation positive
  double inertial_number(const Simulation& sim) const;

 private:
  TriaxialSpec spec_;
  double h0_ = 0, v0_ = 0, d50_ = 0;
  Eigen::Vector3d size0_ = Eigen::Vector3d::Zero();
  mutable double max_phi_deg_ = 0;
  mutable InertialWarning inertial_warning_;
};

/// Mobilised friction angle (deg) from principal stresses: sin φ = (σ1 − σ3)/(σ1 + σ3).
double mobilised_friction_deg(double sigma1, double sigma3);

}  // namespace gs::solver
