#include "stress_rotation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>

#include "errors.hpp"

namespace gs::solver {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

// What `fn` says of the whole assembly (under a domain decomposition: on the whole gathered on
// process 0, its verdict sent to every process), unless `surely_not` says no from each
// process's sums (Simulation::approximate_measures), which then needs no gather.
bool whole_says(Simulation& sim, const std::function<bool(const Simulation::Measures&)>& surely_not,
                const std::function<bool(const Simulation&)>& fn) {
  if (sim.decomposed() && surely_not(sim.approximate_measures(false))) return false;
  return sim.on_whole([&](Simulation& w) { return std::vector<double>{fn(w) ? 1.0 : 0.0}; })[0] !=
         0;
}

// Whether f_unb/f_av from each process's sums exceeds `tolerance` by more than their round-off
// (N·ε relative: the exact ratio exceeds it too; NaN, no contact, too).
bool surely_unbalanced(const Simulation::Measures& m, double tolerance) {
  return !(m.unbalanced_force <= (1 + 1e-5) * tolerance);
}

double whole_unbalanced_force(Simulation& sim) {
  return sim.on_whole([](Simulation& w) { return std::vector<double>{w.unbalanced_force()}; })[0];
}

// p, q = sqrt(3 J2), b and the angle (degrees) of σ1 from z in the x-z plane, folded to within
// 90° of `near`.
struct StressState {
  double p = 0, q = 0, b = 0, alpha_deg = 0;
};

StressState stress_state(const Eigen::Matrix3d& s, double near_deg) {
  const Eigen::Matrix3d sym = 0.5 * (s + s.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(sym);
  const Eigen::Vector3d v = e.eigenvalues();  // ascending: σ3, σ2, σ1
  StressState st;
  st.p = sym.trace() / 3.0;
  const Eigen::Matrix3d dev = sym - st.p * Eigen::Matrix3d::Identity();
  st.q = std::sqrt(1.5 * dev.squaredNorm());
  st.b = v[2] > v[0] ? (v[1] - v[0]) / (v[2] - v[0]) : 0.0;
  const Eigen::Vector3d major = e.eigenvectors().col(2);
  const double a = std::atan2(major.x(), major.z()) / kDeg;
  st.alpha_deg = near_deg + std::remainder(a - near_deg, 180.0);
  return st;
}

}  // namespace

StressRotation::StressRotation(StressRotationSpec spec, double test_friction_deg)
    : spec_(spec),
      P_(tangential_polyhedron(spec.sides, spec.radius_m)),
      test_friction_(test_friction_deg) {
  if (!(spec_.p_Pa > 0)) throw std::invalid_argument("stress rotation: p must be positive");
  if (!(spec_.eta > 0 && spec_.eta < 3))
    throw std::invalid_argument("stress rotation: eta must be in (0, 3)");
  if (!(spec_.b >= 0 && spec_.b <= 1))
    throw std::invalid_argument("stress rotation: b must be in [0, 1]");
  if (!(spec_.eta_step > 0) || !(spec_.alpha_step_deg > 0) || !(spec_.cycles > 0) ||
      !(spec_.tolerance > 0) || !(spec_.deposition_tolerance > 0) ||
      !(spec_.stress_tolerance > 0) || !(spec_.frame_every_deg > 0))
    throw std::invalid_argument("stress rotation: steps, cycles and tolerances must be positive");
  if (spec_.check_every < 1 || spec_.min_stage_steps < 0 || spec_.max_increment_steps < 1 ||
      spec_.max_stage_steps < 1)
    throw std::invalid_argument("stress rotation: step counts must be positive");
}

Eigen::Matrix3d StressRotation::target() const {
  if (stage_ == kIsotropic) return spec_.p_Pa * Eigen::Matrix3d::Identity();
  // Eq 17 with σ1 at α from z in the x-z plane: at (90° - α) from x.
  return principal_stress_state(spec_.p_Pa, eta_now_, spec_.b, (90.0 - alpha_deg_) * kDeg);
}

void StressRotation::enter(Simulation& sim, Stage s) {
  stage_ = s;
  stage_start_ = increment_start_ = sim.step_count();
}

void StressRotation::start(Simulation& sim) {
  if (sim.walls().size() < spec_.poly_first + P_.faces.size() ||
      spec_.box_first + 6 > sim.walls().size())
    throw std::invalid_argument("stress rotation: the scene lacks the box or polyhedron walls");
  // §2.4: deposition under gravity with the low friction and damping of a dynamic run.
  sim.set_gravity(spec_.deposition_gravity);
  sim.set_friction_deg(spec_.deposition_friction_deg);
  sim.set_damping(spec_.deposition_damping);
  for (std::size_t w = 0; w < 6; ++w) sim.set_wall_active(spec_.box_first + w, true);
  for (std::size_t f = 0; f < P_.faces.size(); ++f)
    sim.set_wall_active(spec_.poly_first + f, false);
  enter(sim, kDeposition);
}

std::size_t StressRotation::body_count(const Simulation& sim) const {
  std::size_t n = sim.clumps().size();
  const ParticleState& p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i) n += !p.removed[i] && p.clump[i] < 0;
  return n;
}

