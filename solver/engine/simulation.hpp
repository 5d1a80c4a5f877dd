// The DEM engine: spheres and rigid walls under the YADE contact law, stepped as YADE's engine
// loop does (contact detection, contact law, integration), with monitors, an energy ledger,
// blow-up detection and bit-exact checkpoints.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cohesive_frictional_law.hpp"
#include "contact_geometry.hpp"
#include "dem_types.hpp"
#include "domain.hpp"
#include "neighbor_list.hpp"
#include "newton_integrator.hpp"
#include "periodic_cell.hpp"
#include "rigid_clump.hpp"
#include "snapshot.hpp"

namespace gs::solver {

/// Control of a periodic cell's diagonal (the role of YADE's PeriTriaxController): each axis
/// either strain-rate controlled (L_ii = target, 1/s) or stress controlled: after each step
/// L_ii = clamp(gain·(target − σ_ii), ±max_rate) with σ the cell stress (Pa, compression
/// negative), taking effect in the next step as any velocity gradient does.
/// With `stiffness_fraction` f > 0 the gain of axis i is f/(K_ii·dt) instead, K_ii the affine
/// stiffness of the contacts, K_ii = (1/V) Σ l_i² (kn n_i² + ks (1 − n_i²)) (l the branch
/// vector, n the normal): the step's strain then removes the fraction f of the stress error
/// were the assembly to deform affinely (the stiffness-scaled servo of YADE's walls, for the
/// cell; a stress axis with no contact moves at max_rate).
struct CellServo {
  std::array<bool, 3> stress = {false, false, false};  // true: axis i is stress controlled
  Eigen::Vector3d target = Eigen::Vector3d::Zero();    // Pa (stress axes) or 1/s (rate axes)
  double gain = 0;                                     // 1/(Pa·s)
  double max_rate = 0;                                 // 1/s, |L_ii| of a stress axis
  double stiffness_fraction = 0;  // > 0: gain_i = fraction/(K_ii·dt), `gain` unused
};

struct SimulationConfig {
  Material material;
  ContactLaw law = ContactLaw::CohesiveFrictional;
  // Hertz–Mindlin law only: further materials (index 1, 2, ...; 0 is `material`), and the
  // material-pair table, (1 + more_materials)² entries, symmetric: the restitution of each pair
  // (empty: one material, its own), and its friction angle (negative or empty: the smaller of the
  // two materials' angles, as YADE's default).
  std::vector<Material> more_materials;
  std::vector<double> pair_restitution, pair_friction_deg;
  // Walls under the Hertz–Mindlin law: flat (the wall's radius 1e5 m, R* = R to 1e-8, YADE's
  // Ig2_Facet_Sphere_ScGeom(hertzian=True)), or YADE's default radii (box R, facet 2R).
  bool hertz_flat_walls = true;
  double dt = 0;  // s
  double damping = 0;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  double skin = 0;  // m; 0 = half the smallest radius (YADE's default verletDist)
  int threads = 1;
  double twist_beta = 0;             // twisting stiffness factor (0: twisting moment off)
  double twist_eta = -1;             // twisting limit factor (negative: unbounded)
  double max_overlap_ratio = 0.1;    // blow-up when an overlap exceeds this fraction of a radius
  double max_energy_residual = 0.2;  // blow-up when |ledger residual| exceeds this fraction of
                                     // the energy turnover (checked by check_energy())
};

/// Cumulative energy terms (J). Inputs are positive when energy enters the system.
struct EnergyLedger {
  double kinetic = 0, elastic_normal = 0, elastic_shear = 0, elastic_rolling = 0;
  double friction_dissipation = 0, rolling_dissipation = 0, damping_dissipation = 0;
  double viscous_dissipation = 0;  // the Hertz–Mindlin law's viscous contact forces
  double gravity_work = 0, wall_work = 0, external_work = 0;
  double outflow = 0;  // kinetic energy of the particles removed through an outlet
  double initial = 0;  // kinetic + elastic at the start
  double stored() const { return kinetic + elastic_normal + elastic_shear + elastic_rolling; }
  double dissipated() const {
    return friction_dissipation + rolling_dissipation + damping_dissipation + viscous_dissipation +
           outflow;
  }
  /// stored + dissipated − (initial + work in): zero for an exact integration.
  double residual() const {
    return stored() + dissipated() - (initial + gravity_work + wall_work + external_work);
  }
};

/// Thrown when the state becomes unphysical (NaN, excessive overlap).
class BlowUp : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// YADE's PWaveTimeStep: min over spheres of r·sqrt(ρ/E).
double pwave_timestep(const std::vector<double>& radii, double density, double young);

/// The `dt_s = "auto"` base of a material: pwave_timestep, or with a constant Kn
/// (Material::normal_stiffness_N_m) min over spheres of sqrt(m/Kn), m = ρ·(4/3)π r³ (the
/// period of a sphere on one spring over 2π; seed 003's dt = 1.02 µs is 0.58 of it at r = 0.3 mm).
double material_timestep(const std::vector<double>& radii, const Material& m);

/// Cuts of a list of pairs into nt shares of equal cost, as fractions of the list (nt + 1 of
/// them, 0 … 1): equal counts, unless `seconds` holds the time each share of the last split took
/// (its pairs [bounds[t], bounds[t+1])); then the cost per pair is taken as constant within
/// each of those shares. The threads' contact pass is split so (Simulation::split_pairs).
std::vector<double> balanced_cuts(std::size_t nt, const std::vector<std::size_t>& bounds,
                                  const std::vector<double>& seconds);

class Simulation {
 public:
  Simulation(SimulationConfig config, const std::vector<Particle>& particles,
             std::vector<WallSpec> walls);

