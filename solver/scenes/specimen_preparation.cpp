#include "specimen_preparation.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "sphere_box_volume.hpp"

namespace gs::solver {

SpecimenPreparation::SpecimenPreparation(PreparationSpec spec, SpecimenGauge gauge,
                                         double test_friction_deg)
    : spec_(std::move(spec)), gauge_(std::move(gauge)), test_friction_(test_friction_deg) {
  if (spec_.pressure_Pa < 0) throw std::invalid_argument("preparation pressure is negative");
  if (!(spec_.friction_factor > 0 && spec_.friction_factor < 1))
    throw std::invalid_argument("friction_factor must be in (0, 1)");
  if (spec_.pressure_Pa == 0 && !spec_.deposition)
    throw std::invalid_argument("preparation needs a pressure or deposition");
  if (gauge_.cell_axes > 0 && (spec_.deposition || !(spec_.pressure_Pa > 0)))
    throw std::invalid_argument(
        "a periodic cell is prepared by compaction (a pressure, no deposition)");
  if (gauge_.cell_axes > 0 && spec_.servo_gain > 1)
    throw std::invalid_argument("servo_gain of a cell is a fraction in (0, 1]");
}

double box_void_ratio(const ParticleState& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                      double clump_solid_factor) {
  double solid = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p.removed.empty() && p.removed[i]) continue;
    const Eigen::Vector3d& c = p.pos[i];
    const double r = p.radius[i];
    const double share = !p.clump.empty() && p.clump[i] >= 0 ? clump_solid_factor : 1.0;
    if (((c.array() - r) >= lo.array()).all() && ((c.array() + r) <= hi.array()).all())
      solid += share * 4.0 / 3.0 * M_PI * r * r * r;  // wholly inside
    else if (((c.array() + r) > lo.array()).all() && ((c.array() - r) < hi.array()).all())
      solid += share * sphere_box_volume(c, r, lo, hi);
  }
  return (hi - lo).prod() / solid - 1;
}

SpecimenGauge cell_gauge(int axes, double max_rate_1_s) {
  if (axes != 2 && axes != 3) throw std::invalid_argument("a cell gauge servoes 2 or 3 axes");
  if (!(max_rate_1_s > 0)) throw std::invalid_argument("cell servo rate limit must be positive");
  SpecimenGauge g;
  g.cell_axes = axes;
  g.cell_max_rate_1_s = max_rate_1_s;
  return g;
}

double SpecimenPreparation::void_ratio(const Simulation& sim) const {
  if (gauge_.cell_axes > 0) return cell_void_ratio(sim);
  const auto [lo, hi] = gauge_.box(sim);
  return box_void_ratio(sim.particles(), lo, hi, gauge_.clump_solid_factor);
}

double SpecimenPreparation::core_void_ratio(const Simulation& sim) const {
  if (gauge_.cell_axes > 0) return cell_void_ratio(sim);  // (no walls: the core is the cell)
  auto [lo, hi] = gauge_.box(sim);
  lo.array() += spec_.core_inset_m;
  hi.array() -= spec_.core_inset_m;
  if (((hi - lo).array() <= 0).any()) return std::numeric_limits<double>::quiet_NaN();
  return box_void_ratio(sim.particles(), lo, hi, gauge_.clump_solid_factor);
}

void SpecimenPreparation::start(Simulation& sim) {
  first_step_ = stage_start_ = sim.step_count();
  friction_ = spec_.friction_start_deg >= 0 ? spec_.friction_start_deg : test_friction_;
  sim.set_friction_deg(friction_);
  lowest_friction_ = friction_;
  gravity_saved_ = sim.config().gravity;
  if (spec_.deposition) {
    stage_ = kDeposition;
    sim.set_gravity(spec_.deposition_gravity);
  } else {
    stage_ = kCompaction;
  }
  if (gauge_.cell_axes > 0) {  // the engine's stiffness-scaled servo, for every stage
    CellServo sv;
    for (int i = 0; i < gauge_.cell_axes; ++i) {
      sv.stress[static_cast<std::size_t>(i)] = true;
      sv.target[i] = -spec_.pressure_Pa;  // (the cell's stress is compression negative)
    }
    sv.stiffness_fraction = spec_.servo_gain;
    sv.max_rate = gauge_.cell_max_rate_1_s;
    sim.set_cell_servo(sv);
  }
}

