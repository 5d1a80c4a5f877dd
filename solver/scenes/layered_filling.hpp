// Gravitational filling in layers (seed 004 §5.2: the silo "was filled ... progressively by
// distributed gravitational filling using 6 layers of sand. Each upper layer of granular
// material was added after the kinetic energy of the particles in the silo decreased to a
// negligible level"). The particles of all layers exist from the start, waiting for insertion
// (Simulation::set_pending); a layer is placed by random sequential addition in the fill region,
// clear of the particles already there and of the walls, and falls; the next one follows once
// the kinetic energy is below the threshold. The seed does not say what "negligible" is: here
// the translational kinetic energy Σ ½·m·v² < ratio · Σ m·|g|·d over the bodies in the scene
// (the work of lifting each by its own diameter), ratio 1e-4 by default (a mean speed of
// about sqrt(2e-4·g·d), 1.7 mm/s for d = 1.5 mm). Translational only: without twisting
// resistance nothing damps a sphere's spin about its contact normal, so the total kinetic
// energy of a packing at rest can stay above any such threshold for good.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "loading_programme.hpp"
#include "specimen_generation.hpp"

namespace gs::solver {

struct FillSpec {
  Eigen::Vector3d region_lo_m = Eigen::Vector3d::Zero(), region_hi_m = Eigen::Vector3d::Zero();
  int layers = 6;
  std::int64_t count = 0;  // particles in all layers (the first layers take the remainder)
  SizeSpec sizes;
  std::uint64_t seed = 1;
  double kinetic_ratio = 1e-4;   // next layer once E_k < ratio · Σ m·|g|·d
  std::int64_t min_steps = 100;  // steps a layer falls at least before the next
  // Steps in a row the energy must stay below the threshold before a layer counts as settled
  // (1: the first step below). A grain at the top of a bounce, or a layer held up for a moment
  // before it collapses, is below the threshold for a few steps: a hold longer than that does
  // not take it for rest.
  std::int64_t hold_steps = 1;
  std::int64_t max_steps = 10000000;  // a layer that has not settled by then is an error
  int max_attempts = 20000;           // random draws per particle before the region is full
  // The inter-particle friction angle while filling (negative: the material's): a lower one
  // packs denser (the seeds reach their initial void ratios so, seed 004 §4.2.2); the
  // material's comes back when the filling ends.
  double friction_deg = -1;
  // The global damping while filling (negative: the solver's), back when the filling ends: a
  // fill poured without damping (the DEM8 benchmark's contacts) settles faster with some.
  double damping = -1;
  // Where a layer's particles go: by random sequential addition ("random") or on a simple cubic
  // lattice of spacing 1.05 · the layer's largest diameter, its sites taken from the region's
  // bottom up (`lattice`; each site jittered by up to ±1 % of that diameter): twice as dense
  // as a random addition can reach, so a layer falls less far.
  bool lattice = false;
};

/// The particles of the layers (ids from `first_id`, radii drawn largest first within each
/// layer, all placed at the region's centre until inserted) and, per layer, their indices
/// counted from the first of them.
struct FillParticles {
  std::vector<Particle> particles;
  std::vector<std::vector<std::uint32_t>> layers;
};
FillParticles fill_particles(const FillSpec& spec, std::int64_t first_id);

/// Places particles of the given radii by random sequential addition in [lo, hi] (each wholly
/// inside), clear of the particles of `sim` in the scene and of its active walls. Returns the
/// positions of those that fitted, in order; stops at the first that found no place after
/// `max_attempts` draws. With `lattice`: on the lattice sites of FillSpec::lattice instead, the
/// first free site (from the bottom, along gravity) for each; stops when the sites run out.
std::vector<Eigen::Vector3d> place_in_region(const Simulation& sim,
                                             const std::vector<double>& radii,
                                             const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                             std::uint64_t seed, int max_attempts,
                                             bool lattice = false);

/// Thrown when a layer does not fit or does not settle; says how many particles fitted.
class FillError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The programme: inserts layer 0 at start, each next layer once the previous has fallen at
/// least min_steps and the kinetic energy is below the threshold, and ends when the last layer
/// has settled; then switches off the walls named in `open_walls` (an outlet opened after the
/// filling). `first_index`: the index of the first fill particle in the simulation.
class LayeredFilling final : public LoadingProgramme {
 public:
  LayeredFilling(FillSpec spec, std::uint32_t first_index,
                 std::vector<std::vector<std::uint32_t>> layers, std::int64_t frame_every,
                 std::vector<std::size_t> open_walls = {});
  std::string name() const override { return "filling"; }
  void start(Simulation& sim) override;
  void control(Simulation& sim) override;
  bool finished(const Simulation&) const override { return done_; }
  double progress(const Simulation& sim) const override;
  std::string curve_header() const override { return {}; }
  std::string curve_row(const Simulation&) const override { return {}; }
  std::int64_t frame_index(const Simulation& sim) const override;
  std::string summary(const Simulation& sim) const override;
  std::string save_state() const override;
  void load_state(const std::string& state) override;
  int layers_inserted() const { return inserted_; }
  /// The kinetic-energy threshold (J) for the particles now in the scene, and the energy it
  /// is compared with: Σ ½·m·v² over the free particles and the clumps in the scene.
  double threshold(const Simulation& sim) const;
  static double settling_energy(const Simulation& sim);
  /// Both at once: {energy, threshold} (one exchange of terms under a domain; `exact` false:
  /// see Simulation::owned_sums).
  std::pair<double, double> energy_and_threshold(const Simulation& sim, bool exact = true) const;

 private:
  void insert_layer(Simulation& sim);
  FillSpec spec_;
  std::uint32_t first_;
  std::vector<std::vector<std::uint32_t>> layers_;
  std::vector<std::size_t> open_walls_;
  int inserted_ = 0;
  std::int64_t last_insert_step_ = 0;
  bool done_ = false;
  std::int64_t frame_every_ = 0;
  double material_friction_deg_ = 0;  // restored when the filling ends (fill.friction_deg)
  double solver_damping_ = 0;         // restored when the filling ends (fill.damping)
  bool moved_ = false;      // the last layer's kinetic energy has been above the threshold
  std::int64_t below_ = 0;  // steps in a row below the threshold (fill.hold_steps)
};

}  // namespace gs::solver