  /// One time step. Throws BlowUp.
  void step();
  void run(std::int64_t steps);

  std::int64_t step_count() const { return step_; }
  double time() const { return time_; }
  const SimulationConfig& config() const { return cfg_; }
  /// The OpenMP threads of the following steps (at least 1). Every count gives the same bits
  /// (docs/physics.md), so a run may change it between any two steps (ThreadTuner).
  void set_threads(int threads);
  const ParticleState& particles() const { return p_; }
  ParticleState& particles() { return p_; }
  const std::vector<WallState>& walls() const { return walls_; }
  /// The walls to change (velocity, position, …). Changes made before the next step() take
  /// effect in it; a reference kept across a step is not to be written through (fetch the walls
  /// again): the engine then sorts the walls anew into those it must look at every step and
  /// those that stand still, so that a mesh of many still walls costs nothing per step.
  std::vector<WallState>& mutable_walls() {
    walls_dirty_ = true;
    return walls_;
  }
  /// Sets wall w's velocity (m/s) for the next steps, without sorting all the walls anew.
  void set_wall_velocity(std::size_t w, const Eigen::Vector3d& velocity);

  /// Snapshot of the current state: particles, real contacts, walls with their loads.
  Frame frame() const;
  /// frame() in pieces, to write a large one without holding it whole: the head (all but the
  /// particles and contacts), and piece i of them (the particles of [i·rows, (i+1)·rows) and
  /// the contacts of those candidate pairs), appended to `piece`; false for the last piece.
  Frame frame_head() const;
  bool frame_piece(std::size_t i, std::size_t rows, Frame& piece) const;
  std::size_t contact_count() const;
  /// Real sphere–sphere contacts (wall contacts not counted).
  std::size_t sphere_contact_count() const;
  /// YADE's unbalancedForce: mean |resultant force| on free particles / mean |contact force|.
  double unbalanced_force() const;
  double kinetic_energy() const;
  /// The kinetic energy of the bodies that touch something (a real contact): without the
  /// rattlers, which in a periodic cell keep flying or spinning undamped (local damping acts on
  /// forces) and would hold any kinetic-energy criterion of equilibrium off forever.
  double kinetic_energy_in_contact() const;
  /// Whole-assembly measures for a decision far from its threshold.
  struct Measures {
    double unbalanced_force = 0;  // as unbalanced_force()
    double kinetic_J = 0;         // kinetic_energy(), or kinetic_energy_in_contact()
    double elastic_J = 0;         // the elastic energy of the contacts (energy()'s)
    std::size_t contacts = 0;     // contact_count(), exactly
  };
  /// Under a domain (collective): each process sums over its own bodies and over the contacts
  /// of its own first bodies, and the sums are added over processes (a few doubles). Every term
  /// is non-negative, so each measure is within N·ε (relative) of the one-process value: a
  /// decision with a margin of 1e-6 is the one-process decision, without a gather. Without a
  /// domain: the same sums over everything (within round-off of the functions above).
  Measures approximate_measures(bool kinetic_in_contact) const;
  /// Global inertial number I = γ̇·d/sqrt(p/ρ): γ̇ = sqrt(2·D':D') from the least-squares
  /// affine fit of particle velocities to positions (D its symmetric part, ' deviatoric),
  /// d the mean diameter, p the mean stress of the contact (Love–Weber) stress over the bounding
  /// box of the particles. NaN without contacts or under tension.
  double inertial_number() const;
  /// Updates the stored-energy terms of the ledger and returns it.
  const EnergyLedger& energy();
  /// Throws BlowUp when the ledger residual is out of bounds (see SimulationConfig).
  void check_energy();
  /// Id that walls get in snapshots: first wall = (largest particle id) + 1, like YADE bodies.
  std::int64_t wall_id(std::size_t w) const { return wall_id_base_ + static_cast<std::int64_t>(w); }
  std::int64_t neighbor_list_builds() const { return nl_.builds; }