Eigen::VectorXd SpecimenPreparation::servo_stresses(const Simulation& sim) const {
  if (gauge_.cell_axes > 0) {
    const Eigen::Matrix3d s = sim.cell_stress();
    return -s.diagonal().head(gauge_.cell_axes);
  }
  Eigen::VectorXd out(static_cast<Eigen::Index>(gauge_.servo_walls.size()));
  for (std::size_t k = 0; k < gauge_.servo_walls.size(); ++k) {
    const auto w = gauge_.servo_walls[k];
    out[static_cast<Eigen::Index>(k)] =
        wall_stress(sim, w, gauge_.inward(sim, w), gauge_.area_m2(sim, w));
  }
  return out;
}

bool SpecimenPreparation::equilibrium(Simulation& sim, bool with_stress) const {
  if (with_stress) {
    const Eigen::VectorXd s = servo_stresses(sim);
    for (const double v : s)
      if (!(std::abs(v - spec_.pressure_Pa) <= spec_.stress_tolerance * spec_.pressure_Pa))
        return false;
  }
  const double unb = sim.unbalanced_force();
  if (!(unb <= spec_.unbalanced_force)) return false;
  const double el = elastic_energy(sim);
  // In a cell the rattlers keep their energy (nothing damps a free body), so only the bodies in
  // contact count there; with walls the whole kinetic energy, as it always was.
  const double ek = gauge_.cell_axes > 0 ? sim.kinetic_energy_in_contact() : sim.kinetic_energy();
  return ek <= spec_.kinetic_ratio * el;
}

bool SpecimenPreparation::surely_unsettled(const Simulation& sim, bool with_stress) const {
  constexpr double kMargin = 1 + 1e-5;       // (the sums' round-off: N·ε relative)
  if (with_stress && gauge_.cell_axes == 0)  // (the walls' loads: the whole's, exactly)
    for (const double v : servo_stresses(sim))
      if (!(std::abs(v - spec_.pressure_Pa) <= spec_.stress_tolerance * spec_.pressure_Pa))
        return true;
  const Simulation::Measures m = sim.approximate_measures(gauge_.cell_axes > 0);
  if (!(m.unbalanced_force <= kMargin * spec_.unbalanced_force)) return true;  // (NaN too)
  return m.kinetic_J > kMargin * spec_.kinetic_ratio * m.elastic_J;
}

void SpecimenPreparation::next_stage(Simulation& sim, double core_void_ratio) {
  stage_start_ = sim.step_count();
  if (stage_ == kDeposition) {  // gravity stays on until the preparation ends
    stage_ = spec_.pressure_Pa > 0 ? kCompaction : kSettling;
    if (stage_ == kSettling) {
      friction_ = test_friction_;
      sim.set_friction_deg(friction_);
    }
    return;
  }
  if (stage_ == kCompaction || stage_ == kLowering) {
    const bool dense_enough =
        spec_.void_ratio_target < 0 || core_void_ratio <= spec_.void_ratio_target;
    if (!dense_enough && friction_ > 0) {
      stage_ = kLowering;
      friction_ *= spec_.friction_factor;
      if (friction_ < spec_.friction_floor_deg) friction_ = 0;
      lowest_friction_ = friction_;
      sim.set_friction_deg(friction_);
      return;
    }
    stage_ = kSettling;
    friction_ = test_friction_;
    sim.set_friction_deg(friction_);
    return;
  }
  stage_ = kDone;
  sim.set_gravity(gravity_saved_);  // the scene's own (deposition changed it)
}