bool StressRotation::equilibrium(const Simulation& sim, double tolerance) const {
  return sim.unbalanced_force() <= tolerance;  // (NaN without contacts: not in equilibrium)
}

void StressRotation::carve(Simulation& sim) {
  sim.share_all_states();  // (under a domain: every process carves the same bed)
  const ParticleState& p = sim.particles();
  // The bed must cover the polyhedron (centred at the origin, end walls at z = ±R) with a
  // grain to spare, or its top would be the bed's loose surface.
  double top = -HUGE_VAL, dmax = 0;
  std::vector<std::size_t> alive;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.removed[i]) continue;
    alive.push_back(i);
    top = std::max(top, p.pos[i].z() + p.radius[i]);
    dmax = std::max(dmax, 2 * p.radius[i]);
  }
  if (!(top >= spec_.radius_m + dmax))
    throw ProgrammeError("stress rotation: the deposited bed (top at z = " + num(top) +
                         " m) does not cover the polyhedron (top at z = " + num(spec_.radius_m) +
                         " m) with a grain (" + num(dmax) +
                         " m) to spare: more particles, or a smaller radius_m");
  std::vector<Eigen::Vector3d> centre;
  std::vector<double> radius;
  std::vector<std::int64_t> clump;
  for (const std::size_t i : alive) {
    centre.push_back(p.pos[i]);
    radius.push_back(p.radius[i]);
    clump.push_back(p.clump[i]);
  }
  // §2.4: "particles with the centre of any constitutive sphere falling outside of the boundary
  // walls are deleted" (the centres, not the whole spheres: the walls start outward, below).
  const std::vector<std::size_t> keep =
      carve_polyhedron(P_, centre, std::vector<double>(centre.size(), 0.0), clump);
  std::vector<std::uint8_t> kept(alive.size(), 0);
  for (const std::size_t k : keep) kept[k] = 1;
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < alive.size(); ++k)
    if (!kept[k]) out.push_back(alive[k]);
  // §2.4: gravity removed, the friction and damping of the static stages.
  sim.set_gravity(Eigen::Vector3d::Zero());
  sim.set_friction_deg(test_friction_);
  sim.set_damping(spec_.damping);
  sim.remove_particles(out);
  for (std::size_t w = 0; w < 6; ++w) sim.set_wall_active(spec_.box_first + w, false);
  for (std::size_t f = 0; f < P_.faces.size(); ++f) sim.set_wall_active(spec_.poly_first + f, true);
  // What is left: particles, bodies, the solid volume and the mean radius (Eq 16's r̄).
  const ParticleState& q = sim.particles();
  double rsum = 0, density = sim.config().material.density;
  kept_particles_ = 0;
  solid_volume_ = 0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (q.removed[i]) continue;
    ++kept_particles_;
    rsum += q.radius[i];
    if (q.clump[i] < 0) solid_volume_ += q.mass[i] / density;
  }
  for (const auto& c : sim.clumps()) solid_volume_ += c.mass / density;
  kept_bodies_ = static_cast<std::int64_t>(sim.clumps().size());
  for (std::size_t i = 0; i < q.size(); ++i)
    if (!q.removed[i] && q.clump[i] < 0) ++kept_bodies_;
  if (kept_particles_ == 0)
    throw ProgrammeError(
        "stress rotation: no clump has all its member centres inside the polyhedron");
  servo_E_ = spec_.servo.E;
  if (!(servo_E_ > 0)) {
    const auto& m = sim.config().material;
    const double rbar = rsum / static_cast<double>(kept_particles_);
    const double kn = spec_.normal_stiffness_N_m > 0 ? spec_.normal_stiffness_N_m
                      : m.normal_stiffness_N_m > 0   ? m.normal_stiffness_N_m
                                                     : m.young_ec * rbar;
    double circum = 0;
    for (const auto& v : P_.vertices) circum = std::max(circum, v.norm());
    servo_E_ = servo_modulus(kn, rbar, circum, spec_.relaxation);  // Eq 16
  }
}