  /// Sum of the normal stiffnesses Kn (N/m) of the real contacts on wall w, and their count:
  /// what a stiffness-based servo needs (YADE TriaxialStressController).
  std::pair<double, std::size_t> wall_stiffness(std::size_t w) const;
  /// Changes the friction angle of every existing and future contact, as YADE's
  /// setContactFriction does for sphere pairs, and at once for the contacts of walls that have
  /// no friction angle of their own (spec.friction_deg < 0; the others keep theirs).
  void set_friction_deg(double friction_deg);
  void set_damping(double damping) { cfg_.damping = damping; }
  /// Changes the time step from the next step on (seed 003: a dynamic deposition, then the
  /// quasi-static stages at a smaller one). Not in checkpoints: a programme that changes it sets
  /// it again before every step. Throws std::invalid_argument unless positive and finite.
  void set_dt(double dt);
  void set_gravity(const Eigen::Vector3d& g) { cfg_.gravity = g; }
  /// Switches a wall on or off; contacts with an inactive wall are dropped.
  void set_wall_active(std::size_t w, bool active);
  /// Makes rigid clumps of particles (before the first step): each member is then moved with
  /// its clump (YADE's Clump::moveMembers) and never touches another member of it; the loads on
  /// the members drive the clump (integrate_clump). Throws on a member index out of range or in
  /// two clumps.
  void set_clumps(std::vector<ClumpBody> clumps);
  const std::vector<ClumpBody>& clumps() const { return clumps_; }
  /// The clumps' states, for a domain decomposition to move between processes (the members
  /// and mass properties are not to be changed).
  std::vector<ClumpBody>& clump_states() { return clumps_; }

  /// Outlet: after each step, particles whose centre has left the box [lo, hi] are removed (seed
  /// 004 §5.2, silo discharge): frozen where they left, in no contact, no longer in frames or
  /// energies (their kinetic energy goes to the ledger's outflow term). Clump members are not
  /// removed. Removal survives checkpoints.
  void set_outlet(const Eigen::Vector3d& keep_lo, const Eigen::Vector3d& keep_hi);
  /// Removes particles for good (seed 003 §2.4's carving), as an outlet does: a member of a
  /// clump takes its whole clump (the clumps after it are renumbered). Their kinetic energy and
  /// the elastic energy of their contacts count in the ledger's outflow. Counted in
  /// removed_count() and removed_mass(). Throws std::invalid_argument on an index out of range.
  void remove_particles(const std::vector<std::size_t>& indices);
  std::size_t removed_count() const { return removed_count_; }
  double removed_mass() const { return removed_mass_; }  // kg

  /// Per-facet forces: with `on`, each facet wall sums its contact forces per triangle too
  /// (WallState::facet_force, in the order of its facets), for wall-stress profiles.
  void set_facet_forces(bool on);
  bool facet_forces() const { return facet_forces_; }

  /// Filling (seed 004 §5.2): the particles `indices` are not yet in the scene — frozen, in no
  /// contact, not in frames — until insert_particle places one (at rest). Their state is kept
  /// in checkpoints (ParticleState::removed = 2).
  void set_pending(const std::vector<std::uint32_t>& indices);
  void insert_particle(std::uint32_t i, const Eigen::Vector3d& position);
  bool pending(std::size_t i) const { return p_.removed[i] == 2; }

  /// Periodic cell (before the first step; YADE's O.periodic with O.cell.hSize): particles
  /// interact with the images of the others across its faces, positions stay unwrapped (as
  /// YADE stores them), and a velocity gradient deforms the cell and the assembly. `planar`:
  /// YADE's 2D emulation (blockedDOFs 'zXY' on every particle; all centres in one plane
  /// z = const). Throws std::invalid_argument on walls or clumps (not supported in a cell), a
  /// degenerate or inverted cell, or a cell too small (PeriodicTooSmall).
  void set_periodic(const Eigen::Matrix3d& hsize, bool planar = false);
  /// True disks in the plane (after set_periodic(…, planar = true); seed 002's assembly): a
  /// disk of thickness t has m = ρ·π·r²·t and I = m·r²/2, and a contact between disks the
  /// normal stiffness Ec·t (Ec per unit thickness, whatever the radii: a line contact), Ks =
  /// νc·Kn, Kr = β·Ks·R1·R2. Throws unless the cell is planar, or on t <= 0.
  void set_disks(double thickness_m);
  bool disks() const { return disk_thickness_ > 0; }
  bool periodic() const { return periodic_; }
  bool planar() const { return planar_; }
  const PeriodicCell& cell() const { return cell_; }
  /// YADE's O.cell.velGrad = L: takes effect in the next step's integration, and the cell then
  /// follows one step later (docs/physics.md).
  void set_velocity_gradient(const Eigen::Matrix3d& l);
  /// YADE's utils.getStress() in a periodic cell: (1/det H)·Σ (Fn + Fs) ⊗ (x1 − x2 − H·cellDist)
  /// over the real contacts (Pa, compression negative; seed 000 eq 12, Love–Weber).
  Eigen::Matrix3d cell_stress() const;
  /// Σ x ⊗ f over the real contacts of the walls first .. first + count - 1: x the contact
  /// point, f the force the wall exerts on the sphere (N·m). The boundary term of seed 003's
  /// Eq 14 (σ = -(1/v)(Σ x ⊗ F + Σ x ⊗ G), compression positive). Under a domain
  /// (collective): the one-process sum, from every process's wall contacts in pair order.
  Eigen::Matrix3d wall_contact_moment(std::size_t first, std::size_t count) const;
  /// The affine stiffness of the contacts along each axis (Pa): K_ii of CellServo.
  Eigen::Vector3d cell_stiffness() const;
  /// The cell servo in force, if any.
  const std::optional<CellServo>& cell_servo() const { return cell_servo_; }
  /// Controls the cell's diagonal from now on; the off-diagonal gradient is the last one set
  /// (set_velocity_gradient). Throws without a cell, or on a bad gain, rate limit or target.
  void set_cell_servo(const CellServo& servo);