void SpecimenPreparation::control(Simulation& sim) {
  if (stage_ == kDone) return;
  const bool servo = stage_ != kDeposition && spec_.pressure_Pa > 0;
  for (const auto w : gauge_.servo_walls) {
    const Eigen::Vector3d in = gauge_.inward(sim, w);
    if (!servo) {
      sim.set_wall_velocity(w, Eigen::Vector3d::Zero());
      continue;
    }
    const double a = gauge_.area_m2(sim, w);
    const double v = servo_speed(sim, w, wall_stress(sim, w, in, a), spec_.pressure_Pa, a,
                                 spec_.servo_gain, spec_.max_wall_speed_m_s);
    sim.set_wall_velocity(w, v * in);
  }
  const std::int64_t s = sim.step_count();
  if (spec_.max_steps > 0 && s - first_step_ >= spec_.max_steps) {
    stage_ = kDone;
    sim.set_gravity(gravity_saved_);
    return;
  }
  if (s - stage_start_ < spec_.stage_steps || (s - stage_start_) % spec_.check_every != 0) return;
  // (under a domain decomposition the whole assembly is gathered for the check, unless each
  // process's sums already tell; its verdict, and the core's void ratio where a compaction
  // stage ends, go to every process)
  if (sim.decomposed() && surely_unsettled(sim, servo)) return;
  const bool compacting = stage_ == kCompaction || stage_ == kLowering;
  const std::vector<double> v = sim.on_whole([&](Simulation& whole) -> std::vector<double> {
    if (!equilibrium(whole, servo)) return {0.0, 0.0};
    return {1.0, compacting && spec_.void_ratio_target >= 0 ? core_void_ratio(whole) : 0.0};
  });
  if (v[0] != 0) next_stage(sim, v[1]);
}

double SpecimenPreparation::progress(const Simulation& sim) const {
  if (spec_.max_steps > 0)
    return std::min(1.0, static_cast<double>(sim.step_count() - first_step_) /
                             static_cast<double>(spec_.max_steps));
  return static_cast<double>(stage_) / static_cast<double>(kDone);
}

std::string SpecimenPreparation::curve_header() const {
  std::string h =
      "step,time_s,stage,friction_deg,void_ratio,core_void_ratio,unbalanced_force,kinetic_J";
  for (int i = 0; i < gauge_.cell_axes; ++i)
    h += std::string(",cell_stress_") + "xyz"[i] + "xyz"[i] + "_Pa";
  for (std::size_t k = 0; k < gauge_.servo_walls.size(); ++k)
    h += ",wall" + std::to_string(gauge_.servo_walls[k]) + "_stress_Pa";
  return h;
}

std::string SpecimenPreparation::curve_row(const Simulation& sim) const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%lld,%.9g,%lld,%.9g,%.9g,%.9g,%.6g,%.6g",
                static_cast<long long>(sim.step_count()), sim.time(),
                static_cast<long long>(stage_), friction_, void_ratio(sim), core_void_ratio(sim),
                sim.unbalanced_force(), sim.kinetic_energy());
  std::string row = buf;
  for (const double v : servo_stresses(sim)) {
    std::snprintf(buf, sizeof buf, ",%.9g", v);
    row += buf;
  }
  return row;
}

std::string SpecimenPreparation::summary(const Simulation& sim) const {
  char buf[256];
  if (gauge_.cell_axes > 0) {
    std::snprintf(buf, sizeof buf,
                  "preparation: %lld steps, void ratio %.4f of the cell (target %.4f); friction "
                  "lowered to %.3g deg",
                  static_cast<long long>(sim.step_count() - first_step_), void_ratio(sim),
                  spec_.void_ratio_target, lowest_friction_);
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "preparation: %lld steps, void ratio %.4f in the core (%.4g m from the walls; "
                "target %.4f), %.4f over the whole box; friction lowered to %.3g deg",
                static_cast<long long>(sim.step_count() - first_step_), core_void_ratio(sim),
                spec_.core_inset_m, spec_.void_ratio_target, void_ratio(sim), lowest_friction_);
  return buf;
}

std::string SpecimenPreparation::save_state() const {
  ProgrammeState st;
  st.set("stage", stage_);
  st.set("stage_start", stage_start_);
  st.set("first_step", first_step_);
  st.set("friction", friction_);
  st.set("lowest_friction", lowest_friction_);
  st.set("gx", gravity_saved_.x());
  st.set("gy", gravity_saved_.y());
  st.set("gz", gravity_saved_.z());
  return st.text();
}

void SpecimenPreparation::load_state(const std::string& state) {
  const ProgrammeState st(state);
  stage_ = st.integer("stage");
  stage_start_ = st.integer("stage_start");
  first_step_ = st.integer("first_step");
  friction_ = st.number("friction");
  lowest_friction_ = st.number("lowest_friction");
  gravity_saved_ = {st.number("gx"), st.number("gy"), st.number("gz")};
}

}  // namespace gs::solver