void StressRotation::control(Simulation& sim) {
  const std::int64_t s = sim.step_count();
  // The quasi-static stages' time step, set before every step after the carving (it is not in
  // the checkpoints: a resumed run sets it again before its first step).
  if (stage_ >= kReequilibration && spec_.quasi_static_dt_s > 0 &&
      sim.config().dt != spec_.quasi_static_dt_s)
    sim.set_dt(spec_.quasi_static_dt_s);
  if (stage_ == kDeposition) {
    if (s - stage_start_ >= spec_.max_stage_steps)
      throw ProgrammeError("stress rotation: the deposition did not settle (f_unb/f_av = " +
                           num(whole_unbalanced_force(sim)) + " after " +
                           std::to_string(s - stage_start_) + " steps, tolerance " +
                           num(spec_.deposition_tolerance) + ")");
    // Settled: f_unb/f_av within the tolerance, and a bed (at least as many contacts as bodies:
    // while the cloud falls, a few collisions make f_av large and the ratio small).
    if (s - stage_start_ >= spec_.min_stage_steps && s % spec_.check_every == 0 &&
        whole_says(
            sim,
            [&](const Simulation::Measures& m) {
              return m.contacts < body_count(sim) ||
                     surely_unbalanced(m, spec_.deposition_tolerance);
            },
            [&](const Simulation& w) {
              return w.contact_count() >= body_count(w) &&
                     equilibrium(w, spec_.deposition_tolerance);
            })) {
      carve(sim);
      enter(sim, kReequilibration);
      if (spec_.quasi_static_dt_s > 0) sim.set_dt(spec_.quasi_static_dt_s);
    }
    return;
  }
  if (stage_ == kReequilibration) {  // the walls fixed (§2.4)
    if (s - stage_start_ >= spec_.max_stage_steps)
      throw ProgrammeError("stress rotation: the carved specimen did not settle (f_unb/f_av = " +
                           num(whole_unbalanced_force(sim)) + " after " +
                           std::to_string(s - stage_start_) + " steps)");
    // In equilibrium when f_unb/f_av is within the tolerance, or when nothing touches any more
    // (gravity off, the bed's contacts unloaded and parted: no force to balance).
    if (s - stage_start_ >= spec_.min_stage_steps && s % spec_.check_every == 0 &&
        whole_says(
            sim,
            [&](const Simulation::Measures& m) {
              return m.contacts > 0 && surely_unbalanced(m, spec_.tolerance);
            },
            [&](const Simulation& w) {
              return equilibrium(w, spec_.tolerance) || w.contact_count() == 0;
            }))
      enter(sim, kIsotropic);
    return;
  }
  if (stage_ == kDone) return;
  PolyhedronServo servo = spec_.servo;
  servo.E = servo_E_;
  const Eigen::Matrix3d t = target();
  servo_step(sim, spec_.poly_first, P_, t, servo, sim.config().dt, &sigma_);
  if (s % spec_.check_every != 0) return;
  const double error = (sigma_ - t).norm() / spec_.p_Pa;
  if (!(error <= spec_.stress_tolerance &&
        whole_says(
            sim,
            [&](const Simulation::Measures& m) { return surely_unbalanced(m, spec_.tolerance); },
            [&](const Simulation& w) { return equilibrium(w, spec_.tolerance); }))) {
    const std::int64_t limit =
        stage_ == kIsotropic ? spec_.max_stage_steps : spec_.max_increment_steps;
    if (s - increment_start_ >= limit) {
      const StressState st = stress_state(sigma_, alpha_deg_);
      const std::string where =
          stage_ == kIsotropic ? "p = " + num(spec_.p_Pa) + " Pa isotropic"
          : stage_ == kShear   ? "eta = " + num(eta_now_) + " on the way to eta = " + num(spec_.eta)
                               : "alpha = " + num(alpha_deg_) + " deg at eta = " + num(eta_now_);
      throw ProgrammeError("stress rotation: the servo did not reach " + where + " within " +
                           (stage_ == kIsotropic ? "max_stage_steps (" : "max_increment_steps (") +
                           std::to_string(limit) + "); stopped at p = " + num(st.p) +
                           " Pa, eta = " + num(st.p > 0 ? st.q / st.p : 0.0) +
                           ", b = " + num(st.b) + ", |sigma - target|/p = " + num(error) +
                           ", f_unb/f_av = " + num(whole_unbalanced_force(sim)));
    }
    return;
  }
  increment_start_ = s;
  if (stage_ == kIsotropic) {
    void_ratio_isotropic_ =
        polyhedron_current_volume(sim, spec_.poly_first, P_) / solid_volume_ - 1.0;
    enter(sim, kShear);
    eta_now_ = std::min(spec_.eta_step, spec_.eta);
  } else if (stage_ == kShear) {
    if (eta_now_ >= spec_.eta) {
      enter(sim, kRotation);
      alpha_deg_ = 0;
    } else {
      eta_now_ = std::min(eta_now_ + spec_.eta_step, spec_.eta);
    }
  } else {  // rotation: the next increment Δα once the last one is in equilibrium
    const double total = 180.0 * spec_.cycles;
    if (alpha_deg_ >= total) {
      stage_ = kDone;
    } else {
      alpha_deg_ = std::min(alpha_deg_ + spec_.alpha_step_deg, total);
    }
  }
}