  /// Forces a neighbour-list rebuild before the next step.
  void invalidate_neighbors() { nl_.ref_pos.clear(); }

  /// Domain decomposition (issue 23, docs/scale.md): `domain` gets the step's collective calls
  /// (nullptr: none). Spheres and clumps between planes, boxes and meshes, or spheres in a
  /// periodic cell, with or without an outlet and particles waiting to enter. A domain gives
  /// each clump's members the owner of the clump.
  void set_domain(Domain* domain);
  /// Under a domain decomposition (collective): a neighbour-list rebuild now, after which
  /// every process holds every particle's present state, for a programme that reads the whole
  /// assembly (a filling placing a layer). Nothing without a domain.
  void share_all_states();
  /// What `fn` computes from the whole assembly, on every process: fn(*this) without a domain
  /// (or while this process holds the whole). Under a domain (collective): the domain gathers
  /// the whole into process 0, fn runs there on the state one process would hold, and its values
  /// go to every process. For a programme's decisions on whole-assembly measures (the unbalanced
  /// force, the energies, a void ratio), taken every so many steps: a gather is the state of
  /// every particle and contact. fn must not throw (the other processes wait for its values).
  std::vector<double> on_whole(const std::function<std::vector<double>(Simulation&)>& fn);
  /// Every particle's present position (as p.pos without a domain, or while this process holds
  /// the whole). Under a domain (collective): each owner's positions, shared with every process
  /// (3 doubles per particle), the process's own state left as it is.
  std::vector<Eigen::Vector3d> present_positions() const;
  /// kCount sums, each Σ over the particles then over the clumps of the terms particle(i, t)
  /// and clump(k, t) write (t[0 … kCount − 1]; callables, inlined: a template), added in index
  /// order: the sums one process computes, and the same bits on every process of a domain. Each
  /// process calls the functions for its own bodies only (every body without a domain); the terms
  /// travel to every process (one Domain::share for all the sums) and are added there. Collective
  /// once the domain has set the processes' parts (a process holding every body adds them alone).
  /// `exact` false: under a domain, each process adds its own bodies' terms and the sums are
  /// added over processes (Domain::add_over_processes): within round-off of the exact sums, the
  /// same bits on every process, for a few bytes instead of every body's terms.
  template <int kCount, class Particle, class Clump>
  std::array<double, kCount> owned_sums(Particle&& particle, Clump&& clump,
                                        bool exact = true) const;
  /// Whether a domain decomposition steps this simulation.
  bool decomposed() const { return domain_ != nullptr; }
  /// While a domain has gathered the whole assembly for output (process 0 holds it), sums are
  /// this process's own and no collective is made (the others' values are not used).
  void set_gathered(bool gathered) { gathered_ = gathered; }
  /// This simulation becomes `earlier` (a copy taken before), all but its energy ledger, which
  /// stays as it is now (a domain's process 0 steps on as it was before an output that gathered
  /// the whole assembly into it, with the ledger's sums of that output).
  void restore_keeping_ledger(Simulation&& earlier);
  /// Under a domain, an outlet's removals are counted here, in index order as one process
  /// counts them, where a process holds every particle's current state (a domain's rebuild,
  /// which ends every step that removed a particle anywhere). Each owner retires its own particles
  /// as they leave (their kinetic energy to its ledger's outflow, the count left for this call);
  /// any other particle found outside the kept box was retired by its owner on the same bits, and
  /// is retired here too.
  void count_outflow();
  /// The part of the scene this process steps: per particle a ParticleRole. Pairs are kept
  /// where at least one body is owned; only owned particles are integrated and counted in the
  /// ledger's particle terms. Empty: every particle owned. Takes effect at the next rebuild.
  void set_roles(std::vector<std::uint8_t> roles);
  const std::vector<std::uint8_t>& roles() const { return roles_; }
  /// Rebuilds the neighbour list now, for the roles set; the histories in `received` (pairs
  /// other processes computed until now; sorted or not) replace those of the same pairs.
  /// `keep_reference` (a list for output, not for stepping): the list's reference positions
  /// stay those of the last rebuild, and every real contact received is in the list, also one
  /// whose pair the build leaves out (of a wall switched off since the last step; not in a
  /// periodic cell).
  void rebuild_local(const std::vector<ContactHistory>& received, bool keep_reference = false);
  /// The candidate pairs (sorted by (a, b)) and their histories, parallel.
  const std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs() const { return nl_.pairs; }
  const std::vector<ContactHistory>& histories() const { return hist_; }
  /// The ledger's cumulative terms, for a domain to sum them over processes.
  EnergyLedger& ledger_terms() { return ledger_; }
  /// Under a domain: whether the walls' loads are summed each step over every process's wall
  /// contacts in pair order (wall_load_records), the sums one process forms, or per process and
  /// then over processes (within round-off of them, for fewer bytes and collectives). Exact
  /// where the run reads them as it steps: a servo wall, or `on` (a programme's control).
  void set_exact_wall_loads(bool on) { exact_wall_loads_ = on; }
  bool exact_wall_loads() const { return exact_wall_loads_ || !servo_walls_.empty(); }
  /// Doubles per wall contact in wall_load_records().
  static constexpr std::size_t kWallRecord = 13;
  /// This process's touching wall pairs of the last step, in pair order, each as the terms the
  /// step adds to its wall's loads: particle, wall, normal stiffness, force (3), arm (3),
  /// moment (3) and the triangle its force goes to (−1: none). For a domain: every process's
  /// records merged in pair order are one process's.
  std::vector<double> wall_load_records() const;
  /// The walls' loads (force, torque, contact stiffness and count, per-triangle forces) summed
  /// anew from `records`, in their order, as the step sums its own.
  void sum_wall_load_records(const std::vector<double>& records);
  /// The walls' loads set from `sums`, 8 per wall: force (3), torque (3), contact stiffness and
  /// count (a domain's sums over processes).
  void set_wall_loads(const std::vector<double>& sums);
  /// The Verlet skin (m).
  double skin() const { return nl_.skin; }

