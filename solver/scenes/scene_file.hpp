// Scene files (TOML, schema in docs/scenes.md): packing, material, walls, solver settings and
// output cadence of one `granoscope simulate` run.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <memory>
#include <optional>

#include "clump_shapes.hpp"
#include "direct_shear.hpp"
#include "interface_shear.hpp"
#include "layered_filling.hpp"
#include "loading_programme.hpp"
#include "periodic_biaxial.hpp"
#include "plane_strain_compression.hpp"
#include "silo_flow.hpp"
#include "simulation.hpp"
#include "snapshot.hpp"
#include "specimen_generation.hpp"
#include "specimen_preparation.hpp"
#include "stress_rotation.hpp"
#include "triaxial_compression.hpp"

namespace gs::solver {

/// The most threads a scene or `simulate --threads` may ask for (a million crashed the run).
inline constexpr int kMaxThreads = 1024;

/// Below this many particles a scene with `threads = "auto"` (the default) starts on one thread:
/// two threads were slower than one on 883 and 2 000 spheres on a 2-core machine, and never
/// slower from 5 000 up (docs/scale.md).
inline constexpr std::size_t kAutoThreadsFrom = 5000;

/// The thread count `threads = "auto"` starts a run with for `particles` particles: one below
/// kAutoThreadsFrom, else machine_threads(). (The run then times its steps on neighbouring
/// counts and keeps the fastest: ThreadTuner.)
int auto_threads(std::size_t particles);
/// The machine's cores as OpenMP sees them, at most kMaxThreads.
int machine_threads();

struct OutputSpec {
  std::string trajectory = "trajectory.h5";
  std::int64_t every = 1000;            // steps between trajectory frames
  bool contacts = true;                 // store contacts in frames
  std::string history = "history.csv";  // monitors
  std::int64_t history_every = 100;
  std::int64_t checkpoint_every = 10000;
  std::string curve = "curve.csv";  // macroscopic curve of a laboratory test
  std::int64_t curve_every = 200;
  std::string specimen = "specimen.h5";  // the prepared specimen (one frame)
  std::string preparation = "preparation.csv";
  bool facet_forces = false;            // per-triangle forces of the mesh walls in the history
  std::vector<std::int64_t> track_ids;  // particles whose position and velocity the history holds
};

/// [specimen]: a seeded random specimen generated instead of reading a packing.
struct SpecimenSpec {
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();  // target specimen box (x, y, z)
  SizeSpec sizes;
  double void_ratio = 0.55;  // sets the number of spheres: Σ V = V_box / (1 + e)
  std::uint64_t seed = 1;
  double cloud_solid_fraction = 0.3;  // density of the loose cloud they are placed in
  // The periodic biaxial test (2D): a number of disks instead of size_m and void_ratio (which
  // is then the preparation's target only), in a square cell of this thickness (m).
  std::int64_t count = 0;
  bool disks = true;  // two_d = "disks" (true disks) or "spheres_in_plane"
  double thickness_m = 0;
};

/// [sweep]: one run per value of a scene key.
struct SweepInfo {
  std::string key;                  // "section.key"
  std::vector<std::string> values;  // as text (the run directories' names)
  int point = 0;                    // the point loaded
};

struct Scene {
  std::string name;
  // Materials by index (0: [material], then [[materials]] in order) and, where given, the radius
  // range [lo, hi] (m) of the particles that are of that material.
  std::vector<std::string> material_names;
  std::vector<std::array<double, 2>> material_radius_range;
  std::optional<SweepInfo> sweep;
  std::filesystem::path file;
  SimulationConfig config;
  std::vector<Particle> particles;
  std::vector<WallSpec> walls;  // [[walls]], then the walls of each [[mesh]]
  /// [[clump_template]] + [clumps]: rigid clumps whose members were appended to `particles`
  /// (Simulation::set_clumps).
  std::vector<ClumpBody> clumps;
  /// [clumps] replace = TEMPLATE: every sphere becomes a clump of its volume (seed 003 §2.4);
  /// a generated specimen is replaced once scene_programmes has made it.
  struct ClumpReplace {
    std::string template_name;
    std::vector<ClumpMember> shape;
    ClumpMassModel model = ClumpMassModel::MemberSum;
    std::uint64_t seed = 1;
  };
  std::optional<ClumpReplace> clump_replace;
  /// [outlet]: particles leaving [keep_lo, keep_hi] are removed (Simulation::set_outlet).
  std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> outlet;
  /// [fill]: layers inserted into a region before the `steps` run (LayeredFilling); the fill
  /// particles are `particles` from fill_first on, waiting for insertion; the walls
  /// open_after_fill are switched off when the filling ends.
  std::optional<FillSpec> fill;
  std::uint32_t fill_first = 0;
  std::vector<std::vector<std::uint32_t>> fill_layers;
  std::vector<std::size_t> open_after_fill;
  /// [cell]: a periodic cell (Simulation::set_periodic) with a velocity gradient.
  struct CellSpec {
    Eigen::Matrix3d hsize = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d vel_grad = Eigen::Matrix3d::Zero();
    bool planar = false;  // two_d = "spheres_in_plane" or "disks"
    bool disks = false;   // two_d = "disks": disks as thick as the cell (Simulation::set_disks)
    std::optional<CellServo> servo;  // control / target / servo_gain / max_rate_1_s
  };
  std::optional<CellSpec> cell;
  /// [solver] order = "spatial": the particles loaded (not those a [fill] inserts) renumbered
  /// along a Morton curve before the run (spatial_order.hpp); their ids unchanged.
  bool spatial_order = false;
  std::int64_t steps = 0;
  OutputSpec output;
  std::vector<std::pair<std::string, std::string>> parameters;  // flattened, for run metadata
  double dt_pwave = 0;        // YADE's PWaveTimeStep of the packing (s)
  double dt_auto_safety = 0;  // dt_s = "auto": dt = dt_safety · dt_pwave (0: dt given)