double StressRotation::progress(const Simulation&) const {
  if (stage_ >= kDone) return 1.0;
  if (stage_ < kShear) return 0.05 * static_cast<double>(stage_);
  if (stage_ == kShear) return 0.15 + 0.05 * eta_now_ / spec_.eta;
  return 0.2 + 0.8 * alpha_deg_ / (180.0 * spec_.cycles);
}

std::string StressRotation::curve_header() const {
  return "step,time_s,stage,eta_target,alpha_deg,p_Pa,q_Pa,eta,b,alpha_sigma_deg,sxx_Pa,syy_Pa,"
         "szz_Pa,sxy_Pa,sxz_Pa,syz_Pa,exx,eyy,ezz,exy,exz,eyz,eps_v,void_ratio,"
         "unbalanced_force,particles";
}

std::string StressRotation::curve_row(const Simulation& sim) const {
  const bool walls_on = stage_ >= kReequilibration;
  const Eigen::Matrix3d sigma =
      walls_on ? polyhedron_stress(sim, spec_.poly_first, P_) : Eigen::Matrix3d::Zero().eval();
  const Eigen::Matrix3d F = polyhedron_deformation_gradient(sim, spec_.poly_first, P_);
  // Eq 2: the Biot strain without rigid rotation, ε = 1 - F (compression positive); Eq 11:
  // εv = 1 - det F.
  const Eigen::Matrix3d eps = Eigen::Matrix3d::Identity() - 0.5 * (F + F.transpose());
  const StressState st = stress_state(sigma, alpha_deg_);
  const double e = walls_on && solid_volume_ > 0
                       ? polyhedron_current_volume(sim, spec_.poly_first, P_) / solid_volume_ - 1
                       : NAN;
  std::int64_t alive = 0;
  for (const auto r : sim.particles().removed) alive += r == 0;
  std::string row = std::to_string(sim.step_count()) + "," + num(sim.time()) + "," +
                    std::to_string(stage_) + "," + num(eta_now_) + "," + num(alpha_deg_) + "," +
                    num(st.p) + "," + num(st.q) + "," + num(st.p > 0 ? st.q / st.p : 0.0) + "," +
                    num(st.b) + "," + num(st.alpha_deg);
  for (const auto& [i, j] : {std::pair{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}})
    row += "," + num(sigma(i, j));
  for (const auto& [i, j] : {std::pair{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}})
    row += "," + num(eps(i, j));
  row += "," + num(1.0 - F.determinant()) + "," + num(e) + "," + num(sim.unbalanced_force()) + "," +
         std::to_string(alive);
  return row;
}

