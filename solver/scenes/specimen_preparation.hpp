// Specimen preparation (seed 004 §4.1.2, §4.2.2; seed 003 §2.4): optional gravitational
// deposition (gravity on until the preparation ends, then the scene's restored), then compaction by
// servo-controlled walls to a target stress σc while the inter-particle friction is lowered step by
// step until a target void ratio is reached (YADE's classic "triax" procedure), then the friction
// of the test is restored and the specimen is left to settle. Each stage ends on equilibrium: wall
// stresses within a tolerance of σc, YADE's unbalanced-force ratio and the kinetic / elastic energy
// ratio below thresholds.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "loading_programme.hpp"

namespace gs::solver {

struct PreparationSpec {
  double pressure_Pa = 0;           // σc held by the servo walls (0: no compaction stage)
  double void_ratio_target = -1;    // lower the friction until e ≤ this (negative: keep it)
  double friction_start_deg = -1;   // friction while compacting (negative: the material's)
  double friction_factor = 0.8;     // friction multiplier per lowering stage
  double friction_floor_deg = 0.1;  // below this the friction is set to 0 (last stage)
  std::int64_t stage_steps = 2000;  // shortest stage
  std::int64_t check_every = 100;   // steps between equilibrium checks
  double stress_tolerance = 0.01;   // |σ − σc| / σc on every servo wall
  double unbalanced_force = 0.01;   // YADE unbalancedForce() threshold
  double kinetic_ratio = 1e-3;      // kinetic / elastic energy threshold
  double servo_gain = 0.25;         // fraction of the stress error removed per step
  double max_wall_speed_m_s = 0.1;
  double max_cell_rate_1_s = 1.0;  // a periodic cell's |L_ii| limit
  double core_inset_m = 0;  // void ratio of the core box inset by this from the walls (0: whole
                            // box); walls loosen the layer of grains they touch
  bool deposition = false;  // first let the cloud settle under gravity
  Eigen::Vector3d deposition_gravity = Eigen::Vector3d(0, 0, -9.81);
  std::int64_t max_steps = 0;  // 0: no limit
};

/// How a test measures its specimen: the walls the servo drives with their inward normals and
/// loaded areas, and the specimen volume (all may change as the walls move).
struct SpecimenGauge {
  /// The specimen box between the walls (lo, hi).
  std::function<std::pair<Eigen::Vector3d, Eigen::Vector3d>(const Simulation&)> box;
  std::vector<std::size_t> servo_walls;
  std::function<Eigen::Vector3d(const Simulation&, std::size_t wall)> inward;
  std::function<double(const Simulation&, std::size_t wall)> area_m2;
  /// A periodic cell instead of walls (no servo walls, no box): the servo drives the cell's
  /// first `cell_axes` diagonal components (2: the plane; 3) to −σc (Simulation::set_cell_servo
  /// with stiffness_fraction = servo_gain, max_rate = cell_max_rate_1_s), the void ratio is the
  /// cell's (cell_void_ratio).
  int cell_axes = 0;
  double cell_max_rate_1_s = 1.0;
  /// What a clump member counts of its sphere's volume in the void ratio (its clump's union
  /// volume over the members' sum; 1 for spheres).
  double clump_solid_factor = 1.0;
};

/// The gauge of a periodic cell servo-controlled on `axes` axes.
SpecimenGauge cell_gauge(int axes, double max_rate_1_s);

/// Void ratio of the box [lo, hi] from the exact sphere–box intersection volumes; the members of
/// clumps count `clump_solid_factor` of their volume (their clump's union volume over the
/// members' sum, for clumps of one template).
double box_void_ratio(const ParticleState& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                      double clump_solid_factor = 1.0);

class SpecimenPreparation final : public LoadingProgramme {
 public:
  /// `test_friction_deg`: the friction restored at the end (the material's for the test).
  SpecimenPreparation(PreparationSpec spec, SpecimenGauge gauge, double test_friction_deg);
  std::string name() const override { return "preparation"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  bool finished(const Simulation&) const override { return stage_ == kDone; }
  double progress(const Simulation& sim) const override;
  std::string curve_header() const override;
  std::string curve_row(const Simulation& sim) const override;
  std::int64_t frame_index(const Simulation&) const override { return 0; }
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;

  enum Stage : std::int64_t { kDeposition = 0, kCompaction, kLowering, kSettling, kDone };
  Stage stage() const { return static_cast<Stage>(stage_); }
  /// Void ratio of the whole box and of its core (the box inset by core_inset_m).
  double void_ratio(const Simulation& sim) const;
  double core_void_ratio(const Simulation& sim) const;
  double friction_deg() const { return friction_; }

 private:
  bool equilibrium(Simulation& sim, bool with_stress) const;
  /// Under a domain decomposition: whether each process's sums (Simulation::
  /// approximate_measures, within round-off of the whole's) show the specimen out of
  /// equilibrium by more than round-off could change, so that the check needs no gather.
  bool surely_unsettled(const Simulation& sim, bool with_stress) const;
  /// The stresses the servo holds (compression positive, Pa): each servo wall's, or the cell's
  /// diagonal.
  Eigen::VectorXd servo_stresses(const Simulation& sim) const;
  /// To the next stage; `core_void_ratio`: the core's void ratio now (read where a compaction
  /// stage ends).
  void next_stage(Simulation& sim, double core_void_ratio);

  PreparationSpec spec_;
  SpecimenGauge gauge_;
  double test_friction_;
  std::int64_t stage_ = kCompaction;
  std::int64_t stage_start_ = 0;  // step at which the stage began
  std::int64_t first_step_ = 0;
  double friction_ = 0, lowest_friction_ = 0;
  Eigen::Vector3d gravity_saved_ = Eigen::Vector3d::Zero();
};

}  // namespace gs::solver
