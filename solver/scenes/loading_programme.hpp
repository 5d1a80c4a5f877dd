// A scene's loading programme: what a laboratory test does to its walls and particles between
// steps (servo control, prescribed strain, membrane pressure, friction changes), when it ends,
// its macroscopic curve and when it writes a frame. One implementation per test, one file each
// (specimen_preparation, triaxial_test, plane_strain_test, direct_shear_test), in the manner of
// MercuryDPM's one driver per scene. `granoscope simulate` runs a list of programmes in turn.
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "simulation.hpp"

namespace gs::solver {

/// Thrown by a programme that cannot go on (a target the servo cannot reach, a specimen that
/// does not fit): the message says where it stopped. The run reports it as an input error.
class ProgrammeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LoadingProgramme {
 public:
  virtual ~LoadingProgramme() = default;
  /// "preparation", "triaxial", "plane_strain", "direct_shear", "steps".
  virtual std::string name() const = 0;
  /// Takes over the simulation (walls switched, reference state recorded). Called once, not
  /// again when a run resumes from a checkpoint (the state then comes from load_state()).
  virtual void start(Simulation& sim) = 0;
  /// Before every step: wall velocities, applied forces, stage changes.
  virtual void control(Simulation& sim) = 0;
  /// After a step: has the programme reached its end?
  virtual bool finished(const Simulation& sim) const = 0;
  /// 0..1, for the progress line.
  virtual double progress(const Simulation& sim) const = 0;
  /// The macroscopic curve: CSV header (no newline) and one row of the current state.
  virtual std::string curve_header() const = 0;
  virtual std::string curve_row(const Simulation& sim) const = 0;
  /// Frames are written whenever this index increases (e.g. every Δε of strain).
  virtual std::int64_t frame_index(const Simulation& sim) const = 0;
  /// Lines for the end-of-run report.
  virtual std::string summary(const Simulation& sim) const = 0;
  /// Named end-of-run numbers (peak friction, residual strain …): `results.csv` of the run and
  /// one row of a sweep's table. Empty for a programme with none.
  virtual std::vector<std::pair<std::string, double>> results(const Simulation&) const {
    return {};
  }
  /// Exact state for checkpoints (doubles as hexadecimal floats: bit-for-bit resume).
  virtual std::string save_state() const = 0;
  virtual void load_state(const std::string& state) = 0;
};

/// key → value text with exact doubles, for save_state()/load_state().
class ProgrammeState {
 public:
  ProgrammeState() = default;
  explicit ProgrammeState(const std::string& text);
  void set(const std::string& key, double v);
  void set(const std::string& key, std::int64_t v);
  double number(const std::string& key) const;
  std::int64_t integer(const std::string& key) const;
  bool has(const std::string& key) const { return values_.count(key) != 0; }
  std::string text() const;

 private:
  std::map<std::string, std::string> values_;
};

/// Normal stress (Pa, compression positive) that the particles exert on wall w over `area_m2`:
/// the contact force on the wall against the wall's inward normal `inward`.
double wall_stress(const Simulation& sim, std::size_t w, const Eigen::Vector3d& inward,
                   double area_m2);

/// Stiffness-based servo (as YADE's TriaxialStressController): the velocity along the inward
/// normal that removes the fraction `gain` of the stress error per step, from the summed
/// normal stiffness of the wall's contacts; at full speed `max_speed` while it touches nothing.
/// Positive: into the specimen (too little stress).
double servo_speed(const Simulation& sim, std::size_t w, double stress_Pa, double target_Pa,
                   double area_m2, double gain, double max_speed);

/// Zeroes the particles' cumulative rotation vectors: the rotations of a test's frames count
/// from the start of its loading (seed 000 Fig 4, seed 004 §4.2.3), not from the preparation.
void reset_rotations(Simulation& sim);

/// Mean sphere diameter (m), the d50 of a test's inertial number when the scene gives none.
double mean_diameter(const ParticleState& p);

/// A programme that runs until a monotonic measure (axial strain, displacement) reaches `max`,
/// with a trajectory frame every `every` of it.
struct MeasureTarget {
  double max = 0, every = 0;
  bool reached(double v) const { return v >= max; }
  double progress(double v) const;
  std::int64_t frame_index(double v) const;
};

/// A test driven until a monotonic measure of its loading (axial strain, displacement) reaches
/// the target's maximum, with a frame every `target.every` of it.
class MeasuredProgramme : public LoadingProgramme {
 public:
  explicit MeasuredProgramme(MeasureTarget target) : target_(target) {}
  /// The measure of the loading so far.
  virtual double measure(const Simulation& sim) const = 0;
  bool finished(const Simulation& sim) const final { return target_.reached(measure(sim)); }
  double progress(const Simulation& sim) const final { return target_.progress(measure(sim)); }
  std::int64_t frame_index(const Simulation& sim) const final {
    return target_.frame_index(measure(sim));
  }

 protected:
  MeasureTarget target_;
};

/// Warns once on stderr when the inertial number exceeds `threshold` (not quasi-static).
struct InertialWarning {
  double threshold = 1e-4;
  bool warned = false;
  void check(double inertial, const std::string& test, double strain);
};

/// Coordination number Z = 2·(sphere–sphere contacts) / particles (walls not counted).
double coordination_number(const Simulation& sim);

/// Void ratio of a periodic cell: (V − V_s)/V_s with V the cell's volume and V_s the particles'
/// (2D: the cell's area and the disks' areas).
double cell_void_ratio(const Simulation& sim);

/// A−B in the energy ledger's sense: the elastic energy stored in the contacts (J).
double elastic_energy(Simulation& sim);

}  // namespace gs::solver
