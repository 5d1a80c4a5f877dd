// Seed 003's principal stress rotation test, one programme from the deposited bed to the last
// cycle (§2.2.3, §2.4; the apparatus in boundaries/tangential_polyhedron.hpp):
//  1. deposition of the clumps in the box under g (−100 m/s², friction 0.01, damping 0.2) until
//     f_unb/f_av is at most the tolerance (§2.4) with at least as many contacts as bodies (a
//     bed, not the falling cloud);
//  2. gravity removed, friction and damping of the quasi-static stages (0.5, 0.7), the
//     polyhedron carved out of the bed (§2.4: a clump with a member centre outside goes), its
//     walls on and the box's off, re-equilibrated with the walls fixed. The kept members reach
//     up to a radius beyond the faces: the walls start that much outward (the polyhedron of
//     R + r_max, F = (1 + r_max/R) 1 against the reference of R), so that nothing overlaps
//     them, and the consolidation brings them in;
//  3. isotropic consolidation to p by the servo (Eqs 14-16);
//  4. monotonic shear at b with σ1 along z, η raised in steps applied at equilibrium, to η;
//  5. σ1 turned in the x-z plane at constant p, η, b (σ2 along y; Eq 17), in increments Δα
//     applied when f_unb/f_av is at most the tolerance and the stress is within its tolerance
//     of the target, for the cycles asked (a cycle: 180°).
// α is the angle of σ1 from z, as the paper measures it (§3.1).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "loading_programme.hpp"
#include "tangential_polyhedron.hpp"

namespace gs::solver {

struct StressRotationSpec {
  int sides = 8;              // n of the polyhedron (even, >= 4)
  double radius_m = 6.6e-3;   // R, its inscribed radius
  double p_Pa = 500e3;        // mean stress
  double eta = 0.5;           // q/p the rotation runs at
  double b = 0.5;             // intermediate principal stress ratio
  double eta_step = 0.02;     // η raised by this per increment of the monotonic shear
  double alpha_step_deg = 1;  // Δα
  double cycles = 1;          // of 180°
  double tolerance = 1e-4;    // f_unb/f_av of equilibrium (quasi-static stages)
  double deposition_tolerance = 1e-4;
  double stress_tolerance = 0.01;  // ‖σ − σ_t‖ / p of a reached target
  Eigen::Vector3d deposition_gravity = Eigen::Vector3d(0, 0, -100);  // m/s²
  double deposition_friction_deg = 0.5729386976834859;               // atan(0.01)
  double deposition_damping = 0.2;
  double damping = 0.7;                 // local damping of the quasi-static stages
  std::int64_t min_stage_steps = 2000;  // shortest deposition and re-equilibration
  std::int64_t check_every = 20;        // steps between equilibrium checks
  // A target not reached by then is an error: max_increment_steps for an increment of η or α,
  // max_stage_steps for the deposition, the re-equilibration and the consolidation.
  std::int64_t max_increment_steps = 200000;
  std::int64_t max_stage_steps = 2000000;
  double frame_every_deg = 15;  // trajectory frames during the rotation
  // E set at the carving (Eq 16) unless given; at most 1e-6 of strain a step.
  PolyhedronServo servo;
  // > 0: the time step of the stages after the deposition (the scene's dt_s is the
  // deposition's). docs/rotation.md: seed 003's 1.02 µs is at the stability limit of the
  // lightest dimers once they carry many contacts.
  double quasi_static_dt_s = 0;
  double relaxation = 0.8;          // ς of Eq 16
  double normal_stiffness_N_m = 0;  // kn of Eq 16 (0: Ec times the mean radius)
  std::size_t box_first = 0;        // the box's six walls
  std::size_t poly_first = 6;       // the polyhedron's walls
};

class StressRotation final : public LoadingProgramme {
 public:
  /// `test_friction_deg`: the friction of the quasi-static stages (the material's).
  StressRotation(StressRotationSpec spec, double test_friction_deg);
  std::string name() const override { return "stress_rotation"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  bool finished(const Simulation&) const override { return stage_ == kDone; }
  double progress(const Simulation& sim) const override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::int64_t frame_index(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::vector<std::pair<std::string, double>> results(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  enum Stage : std::int64_t {
    kDeposition = 0,
    kReequilibration,
    kIsotropic,
    kShear,
    kRotation,
    kDone
  };
  Stage stage() const { return static_cast<Stage>(stage_); }
  const TangentialPolyhedron& polyhedron() const { return P_; }
  /// The target of the current stage (Pa, compression positive) and the angle of σ1 from z
  /// (degrees) it has reached.
  Eigen::Matrix3d target() const;
  double alpha_deg() const { return alpha_deg_; }
  double eta_now() const { return eta_now_; }

 private:
  void carve(Simulation& sim);
  void enter(Simulation& sim, Stage s);
  bool equilibrium(const Simulation& sim, double tolerance) const;
  std::size_t body_count(const Simulation& sim) const;  // clumps and free spheres

  StressRotationSpec spec_;
  TangentialPolyhedron P_;
  double test_friction_;
  std::int64_t stage_ = kDeposition;
  std::int64_t stage_start_ = 0, increment_start_ = 0;
  double eta_now_ = 0, alpha_deg_ = 0;
  double servo_E_ = 0;
  // At the carving, for the report: particles and clumps kept, and the solid volume.
  std::int64_t kept_particles_ = 0, kept_bodies_ = 0;
  double solid_volume_ = 0;
  double void_ratio_isotropic_ = -1;
  // The last servo reading (before the step): the stress of Eq 14.
  Eigen::Matrix3d sigma_ = Eigen::Matrix3d::Zero();
};

}  // namespace gs::solver