  /// Complete state, for bit-for-bit resumption. `extra` is stored alongside (the state of a
  /// scene's loading programme) and returned by load_checkpoint.
  void save_checkpoint(const std::filesystem::path& path, const std::string& extra = {}) const;
  std::string load_checkpoint(const std::filesystem::path& path);

 private:
  void rebuild_neighbors();
  /// Re-attaches contact histories (sorted by pair) to the current pair list: those of the
  /// previous list, held in hist_ and params_ (moved in place; pairs kept keep their
  /// parameters), or with `from`, those given (a checkpoint's).
  void attach_histories(const std::vector<ContactHistory>* from = nullptr);
  /// Geometry and body motions of candidate pair k; false when the centres coincide.
  bool pair_geometry(std::size_t k, ContactGeometry& g, BodyMotion& m1, BodyMotion& m2,
                     std::uint32_t* facet = nullptr) const;
  /// pos, facets and normal of a rotating facet wall from its rotation and centre.
  static void place_rotated_facets(WallState& w);
  /// Motions, history and parameters of candidate pair k into lane j of a batch, with the
  /// geometry of a wall pair (a sphere pair's the batch computes); false when a wall pair does
  /// not touch (its history is then marked not real).
  bool prepare_pair(std::size_t k, ContactBatch& batch, int j);
  /// A wall pair's own fields of lane j (geometry and the bodies' motion), or false (and the
  /// contact ended) where it does not touch: prepare_pair's part for walls.
  bool prepare_wall_lane(std::size_t k, ContactBatch& batch, int j);
  /// Material i of the scene (0: cfg_.material).
  const Material& material_at(int i) const {
    return i == 0 ? cfg_.material : cfg_.more_materials[static_cast<std::size_t>(i - 1)];
  }
  /// The scene's contact law on lanes [0, count) of a prepared batch.
  void run_law(ContactBatch& batch, int count, double dt) const;
  /// Fills a batch with the next touching pairs from k (advanced) up to end; returns the
  /// number of lanes, lane_pair[j] the pair of lane j.
  /// With kIndexed, positions i in [i, end) of pass_pairs_ instead of pairs themselves.
  template <bool kIndexed>
  int fill_batch(std::size_t& i, std::size_t end, ContactBatch& batch, std::uint32_t* lane_pair);
  /// The facet pairs whose gap the displacements since the build may have closed join the
  /// pairs the contact pass visits (in pair order).
  void admit_deferred();
  /// The law's results in lane j back into pair k's history, and its loads; false (the
  /// history marked not real) when the pair does not touch. Raises max_overlap_ratio past the
  /// blow-up limit.
  bool finish_pair(std::size_t k, const ContactBatch& batch, int j, ContactLoads& loads,
                   double& max_overlap_ratio);
  /// The contact pass on one thread: positions [0, nv) of the pairs (of visit_ when indexed),
  /// the law, and its loads summed straight onto the particles in pair order; the wall pairs'
  /// loads kept in wall_loads_.
  void serial_pass(std::size_t nv, bool indexed, double& max_overlap_ratio);
  /// One thread's share of the contact pass with several threads: positions [begin, end) of
  /// the pairs (of visit_ with kIndexed), the law, and its loads summed straight onto the
  /// share's particles in pair order, as one thread sums them; the pairs of a particle marked
  /// in split_mixed_ keep their loads in loads_ for its gather instead.
  template <bool kIndexed>
  void contact_pass(std::size_t begin, std::size_t end, double& max_overlap_ratio);
  /// Shares of the pairs for nt threads: particle ranges [split_first_[t], split_first_[t+1])
  /// with all their pairs as body 1, balanced by the time each share took (by pairs before it
  /// was timed); a particle is mixed when a pair of another share loads it (it is then gathered
  /// after the pass). Made at each new pair list, and when the shares timed since the last
  /// split differ by more than kShareImbalance.
  void split_pairs(std::size_t nt);
  /// Whether the shares timed over kShareCheckSteps steps or more are out of balance.
  bool shares_unbalanced() const;
  void update_servos();
  const PeriodicCell* cell_ptr() const { return periodic_ ? &cell_ : nullptr; }
  /// Clump loads from their members, the clumps' integration, and the members moved rigidly;
  /// adds the clumps' gravity work and damping to the ledger. False on a non-finite state.
  bool integrate_clumps();
  /// Takes particle i out for good (removed, fixed, at rest) and counts it; a free sphere's
  /// kinetic energy goes to the ledger's outflow and its mass to removed_mass (a member's are
  /// its clump's).
  void retire(std::size_t i);
  /// Freezes particle i for good (removed, fixed, at rest), without counting it anywhere.
  void freeze(std::size_t i);
  /// Whether an outlet keeps a particle at x.
  bool kept(const Eigen::Vector3d& x) const {
    return (x.array() >= keep_lo_.array()).all() && (x.array() <= keep_hi_.array()).all();
  }
  /// Drops the clumps marked gone (their members already removed), renumbering p_.clump.
  void drop_clumps(const std::vector<std::uint8_t>& gone);
  /// Elastic energy (normal, shear, rolling; J) stored in contact k.
  Eigen::Vector3d contact_elastic_energy(std::size_t k) const;
  void gather_clump_loads();
  /// Whether clump k is this process's to integrate (always, without a domain).
  bool clump_owned(std::size_t k) const;
  /// Wall loads, dissipation and work terms of this step, summed in pair / particle order.
  void accumulate_walls();
  /// Sorts the walls into the lists below (after a build, and after mutable_walls()).
  void classify_walls();
  /// Walls the per-step bookkeeping must look at, ascending: `moving_walls_` those with a
  /// velocity, an angular velocity or a servo, or that have moved since the last build (the
  /// others are exactly where the build saw them and their velocity is zero, so they add nothing
  /// to the work terms and need no new position); `servo_walls_` and `servo_bodies_` (the walls
  /// of each servo'd mesh body), `timed_walls_` (active, with a switch-off time), and
  /// `loaded_walls_` those accumulate_walls gave loads in the last step (the others' are zero).
  std::vector<std::uint32_t> moving_walls_, servo_walls_, timed_walls_, loaded_walls_;
  std::vector<std::vector<std::uint32_t>> servo_bodies_;
  std::vector<std::int32_t> servo_body_of_;  // per servo wall (parallel to servo_walls_): -1 or
                                             // an index into servo_bodies_
  bool walls_dirty_ = true;                  // classify_walls() due
  bool zero_all_walls_ = true;  // accumulate_walls() zeroes every wall (after a load, a change)