std::int64_t StressRotation::frame_index(const Simulation&) const {
  // A frame at each stage's start (the carved specimen, the isotropic state, the state sheared
  // to η: the start of the rotation) and every frame_every_deg of α.
  if (stage_ < kRotation) return stage_;
  return kRotation + static_cast<std::int64_t>(std::floor(alpha_deg_ / spec_.frame_every_deg));
}

std::string StressRotation::summary(const Simulation& sim) const {
  std::string out = "stress rotation (seed 003): n = " + std::to_string(spec_.sides) +
                    ", R = " + num(spec_.radius_m) + " m, " + std::to_string(kept_bodies_) +
                    " bodies (" + std::to_string(kept_particles_) + " spheres) carved\n";
  if (void_ratio_isotropic_ >= 0)
    out += "  void ratio at p = " + num(spec_.p_Pa) +
           " Pa isotropic: " + num(void_ratio_isotropic_) + "\n";
  out += "  eta reached " + num(eta_now_) + " of " + num(spec_.eta) + ", alpha " + num(alpha_deg_) +
         " deg of " + num(180.0 * spec_.cycles) + " (" + num(alpha_deg_ / 180.0) + " cycles)\n";
  if (stage_ >= kIsotropic) {
    const Eigen::Matrix3d F = polyhedron_deformation_gradient(sim, spec_.poly_first, P_);
    out += "  eps_v = 1 - det F = " + num(1.0 - F.determinant()) + "\n";
  }
  return out;
}

std::vector<std::pair<std::string, double>> StressRotation::results(const Simulation& sim) const {
  std::vector<std::pair<std::string, double>> r = {
      {"bodies", static_cast<double>(kept_bodies_)},
      {"spheres", static_cast<double>(kept_particles_)},
      {"void_ratio_isotropic", void_ratio_isotropic_},
      {"eta", eta_now_},
      {"alpha_deg", alpha_deg_},
      {"cycles", alpha_deg_ / 180.0}};
  if (stage_ >= kIsotropic) {
    const Eigen::Matrix3d F = polyhedron_deformation_gradient(sim, spec_.poly_first, P_);
    r.emplace_back("eps_v", 1.0 - F.determinant());
    r.emplace_back("void_ratio",
                   polyhedron_current_volume(sim, spec_.poly_first, P_) / solid_volume_ - 1.0);
  }
  return r;
}

std::string StressRotation::save_state() const {
  ProgrammeState st;
  st.set("stage", stage_);
  st.set("stage_start", stage_start_);
  st.set("increment_start", increment_start_);
  st.set("eta_now", eta_now_);
  st.set("alpha_deg", alpha_deg_);
  st.set("servo_E", servo_E_);
  st.set("kept_particles", kept_particles_);
  st.set("kept_bodies", kept_bodies_);
  st.set("solid_volume", solid_volume_);
  st.set("void_ratio_isotropic", void_ratio_isotropic_);
  return st.text();
}

void StressRotation::load_state(const std::string& state) {
  const ProgrammeState st(state);
  stage_ = st.integer("stage");
  stage_start_ = st.integer("stage_start");
  increment_start_ = st.integer("increment_start");
  eta_now_ = st.number("eta_now");
  alpha_deg_ = st.number("alpha_deg");
  servo_E_ = st.number("servo_E");
  kept_particles_ = st.integer("kept_particles");
  kept_bodies_ = st.integer("kept_bodies");
  solid_volume_ = st.number("solid_volume");
  void_ratio_isotropic_ = st.number("void_ratio_isotropic");
}

}  // namespace gs::solver