  // Laboratory tests (docs/scenes.md): empty `test` is a plain run of `steps` steps.
  // "", "triaxial", "plane_strain", "direct_shear", "interface_shear", "biaxial_periodic", "silo",
  // "stress_rotation"
  std::string test;
  std::optional<SpecimenSpec> specimen;
  std::optional<PreparationSpec> preparation;
  double wall_friction_deg = 0;  // smooth walls by default (seed 004 §4.1.2, seed 000 §3)
  TriaxialSpec triaxial;
  PlaneStrainSpec plane_strain;
  DirectShearSpec direct_shear;
  ShearBoxGeometry shear_box;
  PeriodicBiaxialSpec biaxial_periodic;
  InterfaceShearSpec interface_shear;
  InterfaceSurfaceSpec interface_surface;
  InterfaceShearGeometry interface_geometry;
  SiloSpec silo;
  StressRotationSpec stress_rotation;
};

/// Generates the specimen when the scene asks for one, builds the walls of its test and returns
/// the loading programmes to run in turn (preparation, then the test; a plain scene gets one
/// programme of `steps` steps). Throws InputError naming the scene file.
std::vector<std::unique_ptr<LoadingProgramme>> scene_programmes(Scene& scene);

/// A plain run: `steps` steps, a frame every `every` steps.
class FixedSteps final : public LoadingProgramme {
 public:
  /// `relative`: `steps` counted from where the programme starts (after a filling), not from 0.
  FixedSteps(std::int64_t steps, std::int64_t every, bool relative = false)
      : steps_(steps), every_(every), relative_(relative) {}
  std::string name() const override { return "steps"; }
  void start(Simulation& sim) override { first_ = sim.step_count(); }
  void control(Simulation&) override {}
  bool finished(const Simulation& sim) const override {
    return sim.step_count() >= (relative_ ? first_ : 0) + steps_;
  }
  double progress(const Simulation& sim) const override;
  std::string curve_header() const override { return {}; }
  std::string curve_row(const Simulation&) const override { return {}; }
  std::int64_t frame_index(const Simulation& sim) const override {
    return sim.step_count() / every_;
  }
  std::string summary(const Simulation&) const override { return {}; }
  std::string save_state() const override;
  void load_state(const std::string& state) override;

 private:
  std::int64_t steps_, every_;
  bool relative_ = false;
  std::int64_t first_ = 0;
};

/// Replaces the scene's spheres by clumps (scene.clump_replace; nothing when there are none or
/// clumps already), the time step recomputed when it is "auto".
void replace_spheres_by_clumps(Scene& scene);

/// Reads and checks a scene file. Throws InputError "FILE: key: what (value)".
/// Whether the file parses as TOML with a [sweep] section (false on any error: load_scene
/// reports it).
bool scene_has_sweep(const std::filesystem::path& path);

/// Values set over the file's: dotted key (SECTION.KEY; SECTION.INDEX.KEY in an array of
/// tables such as walls.0.friction_deg) and a TOML value ("1e-6", "true", "\"name\"", "[1, 2]").
using SceneOverrides = std::vector<std::pair<std::string, std::string>>;

/// `sweep_point`: with a [sweep] section, the point to load (its key set to values[point];
/// negative: point 0). The scene's `sweep` then names the key, the values and the point.
/// `overrides` are applied after the sweep point and checked as if the file said them.
Scene load_scene(const std::filesystem::path& path, int sweep_point = -1,
                 const SceneOverrides& overrides = {});

/// Dotted keys and their values (TOML text) of a scene given as TOML text; arrays of tables
/// (walls, materials) as one value.
std::map<std::string, std::string> scene_values(const std::string& toml_text);

/// Dotted keys whose values differ between two scenes given as TOML text (keys present in only
/// one included), sorted. What `simulate --resume` compares with the scene of the run it resumes.
std::vector<std::string> scene_differences(const std::string& a, const std::string& b);

}  // namespace gs::solver