  SimulationConfig cfg_;
  ParticleState p_;
  Domain* domain_ = nullptr;
  std::vector<std::uint8_t> roles_;            // ParticleRole per particle; empty: all owned
  std::vector<std::uint8_t> absent_;           // roles_ == kAbsent (the neighbour list's mask)
  std::vector<Eigen::Vector3d> kept_ref_pos_;  // rebuild_local(…, keep_reference) scratch
  std::pair<std::vector<Eigen::Vector3d>, std::vector<Eigen::Vector3d>> kept_wall_ref_;
  std::vector<WallState> walls_;
  void remove_outflow();

  std::vector<ClumpBody> clumps_;
  bool periodic_ = false, planar_ = false;
  double disk_thickness_ = 0;  // m; > 0: true disks (set_disks)
  PeriodicCell cell_;
  HomogeneousField field_;  // this step's homogeneous terms of the integration
  std::optional<CellServo> cell_servo_;
  /// The cell's Love–Weber stress and, if asked for, its affine stiffness, in one pass.
  /// `over_domain`: this process's owned contacts, summed over the domain's processes.
  void cell_sums(Eigen::Matrix3d& stress, Eigen::Vector3d* stiffness,
                 bool over_domain = false) const;
  /// Kinetic energy of all bodies, or of those marked in `touching`.
  double kinetic_energy_of(const std::vector<std::uint8_t>* touching) const;
  /// A particle's kinetic energy, translation and rotation (in a cell: about the mean field).
  double particle_kinetic_energy(std::size_t i) const;
  Eigen::Matrix3d servo_base_gradient_ = Eigen::Matrix3d::Zero();  // its off-diagonal part
  bool outlet_ = false;
  Eigen::Vector3d keep_lo_ = Eigen::Vector3d::Zero(), keep_hi_ = Eigen::Vector3d::Zero();
  std::size_t removed_count_ = 0;
  double removed_mass_ = 0;
  std::vector<ClumpLoad> clump_loads_;
  std::vector<double> clump_damping_;  // per clump, this step (integrate_clumps)
  NeighborList nl_;
  std::vector<ContactHistory> hist_;  // parallel to nl_.pairs
  std::vector<double> facet_gap_;     // facet-wall pairs: the gap at the last build (m)
  // The contact pass visits pass_pairs_ (ascending) when some facet pairs are deferred: those
  // whose gap at the build exceeds the bound on how far it has closed since (the displacement
  // of its particle plus nl_.walls_moved), per particle sorted by gap (deferred_groups_); each
  // step visits those within the bound (admit_deferred). A skipped pair provably does not touch, so
  // skipping it changes no result (its history is marked not real at the build, as the pass
  // would have marked it).
  // pass_pairs_ / pass_wall_pairs_: the pairs never deferred; admitted_ (admitted_prev_): the
  // deferred ones visited in this (the last) step; visit_ / visit_wall_: the two merged.
  std::vector<std::uint32_t> pass_pairs_, pass_wall_pairs_, deferred_, admitted_, admitted_prev_;
  std::vector<std::uint32_t> visit_, visit_wall_;
  bool visit_valid_ = false;  // visit_ merged from this build's lists and admitted_prev_
  struct DeferredGroup {
    std::uint32_t particle, begin, end;  // its deferred pairs: deferred_[begin, end), by gap
  };
  std::vector<DeferredGroup> deferred_groups_;
  std::vector<std::uint8_t> is_deferred_;  // (scratch of attach_histories)
  bool facet_forces_ = false;
  std::vector<std::uint32_t> pair_facet_;  // closest facet of each wall pair (facet forces on)
  std::vector<ContactParams> params_;
  // What params_ were computed from (attach_histories reuses them only while these are
  // unchanged).
  bool params_key_valid_ = false;
  std::vector<double> params_radius_;
  std::array<double, 7> params_material_{};
  RollingRadius params_rolling_radius_ = RollingRadius::Min;
  std::vector<int> params_walls_;
  // With threads, the loads and dissipation of the pairs a mixed particle or a wall is in, at
  // their row load_slot_[k] (split_pairs; the others' go straight onto their particles).
  std::vector<ContactLoads> loads_;
  std::vector<std::uint32_t> load_slot_;
  std::vector<std::pair<std::uint32_t, ContactLoads>> wall_loads_;  // one thread: its walls'
  std::vector<std::uint8_t> active_;
  static constexpr std::size_t kChunk = 256, kSums = 5;
  // From this many particles the contact pass fetches body 2's state ahead (fill_batch): about
  // where their positions, motion and loads (128 B each) outgrow a core's 512 kB L2.
  static constexpr std::size_t kFarParticles = 8192;
  std::vector<double> chunk_sums_;  // per chunk: friction, rolling, gravity, external, damping
  std::vector<double> particle_dissipation_;  // friction and rolling of the step, per body 1
  std::vector<double> dissipation_;           // friction and rolling dissipation, rows as loads_
  // Pairs of each mixed particle (split_mixed_list_ order), in pair order (CSR), and the wall
  // pairs: loads are gathered per particle in parallel with the sums in the order of a serial
  // pass over the pairs.
  std::vector<std::uint32_t> mixed_start_, mixed_pairs_, wall_pairs_;
  // Threads' shares of the contact pass (split_pairs), for pairs_version_ and split_threads_.
  std::uint64_t pairs_version_ = 0, split_version_ = ~std::uint64_t{0};
  std::size_t split_threads_ = 0;
  std::vector<std::uint32_t> split_first_;  // particle ranges, nt + 1 bounds
  std::vector<std::size_t> split_pair_;     // their first pairs, nt + 1 bounds
  std::vector<double> share_seconds_;       // each share's pass time since the split
  std::size_t share_steps_ = 0;             // steps since the split
  static constexpr std::size_t kShareCheckSteps = 50;
  static constexpr double kShareImbalance = 1.05;
  std::vector<std::uint8_t> split_mixed_;  // per particle: loaded by another share's pairs
  std::vector<std::uint32_t> split_mixed_list_;
  std::int64_t step_ = 0;
  double time_ = 0;
  std::int64_t wall_id_base_ = 0;
  EnergyLedger ledger_;
  bool ledger_started_ = false;
  bool gathered_ = false;                // set_gathered
  std::vector<std::uint8_t> uncounted_;  // retired here by an outlet, not counted yet
  bool exact_wall_loads_ = false;        // set_exact_wall_loads
  // Per pair, whether it was a contact after the last step (ContactHistory::real, or a superset
  // of it): the last step's active_, or the flags attach_histories set from the histories it
  // placed (active_valid_), else read from hist_. The pass reads this compact array and touches
  // hist_[k] only for the pairs within reach or a contact to end, not every candidate's
  // history each step.
  std::vector<std::uint8_t> was_real_;
  bool active_valid_ = false;  // active_ ⊇ the contacts (set at a step's end and by
                               // attach_histories, cleared where contacts are received)
  // Particles taken out by the outlet since the build: their pairs are dropped from the pass
  // (pass_pairs_, pass_wall_pairs_, deferred_groups_) instead of the list being built anew
  // (the hopper took 300 of its 766 builds for them). dropped_ lists the dropped pairs of
  // pass_pairs_ not yet marked apart: they are at the next step's start, where a build would
  // have dropped them (so that what is read between steps is what it was with the build).
  bool pairs_dropped_ = false;
  std::vector<std::uint32_t> dropped_;
  /// The pass visits visit_ (some pairs deferred or dropped) rather than every pair.
  bool indexed_pass() const { return !deferred_.empty() || pairs_dropped_; }
  /// Drops the pairs of particles removed since the build from the pass (see pairs_dropped_).
  void drop_removed_pairs();
};

// (Simulation::owned_sums: a template, so that one process's sums stay plain loops.)
template <int kCount, class Particle, class Clump>
std::array<double, kCount> Simulation::owned_sums(Particle&& particle, Clump&& clump,
                                                  bool exact) const {
  constexpr auto m = static_cast<std::size_t>(kCount);
  const std::size_t n = p_.size(), nc = clumps_.size();
  std::array<double, kCount> sum{}, t{};
  auto add = [&](std::array<double, kCount>& to) {
    for (std::size_t j = 0; j < m; ++j) to[j] += t[j];
  };
  // (under a domain without roles, this process holds every state: before the first rebuild,
  // and process 0 while it holds the whole for output; it adds them alone, as one process)
  const bool split = domain_ && !roles_.empty() && !gathered_;
  if (!split) {
    for (std::size_t i = 0; i < n; ++i) {
      particle(i, t.data());
      add(sum);
    }
    for (std::size_t k = 0; k < nc; ++k) {
      clump(k, t.data());
      add(sum);
    }
    return sum;
  }
  if (!exact) {
    for (std::size_t i = 0; i < n; ++i)
      if (roles_[i] == kOwned) {
        particle(i, t.data());
        add(sum);
      }
    std::array<double, kCount> every{};  // (a clump without members: every process's alike)
    for (std::size_t k = 0; k < nc; ++k) {
      const bool none = clumps_[k].members.empty();
      if (!none && !clump_owned(k)) continue;
      clump(k, t.data());
      add(none ? every : sum);
    }
    std::vector<double> over(sum.begin(), sum.end());
    domain_->add_over_processes(over);
    for (std::size_t j = 0; j < m; ++j) sum[j] = over[j] + every[j];
    return sum;
  }
  // Term j of body b at v[j·(n + nc) + b], zero for the bodies of other processes (x + 0 = x:
  // the shared terms are the owners' to the bit, and the sums the same as above).
  const std::size_t nb = n + nc;
  std::vector<double> v(m * nb, 0.0);
  auto put = [&](std::size_t b) {
    for (std::size_t j = 0; j < m; ++j) v[j * nb + b] = t[j];
  };
  for (std::size_t i = 0; i < n; ++i)
    if (roles_[i] == kOwned) {
      particle(i, t.data());
      put(i);
    }
  for (std::size_t k = 0; k < nc; ++k)
    if (!clumps_[k].members.empty() && clump_owned(k)) {
      clump(k, t.data());
      put(n + k);
    }
  domain_->share(v);
  for (std::size_t k = 0; k < nc; ++k)  // (a clump without members is every process's alike)
    if (clumps_[k].members.empty()) {
      clump(k, t.data());
      put(n + k);
    }
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t b = 0; b < nb; ++b) sum[j] += v[j * nb + b];
  return sum;
}

}  // namespace gs::solver
