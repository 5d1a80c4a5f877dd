#include "simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <limits>

#include <Eigen/QR>

#include "atomic_file.hpp"
#include "contact_geometry.hpp"
#include "errors.hpp"
#include "hertz_mindlin_law.hpp"
#include "lane_gather.hpp"
#include "newton_integrator.hpp"
#include "thread_team.hpp"

namespace gs::solver {

double pwave_timestep(const std::vector<double>& radii, double density, double young) {
  double dt = std::numeric_limits<double>::infinity();
  for (double r : radii) dt = std::min(dt, r / std::sqrt(young / density));
  return dt;
}

double material_timestep(const std::vector<double>& radii, const Material& m) {
  if (!(m.normal_stiffness_N_m > 0)) return pwave_timestep(radii, m.density, m.young_ec);
  double dt = std::numeric_limits<double>::infinity();
  for (double r : radii)
    dt = std::min(dt, std::sqrt(m.density * 4.0 / 3.0 * M_PI * r * r * r / m.normal_stiffness_N_m));
  return dt;
}

Simulation::Simulation(SimulationConfig config, const std::vector<Particle>& particles,
                       std::vector<WallSpec> walls)
    : cfg_(std::move(config)) {
  if (!(cfg_.dt > 0)) throw std::invalid_argument("time step must be positive");
  if (!(cfg_.material.density > 0) ||
      !(cfg_.material.young_ec > 0 || cfg_.material.normal_stiffness_N_m > 0))
    throw std::invalid_argument("material density and Ec (or a constant Kn) must be positive");
  if (cfg_.material.normal_stiffness_N_m > 0 && cfg_.law != ContactLaw::CohesiveFrictional)
    throw std::invalid_argument("a constant Kn needs the linear (CohFrictMat) law");
  const std::size_t n = particles.size();
  if (n >= kWallBase) throw std::invalid_argument("too many particles");
  p_.id.resize(n);
  p_.radius.resize(n);
  p_.mass.resize(n);
  p_.inertia.resize(n);
  p_.pos.resize(n);
  p_.vel.resize(n);
  p_.angvel.resize(n);
  p_.rot.resize(n);
  p_.force.assign(n, Eigen::Vector3d::Zero());
  p_.torque.assign(n, Eigen::Vector3d::Zero());
  p_.ori.resize(n);
  p_.fixed.assign(n, 0);
  p_.rot_blocked.assign(n, 0);
  p_.external_force.assign(n, Eigen::Vector3d::Zero());
  p_.clump.assign(n, -1);
  p_.removed.assign(n, 0);
  p_.material.assign(n, 0);
  const std::size_t n_materials = 1 + cfg_.more_materials.size();
  if (n_materials > 256) throw std::invalid_argument("more than 256 materials");
  for (const auto& m : cfg_.more_materials)
    if (!(m.density > 0) || !(m.young_ec > 0))
      throw std::invalid_argument("material density and Ec must be positive");
  for (const auto* t : {&cfg_.pair_restitution, &cfg_.pair_friction_deg})
    if (!t->empty() && t->size() != n_materials * n_materials)
      throw std::invalid_argument("material-pair table of the wrong size");
  if (n_materials > 1 && cfg_.law != ContactLaw::HertzMindlin)
    throw std::invalid_argument("several materials need the Hertz-Mindlin law");
  std::int64_t max_id = -1;
  double rmin = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& q = particles[i];
    if (!(q.radius > 0)) throw std::invalid_argument("particle radius must be positive");
    p_.id[i] = q.id;
    p_.radius[i] = q.radius;
    // As YADE's utils.sphere: V = 4/3·π·r³, m = V·ρ, I = (2/5·V·r²)·ρ.
    if (q.material_id < 0 || static_cast<std::size_t>(q.material_id) >= n_materials)
      throw std::invalid_argument("particle " + std::to_string(q.id) + ": no material " +
                                  std::to_string(q.material_id));
    p_.material[i] = static_cast<std::uint8_t>(q.material_id);
    const double density = material_at(q.material_id).density;
    const double volume = (4.0 / 3.0) * M_PI * std::pow(q.radius, 3);
    p_.mass[i] = volume * density;
    p_.inertia[i] = (2.0 / 5.0) * volume * std::pow(q.radius, 2) * density;
    p_.pos[i] = q.position;
    p_.vel[i] = q.velocity;
    p_.angvel[i] = q.angular_velocity;
    p_.rot[i] = q.rotation;
    p_.ori[i] = q.orientation;
    max_id = std::max(max_id, q.id);
    rmin = std::min(rmin, q.radius);
  }
  wall_id_base_ = max_id + 1;
  for (auto& spec : walls) {
    if (spec.material < 0 || static_cast<std::size_t>(spec.material) >= n_materials)
      throw std::invalid_argument("wall '" + spec.name + "': no material " +
                                  std::to_string(spec.material));
    if (spec.shape == WallShape::Facets && spec.facets.empty())
      throw std::invalid_argument("facet wall '" + spec.name + "' has no triangles");
    WallState w;
    w.spec = spec;
    w.pos = spec.center;
    w.normal = spec.shape == WallShape::Plane    ? Eigen::Vector3d(spec.normal.normalized())
               : spec.shape == WallShape::Facets ? spec.facets[0].normal.eigen()
                                                 : spec.normal;
    w.vel = spec.velocity;
    w.active = spec.active;
    if (spec.shape == WallShape::Facets) {
      w.facets = spec.facets;
      w.rot_center = spec.rotation_center;
      for (const auto& f : spec.facets)
        for (const auto& v : f.vertex) w.reach = std::max(w.reach, (f.offset + v).eigen().norm());
    }
    walls_.push_back(w);
  }
  nl_.skin = cfg_.skin > 0 ? cfg_.skin : (n > 0 ? 0.5 * rmin : 1e-3);
  nl_.threads = std::max(1, cfg_.threads);
}

void Simulation::set_threads(int threads) {
  cfg_.threads = std::max(1, threads);
  nl_.threads = cfg_.threads;
}

void Simulation::set_clumps(std::vector<ClumpBody> clumps) {
  if (step_ != 0) throw std::logic_error("clumps must be set before the first step");
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.clump[i] >= 0) throw std::logic_error("clumps are already set");
  for (std::size_t c = 0; c < clumps.size(); ++c) {
    const ClumpBody& b = clumps[c];
    if (b.members.empty() || b.local_pos.size() != b.members.size() ||
        b.local_ori.size() != b.members.size())
      throw std::invalid_argument("clump " + std::to_string(c) + " has no members");
    if (!(b.mass > 0) || !(b.inertia.minCoeff() > 0))
      throw std::invalid_argument("clump " + std::to_string(c) +
                                  " needs a positive mass and inertia");
    for (const std::uint32_t i : b.members) {
      if (i >= p_.size())
        throw std::invalid_argument("clump " + std::to_string(c) + ": no particle " +
                                    std::to_string(i));
      if (p_.clump[i] >= 0)
        throw std::invalid_argument("particle " + std::to_string(i) + " is in two clumps");
      p_.clump[i] = static_cast<std::int32_t>(c);
      p_.fixed[i] = 1;  // moved by its clump, not integrated as a sphere
    }
  }
  clumps_ = std::move(clumps);
  invalidate_neighbors();
}

bool Simulation::clump_owned(std::size_t k) const {
  // (a domain gives a clump's members its owner: the process of its centre of mass)
  return roles_.empty() || clumps_[k].members.empty() || roles_[clumps_[k].members[0]] == kOwned;
}

void Simulation::gather_clump_loads() {
  clump_loads_.resize(clumps_.size());
  for (std::size_t k = 0; k < clumps_.size(); ++k) {
    if (!clump_owned(k)) continue;  // (its members' loads are complete at its owner only)
    const ClumpBody& c = clumps_[k];
    // YADE's Clump::addForceTorqueFromMembers, in member order, with the member positions the
    // contact loads were computed at.
    ClumpLoad load;
    for (const std::uint32_t i : c.members) {
      const Eigen::Vector3d& f = p_.force[i];
      load.force += f;
      load.torque += p_.torque[i] + (p_.pos[i] - c.pos).cross(f);
    }
    clump_loads_[k] = load;
  }
}

bool Simulation::integrate_clumps() {
  const double dt = cfg_.dt;
  bool finite = true;
  double gravity_power = 0, damping = 0;
  for (std::size_t k = 0; k < clumps_.size(); ++k)
    if (clump_owned(k)) gravity_power += clumps_[k].mass * cfg_.gravity.dot(clumps_[k].vel);
  clump_damping_.resize(clumps_.size());
  // Under a domain, each run of owned clumps (the integration is lane by lane: the same bits
  // in runs as in one batch).
  for (std::size_t k0 = 0; k0 < clumps_.size();) {
    if (!clump_owned(k0)) {
      ++k0;
      continue;
    }
    std::size_t k1 = k0 + 1;
    while (k1 < clumps_.size() && clump_owned(k1)) ++k1;
    integrate_clump_bodies(clumps_.data() + k0, clump_loads_.data() + k0, k1 - k0, cfg_.gravity,
                           cfg_.damping, dt, clump_damping_.data() + k0);
    k0 = k1;
  }
  for (std::size_t k = 0; k < clumps_.size(); ++k) {
    if (!clump_owned(k)) continue;  // (its members are ghosts here, or absent)
    const ClumpBody& c = clumps_[k];
    damping += clump_damping_[k];
    finite = finite && c.pos.allFinite() && c.vel.allFinite() && c.angmom.allFinite();
    // YADE's Clump::moveMembers.
    for (std::size_t m = 0; m < c.members.size(); ++m) {
      const std::uint32_t i = c.members[m];
      place_member(c, m, p_.pos[i], p_.ori[i], p_.vel[i]);
      p_.angvel[i] = c.angvel;
    }
  }
  ledger_.gravity_work += gravity_power * dt;
  ledger_.damping_dissipation += damping;
  return finite;
}

void Simulation::set_outlet(const Eigen::Vector3d& keep_lo, const Eigen::Vector3d& keep_hi) {
  if (!keep_lo.allFinite() || !keep_hi.allFinite() || !(keep_lo.array() < keep_hi.array()).all())
    throw std::invalid_argument("outlet: the region kept must be a box with lo < hi");
  outlet_ = true;
  keep_lo_ = keep_lo;
  keep_hi_ = keep_hi;
}

void Simulation::remove_outflow() {
  // (under a domain: this process's own particles, whose states are its to change; they are
  // counted in count_outflow, where every process holds every state)
  const bool split = !roles_.empty();
  if (split) uncounted_.resize(p_.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (p_.removed[i] || p_.clump[i] >= 0 || kept(p_.pos[i])) continue;
    if (split && roles_[i] != kOwned) continue;
    if (split) {
      ledger_.outflow += 0.5 * p_.mass[i] * p_.vel[i].squaredNorm() +
                         0.5 * p_.inertia[i] * p_.angvel[i].squaredNorm();
      uncounted_[i] = 1;
      freeze(i);
    } else {
      retire(i);
    }
    any = true;
  }
  if (domain_) {
    // (every process at once, when any process retired one: a rebuild now, where every process
    // counts the step's removals as one process has just counted them, so that whatever reads
    // the counts between steps reads the same on every process)
    if (domain_->stale(any)) domain_->rebuild(*this);
  } else if (any) {
    drop_removed_pairs();  // (or the rebuild before the next step drops them)
  }
}

void Simulation::drop_removed_pairs() {
  // (a list to be built anyway, or a periodic one, whose images the pass does not index:
  // the build drops them)
  if (nl_.ref_pos.empty() || periodic_ || hist_.size() != nl_.pairs.size()) {
    invalidate_neighbors();
    return;
  }
  auto gone = [&](std::uint32_t k) {
    const auto [a, b] = nl_.pairs[k];
    return p_.removed[a] != 0 || (b < kWallBase && p_.removed[b] != 0);
  };
  if (!indexed_pass()) {  // (every pair was visited: now all but the dropped)
    const std::size_t np = nl_.pairs.size();
    pass_pairs_.resize(np);
    for (std::size_t k = 0; k < np; ++k) pass_pairs_[k] = static_cast<std::uint32_t>(k);
    pass_wall_pairs_ = wall_pairs_;
  }
  std::erase_if(pass_pairs_, [&](std::uint32_t k) {
    if (!gone(k)) return false;
    dropped_.push_back(k);  // (in pair order)
    return true;
  });
  std::erase_if(pass_wall_pairs_, gone);
  // (a deferred pair admitted in the last step and not in the next is marked apart there)
  std::erase_if(deferred_groups_,
                [&](const DeferredGroup& g) { return p_.removed[g.particle] != 0; });
  pairs_dropped_ = true;
  visit_valid_ = false;
}

void Simulation::share_all_states() {
  if (domain_ && !gathered_) domain_->rebuild(*this);
}

std::vector<double> Simulation::on_whole(
    const std::function<std::vector<double>(Simulation&)>& fn) {
  if (!domain_ || gathered_) return fn(*this);
  domain_->gather(*this);
  std::vector<double> values;
  if (domain_->root()) values = fn(*this);  // (process 0 holds the whole)
  domain_->release(*this);
  domain_->broadcast(values);
  return values;
}

std::vector<Eigen::Vector3d> Simulation::present_positions() const {
  const std::size_t n = p_.size();
  if (!domain_ || gathered_ || roles_.empty()) return p_.pos;
  std::vector<double> v(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    if (roles_[i] == kOwned && !p_.removed[i])
      for (int k = 0; k < 3; ++k) v[3 * i + static_cast<std::size_t>(k)] = p_.pos[i][k];
  domain_->share(v);
  std::vector<Eigen::Vector3d> x(n);
  for (std::size_t i = 0; i < n; ++i)  // (a removed particle lies where it left, on every process)
    x[i] = p_.removed[i] ? p_.pos[i] : Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  return x;
}

void Simulation::restore_keeping_ledger(Simulation&& earlier) {
  const EnergyLedger ledger = ledger_;
  const bool started = ledger_started_;
  *this = std::move(earlier);
  ledger_ = ledger;
  ledger_started_ = started;
  nl_.absent = roles_.empty() ? nullptr : &absent_;  // (its own mask, not the earlier object's)
}

void Simulation::count_outflow() {
  if (!outlet_) return;
  const std::size_t n = p_.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (p_.clump[i] >= 0) continue;
    if (p_.removed[i] == 0) {
      if (kept(p_.pos[i])) continue;
      freeze(i);  // (its owner's ledger has its energy)
    } else if (i >= uncounted_.size() || !uncounted_[i]) {
      continue;
    }
    if (i < uncounted_.size()) uncounted_[i] = 0;
    removed_mass_ += p_.mass[i];
    ++removed_count_;
  }
}

void Simulation::retire(std::size_t i) {
  if (p_.clump[i] < 0) {  // (a member's motion and mass are its clump's)
    ledger_.outflow += 0.5 * p_.mass[i] * p_.vel[i].squaredNorm() +
                       0.5 * p_.inertia[i] * p_.angvel[i].squaredNorm();
    removed_mass_ += p_.mass[i];
  }
  freeze(i);
  ++removed_count_;
}

void Simulation::freeze(std::size_t i) {
  p_.removed[i] = 1;
  p_.fixed[i] = 1;
  p_.vel[i].setZero();
  p_.angvel[i].setZero();
  p_.external_force[i].setZero();
}

void Simulation::set_pending(const std::vector<std::uint32_t>& indices) {
  for (const std::uint32_t i : indices) {
    if (i >= p_.size()) throw std::invalid_argument("no particle " + std::to_string(i));
    if (p_.clump[i] >= 0 || p_.removed[i] == 1)
      throw std::invalid_argument("particle " + std::to_string(i) + " cannot wait for insertion");
    p_.removed[i] = 2;
    p_.fixed[i] = 1;
    p_.vel[i].setZero();
    p_.angvel[i].setZero();
  }
  invalidate_neighbors();
}

void Simulation::insert_particle(std::uint32_t i, const Eigen::Vector3d& position) {
  if (i >= p_.size() || p_.removed[i] != 2)
    throw std::invalid_argument("particle " + std::to_string(i) + " is not waiting for insertion");
  p_.removed[i] = 0;
  p_.fixed[i] = 0;
  p_.pos[i] = position;
  invalidate_neighbors();
}

void Simulation::set_periodic(const Eigen::Matrix3d& hsize, bool planar) {
  if (step_ != 0) throw std::invalid_argument("a periodic cell is set before the first step");
  if (!walls_.empty()) throw std::invalid_argument("walls in a periodic cell are not supported");
  if (!clumps_.empty()) throw std::invalid_argument("clumps in a periodic cell are not supported");
  if (!hsize.allFinite() || !(hsize.determinant() > 0))
    throw std::invalid_argument("periodic cell is degenerate or inverted (det H = " +
                                std::to_string(hsize.determinant()) + ")");
  if (planar) {
    // YADE's 2D emulation: the cell's third base vector along z, no z component in the others,
    // and every centre in one plane z = const.
    if (hsize(2, 0) != 0 || hsize(2, 1) != 0 || hsize(0, 2) != 0 || hsize(1, 2) != 0)
      throw std::invalid_argument("2D cell: the base vectors must lie in the xy plane and z");
    for (std::size_t i = 1; i < p_.size(); ++i)
      if (p_.pos[i].z() != p_.pos[0].z())
        throw std::invalid_argument("2D: particle " + std::to_string(p_.id[i]) +
                                    " at z = " + std::to_string(p_.pos[i].z()) +
                                    " m is not in the plane z = " + std::to_string(p_.pos[0].z()) +
                                    " m");
  }
  periodic_ = true;
  planar_ = planar;
  field_.planar = planar;
  cell_ = PeriodicCell{};
  cell_.hsize = hsize;
  cell_.prev_hsize = hsize;
  invalidate_neighbors();
  nl_.build(p_, walls_, cell_ptr(), planar_);  // (throws PeriodicTooSmall now, not at step 1)
  invalidate_neighbors();
  nl_.pairs.clear();  // (pairs and histories go together: the first step finds them)
  ++pairs_version_;
  nl_.cell_dist.clear();
}

void Simulation::set_cell_servo(const CellServo& servo) {
  if (!periodic_) throw std::invalid_argument("a cell servo needs a periodic cell");
  if (!servo.target.allFinite()) throw std::invalid_argument("cell servo target is not finite");
  const bool any = servo.stress[0] || servo.stress[1] || servo.stress[2];
  if (!(servo.stiffness_fraction >= 0 && servo.stiffness_fraction <= 1))
    throw std::invalid_argument("cell servo stiffness fraction must be in [0, 1] (" +
                                std::to_string(servo.stiffness_fraction) + ")");
  if (any && servo.stiffness_fraction == 0 && (!(servo.gain > 0) || !std::isfinite(servo.gain)))
    throw std::invalid_argument("cell servo gain must be positive (" + std::to_string(servo.gain) +
                                ")");
  if (any && (!(servo.max_rate > 0) || !std::isfinite(servo.max_rate)))
    throw std::invalid_argument("cell servo rate limit must be positive (" +
                                std::to_string(servo.max_rate) + ")");
  if (planar_ && (servo.stress[2] || servo.target[2] != 0))
    throw std::invalid_argument("2D: the cell servo acts in the xy plane only");
  cell_servo_ = servo;
  servo_base_gradient_ = cell_.vel_grad_changed ? cell_.next_vel_grad : cell_.vel_grad;
  servo_base_gradient_.diagonal().setZero();
  Eigen::Matrix3d l = servo_base_gradient_;
  for (int i = 0; i < 3; ++i) l(i, i) = servo.stress[i] ? 0.0 : servo.target[i];
  cell_.set_velocity_gradient(l);
}

void Simulation::set_disks(double thickness_m) {
  if (!planar_) throw std::invalid_argument("disks need a planar periodic cell");
  if (!(thickness_m > 0) || !std::isfinite(thickness_m))
    throw std::invalid_argument("disk thickness must be positive (" + std::to_string(thickness_m) +
                                " m)");
  if (step_ != 0) throw std::invalid_argument("disks are set before the first step");
  disk_thickness_ = thickness_m;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    const double r = p_.radius[i];
    p_.mass[i] = M_PI * r * r * thickness_m * cfg_.material.density;
    p_.inertia[i] = 0.5 * p_.mass[i] * r * r;
  }
  params_key_valid_ = false;
  invalidate_neighbors();
}

void Simulation::set_velocity_gradient(const Eigen::Matrix3d& l) {
  if (!periodic_) throw std::invalid_argument("a velocity gradient needs a periodic cell");
  if (!l.allFinite()) throw std::invalid_argument("velocity gradient is not finite");
  if (planar_ && (l(2, 0) != 0 || l(2, 1) != 0 || l(0, 2) != 0 || l(1, 2) != 0 || l(2, 2) != 0))
    throw std::invalid_argument("2D: the velocity gradient must be in the xy plane");
  cell_.set_velocity_gradient(l);
}

void Simulation::cell_sums(Eigen::Matrix3d& stress, Eigen::Vector3d* stiffness,
                           bool over_domain) const {
  stress.setZero();
  if (stiffness) stiffness->setZero();
  for (std::size_t k = 0; k < hist_.size(); ++k) {
    const auto& h = hist_[k];
    if (!h.real || h.b >= kWallBase) continue;
    if (over_domain && roles_[h.a] != kOwned) continue;  // (the owner of a's counts it)
    Eigen::Vector3d branch = p_.pos[h.a] - p_.pos[h.b];
    if (periodic_) branch -= cell_.hsize * nl_.cell_dist[k].cast<double>();
    stress += (h.fn * h.normal + h.shear_force) * branch.transpose();
    if (stiffness) {
      const Eigen::Array3d n2 = h.normal.array().square();
      stiffness->array() +=
          branch.array().square() * (params_[k].kn * n2 + params_[k].ks * (1 - n2));
    }
  }
  // (over a domain: every process's sums, added in process order; collective)
  if (over_domain) domain_->reduce_cell(stress, stiffness);
  const double volume = periodic_ ? cell_.volume() : 0.0;
  if (!(volume > 0)) return;
  stress /= volume;
  if (stiffness) *stiffness /= volume;
}

Eigen::Matrix3d Simulation::cell_stress() const {
  Eigen::Matrix3d sigma;
  cell_sums(sigma, nullptr);
  return sigma;
}

Eigen::Vector3d Simulation::cell_stiffness() const {
  Eigen::Matrix3d sigma;
  Eigen::Vector3d k;
  cell_sums(sigma, &k);
  return k;
}

void Simulation::rebuild_neighbors() {
  if (domain_) return domain_->rebuild(*this);  // (it calls rebuild_local)
  nl_.build(p_, walls_, cell_ptr(), planar_);
  attach_histories();  // (the old histories and parameters move in place)
  classify_walls();
}

void Simulation::set_domain(Domain* domain) {
  domain_ = domain;
  invalidate_neighbors();
}

void Simulation::set_roles(std::vector<std::uint8_t> roles) {
  if (!roles.empty() && roles.size() != p_.size())
    throw std::invalid_argument("set_roles: one role per particle");
  roles_ = std::move(roles);
  absent_.resize(roles_.size());
  for (std::size_t i = 0; i < roles_.size(); ++i) absent_[i] = roles_[i] == kAbsent;
}

void Simulation::rebuild_local(const std::vector<ContactHistory>& received, bool keep_reference) {
  const bool keep = keep_reference && nl_.ref_pos.size() == p_.size();
  if (keep) {
    kept_ref_pos_.swap(nl_.ref_pos);
    kept_wall_ref_ = {nl_.wall_ref, nl_.wall_normal_ref};
  }
  const Eigen::Matrix3d h_ref = nl_.h_ref;
  nl_.absent = roles_.empty() ? nullptr : &absent_;
  nl_.build(p_, walls_, cell_ptr(), planar_);
  if (keep) {
    nl_.ref_pos.swap(kept_ref_pos_);
    nl_.wall_ref = kept_wall_ref_.first;
    nl_.wall_normal_ref = kept_wall_ref_.second;
    nl_.h_ref = h_ref;  // (the cell's staleness is measured from the last real build too)
  }
  if (!roles_.empty()) {
    // Pairs of two ghosts are another process's (their loads would be dropped here).
    // (a cell's periods go with their pairs)
    const bool periods = nl_.cell_dist.size() == nl_.pairs.size();
    std::size_t kept = 0;
    for (std::size_t k = 0; k < nl_.pairs.size(); ++k) {
      const auto [a, b] = nl_.pairs[k];
      if (roles_[a] != kOwned && (b >= kWallBase || roles_[b] != kOwned)) continue;
      nl_.pairs[kept] = nl_.pairs[k];
      if (periods) nl_.cell_dist[kept] = nl_.cell_dist[k];
      ++kept;
    }
    nl_.pairs.resize(kept);
    if (periods) nl_.cell_dist.resize(kept);
  }
  if (keep_reference && !periodic_) {
    // (for output: every contact received, also one whose pair this build leaves out; a wall
    // switched off after the last step still holds its contacts of that step, as one process
    // holds them until its next rebuild)
    std::vector<std::pair<std::uint32_t, std::uint32_t>> missing;
    for (const ContactHistory& h : received) {
      const auto key = std::make_pair(h.a, h.b);
      if (h.real && !std::binary_search(nl_.pairs.begin(), nl_.pairs.end(), key))
        missing.push_back(key);
    }
    if (!missing.empty()) {
      std::sort(missing.begin(), missing.end());
      std::vector<std::pair<std::uint32_t, std::uint32_t>> all;
      all.reserve(nl_.pairs.size() + missing.size());
      std::merge(nl_.pairs.begin(), nl_.pairs.end(), missing.begin(), missing.end(),
                 std::back_inserter(all));
      nl_.pairs.swap(all);
    }
  }
  attach_histories();
  for (const ContactHistory& h : received) {
    const auto key = std::make_pair(h.a, h.b);
    const auto at = std::lower_bound(nl_.pairs.begin(), nl_.pairs.end(), key);
    if (at != nl_.pairs.end() && *at == key)
      hist_[static_cast<std::size_t>(at - nl_.pairs.begin())] = h;
  }
  active_valid_ = false;  // (contacts received: the next step reads hist_)
  classify_walls();
}

void Simulation::classify_walls() {
  walls_dirty_ = false;
  zero_all_walls_ = true;
  moving_walls_.clear();
  servo_walls_.clear();
  servo_body_of_.clear();
  servo_bodies_.clear();
  timed_walls_.clear();
  const bool built = nl_.wall_ref.size() == walls_.size() &&
                     nl_.wall_normal_ref.size() == walls_.size() &&
                     nl_.wall_ori_ref.size() == walls_.size();
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  std::vector<int> body_slot;
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    WallState& ws = walls_[w];
    const auto i = static_cast<std::uint32_t>(w);
    const bool servo = ws.spec.servo_area_m2 > 0;
    const bool moves = servo || ws.vel != zero || ws.spec.angular_velocity != zero;
    const bool displaced = !built || ws.pos != nl_.wall_ref[w] ||
                           ws.normal != nl_.wall_normal_ref[w] ||
                           ws.ori.coeffs() != nl_.wall_ori_ref[w].coeffs();
    if (moves || displaced) moving_walls_.push_back(i);
    // A still wall's step adds its (signed) zero velocity to its position once here rather than
    // every step: the same bits from then on.
    if (!moves) ws.pos += ws.vel * 0.0;
    if (ws.active && ws.spec.off_at_s < HUGE_VAL) timed_walls_.push_back(i);
    if (!servo) continue;
    servo_walls_.push_back(i);
    const int b = ws.spec.body;
    if (b < 0) {
      servo_body_of_.push_back(-1);
      continue;
    }
    if (body_slot.size() <= static_cast<std::size_t>(b)) body_slot.resize(b + 1, -1);
    if (body_slot[b] < 0) {
      body_slot[b] = static_cast<int>(servo_bodies_.size());
      servo_bodies_.emplace_back();
      for (std::size_t v = 0; v < walls_.size(); ++v)
        if (walls_[v].spec.body == b) servo_bodies_.back().push_back(static_cast<std::uint32_t>(v));
    }
    servo_body_of_.push_back(body_slot[b]);
  }
}

void Simulation::set_wall_velocity(std::size_t w, const Eigen::Vector3d& velocity) {
  walls_.at(w).vel = velocity;
  if (walls_dirty_) return;
  const auto i = static_cast<std::uint32_t>(w);
  const auto at = std::lower_bound(moving_walls_.begin(), moving_walls_.end(), i);
  if (at == moving_walls_.end() || *at != i) moving_walls_.insert(at, i);
}

void Simulation::attach_histories(const std::vector<ContactHistory>* from) {
  // The old histories (hist_, or `from`) are sorted by (a, b), as the pair list is. A contact
  // whose pair left the list cannot be touching (the skin guarantees it), so dropping it loses
  // nothing.
  const std::size_t np = nl_.pairs.size();
  const std::vector<ContactHistory>& old = from ? *from : hist_;
  const std::size_t m = old.size();
  ++pairs_version_;
  active_valid_ = false;  // (until the pairs' flags are set below)
  if (facet_forces_) pair_facet_.assign(np, 0);
  // A pair that stays in the list keeps its stiffnesses and limits (contact_params of the same
  // radii and material, so the same values) when nothing they are computed from has changed;
  // the friction is set afresh (set_friction_deg changes it for sphere pairs only).
  const auto& mat = cfg_.material;
  bool reuse = !from && params_.size() == m && params_key_valid_ && params_radius_ == p_.radius &&
               params_walls_.size() == walls_.size() && params_material_[0] == mat.young_ec &&
               params_material_[1] == mat.stiffness_ratio &&
               params_material_[2] == mat.rolling_beta && params_material_[3] == mat.rolling_eta &&
               params_material_[4] == cfg_.twist_beta && params_material_[5] == cfg_.twist_eta &&
               params_material_[6] == mat.normal_stiffness_N_m &&
               params_rolling_radius_ == mat.rolling_radius;
  for (std::size_t w = 0; reuse && w < walls_.size(); ++w)
    reuse = params_walls_[w] == (static_cast<int>(walls_[w].spec.shape) << 1 |
                                 static_cast<int>(walls_[w].spec.plane_radii));
  const double tan_material = std::tan(mat.friction_deg * M_PI / 180.0);
  // Threads take shares of the new list past 20 000 pairs.
  const int threads = np >= 20000 ? std::max(1, cfg_.threads) : 1;
  constexpr std::uint32_t kNew = std::numeric_limits<std::uint32_t>::max();
  std::exception_ptr error;  // (the first thread's error, rethrown after each region)
  auto keep_error = [&error] {
#pragma omp critical(gs_attach_error)
    if (!error) error = std::current_exception();
  };
  // 1. Each new pair's old index (kNew: a new pair), each share walking the old list from a
  //    binary search for its first pair. The map is increasing.
  std::vector<std::uint32_t> attach_from(np);  // (4 B a pair, while attaching only)
  run_on_team(threads, [&] {
    const auto nt = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    const std::size_t k0 = np * t / nt, k1 = np * (t + 1) / nt;
    auto before = [](const ContactHistory& h, const std::pair<std::uint32_t, std::uint32_t>& pr) {
      return std::make_pair(h.a, h.b) < pr;
    };
    std::size_t o =
        k0 < np ? static_cast<std::size_t>(
                      std::lower_bound(old.begin(), old.end(), nl_.pairs[k0], before) - old.begin())
                : m;
    for (std::size_t k = k0; k < k1; ++k) {
      const auto pr = nl_.pairs[k];
      while (o < m && std::make_pair(old[o].a, old[o].b) < pr) ++o;
      attach_from[k] = o < m && old[o].a == pr.first && old[o].b == pr.second
                           ? static_cast<std::uint32_t>(o)
                           : kNew;
    }
  });
  // 2. In place, the kept histories (and parameters) move to their new indices; no second copy
  //    of them is held. Each share [k0, k1) of the new list first saves the entries it takes
  //    from outside itself (another share's, or past the new end); after a barrier it moves
  //    those it takes from inside itself: to higher indices from the top down, then to lower
  //    ones from the bottom up, so that (the map being increasing) no entry is overwritten
  //    before it has moved; then it writes the saved ones.
  if (from) {
    with_room(hist_, np);
    hist_.resize(np);  // (every entry is set below, on the threads)
    with_room(params_, np);
    params_.resize(np);
  } else {
    const std::size_t span = std::max(m, np);
    with_room(hist_, span);
    hist_.resize(span);
    with_room(params_, reuse ? span : np);  // (parameters not reused are computed afresh)
    params_.resize(reuse ? span : np);
    run_on_team(threads, [&] {
      const auto nt = static_cast<std::size_t>(omp_get_num_threads());
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      const std::size_t k0 = np * t / nt, k1 = np * (t + 1) / nt;
      const auto inside = [k0, k1](std::size_t o) { return o >= k0 && o < k1; };
      struct Saved {
        std::uint32_t k;
        ContactHistory h;
        ContactParams q;
      };
      std::vector<Saved> saved;
      try {
        for (std::size_t k = k0; k < k1; ++k) {
          const std::uint32_t o = attach_from[k];
          if (o != kNew && !inside(o))
            saved.push_back(
                {static_cast<std::uint32_t>(k), hist_[o], reuse ? params_[o] : ContactParams{}});
        }
      } catch (...) {
        keep_error();
      }
#pragma omp barrier
      if (!error) {  // (every thread reaches the barrier, and none moves after an error)
        for (std::size_t k = k1; k-- > k0;) {
          const std::uint32_t o = attach_from[k];
          if (o == kNew || o >= k || !inside(o)) continue;
          hist_[k] = hist_[o];
          if (reuse) params_[k] = params_[o];
        }
        for (std::size_t k = k0; k < k1; ++k) {
          const std::uint32_t o = attach_from[k];
          if (o == kNew || o <= k || !inside(o)) continue;
          hist_[k] = hist_[o];
          if (reuse) params_[k] = params_[o];
        }
        for (const Saved& e : saved) {
          hist_[e.k] = e.h;
          if (reuse) params_[e.k] = e.q;
        }
      }
    });
    if (error) std::rethrow_exception(error);
    hist_.resize(np);
    params_.resize(np);
  }
  // 3. Each pair's history and parameters, and whether it is a contact (active_, read by the
  //    next step as the last step's: hist_ is not read again for it).
  with_room(active_, np);
  active_.resize(np);
  run_on_team(threads, [&] {
    try {
      const auto nt = static_cast<std::size_t>(omp_get_num_threads());
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      const std::size_t k0 = np * t / nt, k1 = np * (t + 1) / nt;
      for (std::size_t k = k0; k < k1; ++k) {
        const auto pr = nl_.pairs[k];
        const std::uint32_t o = attach_from[k];
        const bool kept = o != kNew;
        if (!kept)
          hist_[k] = ContactHistory{};
        else if (from)
          hist_[k] = (*from)[o];
        hist_[k].a = pr.first;
        hist_[k].b = pr.second;
        active_[k] = hist_[k].real ? 1 : 0;
        const WallSpec* ws = pr.second >= kWallBase ? &walls_[pr.second - kWallBase].spec : nullptr;
        if (kept && reuse) {
          if (cfg_.law == ContactLaw::HertzMindlin)
            continue;  // (set_friction_deg: linear law only)
          params_[k].tan_friction = ws && ws->friction_deg >= 0
                                        ? std::tan(ws->friction_deg * M_PI / 180.0)
                                        : tan_material;
          continue;
        }
        const double ra = p_.radius[pr.first];
        const double rb = pr.second >= kWallBase ? ra : p_.radius[pr.second];
        const bool facet2r = ws && ws->shape == WallShape::Facets && !ws->plane_radii;
        if (cfg_.law == ContactLaw::HertzMindlin) {
          // Walls flat (radius 1e5 m, YADE's hertzian facets) or YADE's default radii (a box R, a
          // facet 2R); m* of the dynamic bodies; the pair's restitution and friction. (E*, G*, R*
          // and m* are symmetric to the bit, so the order of the two bodies does not matter.)
          const int ia = p_.material[pr.first], ib = ws ? ws->material : p_.material[pr.second];
          const Material &A = material_at(ia), &B = material_at(ib);
          const double r_wall = cfg_.hertz_flat_walls ? 1e5 : facet2r ? 2 * ra : ra;
          const double ma = p_.fixed[pr.first] ? 0.0 : p_.mass[pr.first];
          const double mb = ws || p_.fixed[pr.second] ? 0.0 : p_.mass[pr.second];
          const std::size_t nm = 1 + cfg_.more_materials.size();
          const std::size_t cell = static_cast<std::size_t>(ia) * nm + static_cast<std::size_t>(ib);
          const double en =
              cfg_.pair_restitution.empty() ? A.restitution : cfg_.pair_restitution[cell];
          double phi = cfg_.pair_friction_deg.empty() ? -1 : cfg_.pair_friction_deg[cell];
          if (phi < 0) phi = std::min(A.friction_deg, B.friction_deg);
          params_[k] =
              hertz_mindlin_params({A.young_ec, A.poisson}, {B.young_ec, B.poisson}, ra,
                                   ws ? r_wall : rb, ma, mb, en, std::tan(phi * M_PI / 180.0));
        } else if (facet2r) {  // YADE: the facet is 2R, first
          params_[k] = contact_params(cfg_.material, 2 * ra, ra, cfg_.twist_beta, cfg_.twist_eta);
        } else {
          params_[k] = contact_params(cfg_.material, ra, rb, cfg_.twist_beta, cfg_.twist_eta);
        }
        if (disk_thickness_ > 0 && !ws &&
            !(mat.normal_stiffness_N_m > 0)) {  // disks: a line contact of Ec per unit thickness
          params_[k].kn = mat.young_ec * disk_thickness_;
          params_[k].ks = mat.stiffness_ratio * params_[k].kn;
          params_[k].kr = mat.rolling_beta * params_[k].ks * ra * rb;
        }
        if (pr.second >= kWallBase) {
          const double wf = walls_[pr.second - kWallBase].spec.friction_deg;
          if (wf >= 0) params_[k].tan_friction = std::tan(wf * M_PI / 180.0);
        }
      }
    } catch (...) {
      keep_error();
    }
  });
  if (error) std::rethrow_exception(error);
  params_key_valid_ = true;
  params_radius_ = p_.radius;
  params_material_ = {
      mat.young_ec,    mat.stiffness_ratio, mat.rolling_beta,        mat.rolling_eta,
      cfg_.twist_beta, cfg_.twist_eta,      mat.normal_stiffness_N_m};
  params_rolling_radius_ = mat.rolling_radius;
  params_walls_.resize(walls_.size());
  for (std::size_t w = 0; w < walls_.size(); ++w)
    params_walls_[w] =
        static_cast<int>(walls_[w].spec.shape) << 1 | static_cast<int>(walls_[w].spec.plane_radii);
  wall_pairs_.clear();
  for (std::size_t k = 0; k < np; ++k)
    if (nl_.pairs[k].second >= kWallBase) wall_pairs_.push_back(static_cast<std::uint32_t>(k));
  // Each facet-wall pair's gap at this build: the distance from the sphere's centre to the
  // closest of the wall's triangles, less its radius, less a margin for the rounding of that
  // distance. Until the positions have moved by more than it (NeighborList::moved), the pair
  // provably does not touch and the contact pass skips it: a wall of many small facets within
  // the skin of a sphere then costs what its contacts cost, not a geometry per facet and step.
  // (none without facet walls: 8 B a pair saved)
  bool facets = false;
  for (const auto& w : walls_) facets = facets || w.spec.shape == WallShape::Facets;
  if (facets) {
    with_room(facet_gap_, np);
    facet_gap_.assign(np, -HUGE_VAL);
  } else {
    std::vector<double>().swap(facet_gap_);
  }
  for (const std::uint32_t k : facets ? wall_pairs_ : std::vector<std::uint32_t>{}) {
    const auto [a, b] = nl_.pairs[k];
    const WallState& w = walls_[b - kWallBase];
    if (w.spec.shape != WallShape::Facets) continue;
    const V3 x(p_.pos[a]), wp(w.pos);
    const double r = p_.radius[a];
    double dist = HUGE_VAL;
    for (const auto& f : w.facets) {
      ContactGeometry g;
      dist = std::min(dist, facet_sphere_geometry(f, wp, x, r, w.spec.plane_radii, g));
    }
    const double tol =
        1e-9 * (r + w.reach + std::abs(x.x - wp.x) + std::abs(x.y - wp.y) + std::abs(x.z - wp.z));
    facet_gap_[k] = dist - r - tol;
  }
  // Pairs that start deferred: a positive gap (the pass would find them apart at once, since the
  // bound on the displacements is 0 right after a build).
  // They are kept per particle (the pairs are sorted by particle), each particle's sorted by
  // gap: a pair's gap closes by at most its particle's displacement plus the walls' (a sphere
  // resting on a finely toothed wall keeps its far teeth out of the pass however much the rest
  // of the assembly moves).
  deferred_.clear();
  deferred_groups_.clear();
  admitted_.clear();
  admitted_prev_.clear();
  visit_valid_ = false;
  pass_pairs_.clear();
  pass_wall_pairs_.clear();
  pairs_dropped_ = false;
  dropped_.clear();
  if (facets)
    for (const std::uint32_t k : wall_pairs_)
      if (facet_gap_[k] > 0) deferred_.push_back(k);
  if (!deferred_.empty()) {
    const auto by_gap = [&](std::uint32_t x, std::uint32_t y) {
      return facet_gap_[x] != facet_gap_[y] ? facet_gap_[x] < facet_gap_[y] : x < y;
    };
    for (std::size_t g = 0; g < deferred_.size();) {
      std::size_t e = g + 1;
      while (e < deferred_.size() && nl_.pairs[deferred_[e]].first == nl_.pairs[deferred_[g]].first)
        ++e;
      std::sort(deferred_.begin() + static_cast<std::ptrdiff_t>(g),
                deferred_.begin() + static_cast<std::ptrdiff_t>(e), by_gap);
      deferred_groups_.push_back({nl_.pairs[deferred_[g]].first, static_cast<std::uint32_t>(g),
                                  static_cast<std::uint32_t>(e)});
      g = e;
    }
    for (const std::uint32_t k : deferred_) hist_[k].real = false;
    pass_pairs_.reserve(np);
    is_deferred_.assign(np, 0);
    for (const std::uint32_t k : deferred_) is_deferred_[k] = 1;
    for (std::size_t k = 0; k < np; ++k)
      if (!is_deferred_[k]) pass_pairs_.push_back(static_cast<std::uint32_t>(k));
    pass_wall_pairs_.clear();
    for (const std::uint32_t k : wall_pairs_)
      if (!is_deferred_[k]) pass_wall_pairs_.push_back(k);
  }
  active_valid_ = true;  // (a superset of the contacts: the deferred pairs are not)
}

std::pair<double, std::size_t> Simulation::wall_stiffness(std::size_t w) const {
  return {walls_.at(w).contact_stiffness, walls_[w].contacts};
}

void Simulation::set_friction_deg(double friction_deg) {
  // Every contact takes it now, sphere pairs and the pairs of walls without a friction angle of
  // their own: what a pair's friction is does not depend on when the neighbour list was last
  // built (a resumed run builds it afresh), so a run resumes bit for bit.
  cfg_.material.friction_deg = friction_deg;
  const double t = std::tan(friction_deg * M_PI / 180.0);
  for (std::size_t k = 0; k < params_.size(); ++k) {
    const std::uint32_t b = nl_.pairs[k].second;
    if (b < kWallBase || !(walls_[b - kWallBase].spec.friction_deg >= 0))
      params_[k].tan_friction = t;
  }
}

void Simulation::set_dt(double dt) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("time step must be positive, got " + std::to_string(dt));
  cfg_.dt = dt;
}

void Simulation::set_wall_active(std::size_t w, bool active) {
  if (walls_.at(w).active == active) return;
  walls_[w].active = active;
  walls_[w].force.setZero();
  walls_[w].torque.setZero();
  walls_dirty_ = true;
  invalidate_neighbors();
}

void Simulation::place_rotated_facets(WallState& w) {
  w.pos = w.rot_center + w.ori * (w.spec.center - w.spec.rotation_center);
  for (std::size_t k = 0; k < w.facets.size(); ++k)
    w.facets[k] = rotated_facet(w.spec.facets[k], w.ori);
  w.normal = w.facets.at(0).normal.eigen();
}

void Simulation::set_facet_forces(bool on) {
  facet_forces_ = on;
  if (!on)
    for (auto& w : walls_) w.facet_force.clear();
  walls_dirty_ = true;
  invalidate_neighbors();
}

[[gnu::always_inline]] inline bool Simulation::pair_geometry(std::size_t k, ContactGeometry& g,
                                                             BodyMotion& m1, BodyMotion& m2,
                                                             std::uint32_t* facet) const {
  const auto [a, b] = nl_.pairs[k];
  if (b >= kWallBase) {
    const WallState& w = walls_[b - kWallBase];
    m2 = {V3(p_.pos[a]), V3(p_.vel[a]), V3(p_.angvel[a])};
    if (w.spec.shape == WallShape::Box) {
      box_sphere_geometry(V3(w.pos), V3(w.spec.half_extents), m2.pos, p_.radius[a], g);
      m1 = {V3(w.pos), V3(w.vel), V3()};
    } else if (w.spec.shape == WallShape::Facets) {
      // The closest of the wall's triangles (one, in YADE's layout).
      const V3 wp(w.pos);
      const auto& fs = w.facets;
      double best = facet_sphere_geometry(fs[0], wp, m2.pos, p_.radius[a], w.spec.plane_radii, g);
      std::size_t k_best = 0;
      for (std::size_t k = 1; k < fs.size(); ++k) {
        ContactGeometry gk;
        const double d =
            facet_sphere_geometry(fs[k], wp, m2.pos, p_.radius[a], w.spec.plane_radii, gk);
        if (d < best) {
          best = d;
          g = gk;
          k_best = k;
        }
      }
      // The wall moves rigidly: v + ω × (x − c) about its rotation centre c (torques about pos).
      const Eigen::Vector3d& om = w.spec.angular_velocity;
      m1 = {wp, V3(w.vel + om.cross(w.pos - w.rot_center)), V3(om)};
      if (facet) *facet = static_cast<std::uint32_t>(k_best);
    } else {
      plane_sphere_geometry(V3(w.pos), V3(w.normal), m2.pos, p_.radius[a], g);
      m1 = {V3(w.pos), V3(w.vel), V3(w.spec.angular_velocity)};
    }
    return true;
  }
  m1 = {V3(p_.pos[a]), V3(p_.vel[a]), V3(p_.angvel[a])};
  m2 = {V3(p_.pos[b]), V3(p_.vel[b]), V3(p_.angvel[b])};
  if (periodic_ && !nl_.cell_dist[k].isZero())
    m2.pos = m2.pos + cell_.shift_pos(nl_.cell_dist[k]);  // se32.position + shift2
  return sphere_sphere_geometry(m1.pos, p_.radius[a], m2.pos, p_.radius[b], g);
}

void Simulation::update_servos() {
  // The force on each servo'd rigid mesh (body): the sum over its walls, in wall order.
  std::vector<Eigen::Vector3d> body_force(servo_bodies_.size(), Eigen::Vector3d::Zero());
  for (std::size_t b = 0; b < servo_bodies_.size(); ++b)
    for (const std::uint32_t w : servo_bodies_[b]) body_force[b] += walls_[w].force;
  for (std::size_t i = 0; i < servo_walls_.size(); ++i) {
    WallState& w = walls_[servo_walls_[i]];
    const auto& s = w.spec;
    // Compressive stress on the wall: the particles push it along −normal (its inward normal).
    const Eigen::Vector3d axis = s.shape == WallShape::Plane ? w.normal : s.normal.normalized();
    const int b = servo_body_of_[i];
    const Eigen::Vector3d& force = b >= 0 ? body_force[static_cast<std::size_t>(b)] : w.force;
    const double stress = -force.dot(axis) / s.servo_area_m2;
    const double v = std::clamp(s.servo_gain * (s.servo_stress_Pa - stress), -s.servo_max_velocity,
                                s.servo_max_velocity);
    w.vel = v * axis;  // too little stress: move into the domain
  }
}

void Simulation::accumulate_walls() {
  // Only the walls loaded in the last step have loads to clear (all of them after a change).
  auto clear = [&](WallState& w) {
    w.force.setZero();
    w.torque.setZero();
    w.contact_stiffness = 0;
    w.contacts = 0;
    if (facet_forces_) w.facet_force.assign(w.facets.size(), Eigen::Vector3d::Zero());
  };
  if (zero_all_walls_) {
    for (auto& w : walls_) clear(w);
    zero_all_walls_ = false;
  } else {
    for (const std::uint32_t w : loaded_walls_) clear(walls_[w]);
  }
  loaded_walls_.clear();
  // (the deferred pairs are not active: only the visited ones are looked at)
  auto add = [&](std::uint32_t k, const ContactLoads& L) {
    WallState& w = walls_[nl_.pairs[k].second - kWallBase];
    if (w.contacts == 0) loaded_walls_.push_back(nl_.pairs[k].second - kWallBase);
    add_to(w.force, L.force1);
    if (facet_forces_ && !w.facet_force.empty()) add_to(w.facet_force[pair_facet_[k]], L.force1);
    w.contact_stiffness += params_[k].kn;
    ++w.contacts;
    add_to(w.torque, L.arm1);
    add_to(w.torque, -L.moment);
  };
  if (!wall_loads_.empty() || std::max(1, cfg_.threads) == 1) {
    // One thread: the touching wall pairs' loads, kept in pair order by the pass.
    for (const auto& [k, L] : wall_loads_) add(k, L);
    return;
  }
  for (const std::uint32_t k : indexed_pass() ? visit_wall_ : wall_pairs_)
    if (active_[k]) add(k, loads_[load_slot_[k]]);
}

std::vector<double> Simulation::wall_load_records() const {
  std::vector<double> out;
  auto put = [&](std::uint32_t k, const ContactLoads& L) {
    const auto [a, b] = nl_.pairs[k];
    const bool facet = facet_forces_ && !walls_[b - kWallBase].facet_force.empty();
    const double r[kWallRecord] = {static_cast<double>(a),
                                   static_cast<double>(b - kWallBase),
                                   params_[k].kn,
                                   L.force1.x,
                                   L.force1.y,
                                   L.force1.z,
                                   L.arm1.x,
                                   L.arm1.y,
                                   L.arm1.z,
                                   L.moment.x,
                                   L.moment.y,
                                   L.moment.z,
                                   facet ? static_cast<double>(pair_facet_[k]) : -1.0};
    out.insert(out.end(), r, r + kWallRecord);
  };
  // (the pairs accumulate_walls adds, in its order)
  if (!wall_loads_.empty() || std::max(1, cfg_.threads) == 1) {
    for (const auto& [k, L] : wall_loads_) put(k, L);
    return out;
  }
  for (const std::uint32_t k : indexed_pass() ? visit_wall_ : wall_pairs_)
    if (active_[k]) put(k, loads_[load_slot_[k]]);
  return out;
}

void Simulation::sum_wall_load_records(const std::vector<double>& records) {
  for (WallState& w : walls_) {
    w.force.setZero();
    w.torque.setZero();
    w.contact_stiffness = 0;
    w.contacts = 0;
    if (facet_forces_) w.facet_force.assign(w.facets.size(), Eigen::Vector3d::Zero());
  }
  // (the operations of accumulate_walls' add, on the same numbers)
  for (std::size_t j = 0; j + kWallRecord <= records.size(); j += kWallRecord) {
    const double* r = records.data() + j;
    WallState& w = walls_.at(static_cast<std::size_t>(r[1]));
    w.contact_stiffness += r[2];
    ++w.contacts;
    for (int c = 0; c < 3; ++c) {
      w.force[c] += r[3 + c];
      w.torque[c] += r[6 + c];
      w.torque[c] += -r[9 + c];
    }
    if (r[12] >= 0)
      for (int c = 0; c < 3; ++c) w.facet_force.at(static_cast<std::size_t>(r[12]))[c] += r[3 + c];
  }
}

void Simulation::set_wall_loads(const std::vector<double>& sums) {
  if (sums.size() != 8 * walls_.size()) throw std::invalid_argument("wall loads: 8 per wall");
  const double* s = sums.data();
  for (WallState& w : walls_) {
    w.force = Eigen::Vector3d(s[0], s[1], s[2]);
    w.torque = Eigen::Vector3d(s[3], s[4], s[5]);
    w.contact_stiffness = s[6];
    w.contacts = static_cast<std::size_t>(s[7]);
    s += 8;
  }
}

[[gnu::always_inline]] inline bool Simulation::prepare_wall_lane(std::size_t k, ContactBatch& B,
                                                                 int j) {
  using F = ContactBatch::Field;
  ContactGeometry g;
  BodyMotion m1, m2;
  if (!pair_geometry(k, g, m1, m2, facet_forces_ ? &pair_facet_[k] : nullptr) ||
      g.penetration < 0) {
    // Not touching (YADE erases the interaction).
    hist_[k].real = false;
    return false;
  }
  B.v[F::GEOM][j] = 0;
  B.set3(F::X1X, j, V3());  // (not read)
  B.set3(F::X2X, j, V3());
  B.set3(F::NX, j, g.normal);
  B.v[F::PEN][j] = g.penetration;
  B.v[F::R1][j] = g.radius1;
  B.v[F::R2][j] = g.radius2;
  B.v[F::RATCHET][j] = g.ratchet_free ? 1 : 0;
  B.set3(F::V1X, j, m1.vel);
  B.set3(F::V2X, j, m2.vel);
  B.set3(F::W1X, j, m1.angvel);
  B.set3(F::W2X, j, m2.angvel);
  B.set3(F::C1X, j, g.point - m1.pos);
  B.set3(F::C2X, j, g.point - m2.pos);
  B.set3(F::PTX, j, g.point);
  if (periodic_) B.set3(F::SVX, j, V3());
  return true;
}

[[gnu::always_inline]] inline bool Simulation::prepare_pair(std::size_t k, ContactBatch& B, int j) {
  using F = ContactBatch::Field;
  const ContactHistory& h = hist_[k];
  const auto [a, b] = nl_.pairs[k];
  auto put = [&](F f, const V3& x) {
    B.v[f][j] = x.x;
    B.v[f + 1][j] = x.y;
    B.v[f + 2][j] = x.z;
  };
  if (b < kWallBase) {
    // A sphere pair: the batch computes its geometry (sphere_sphere_geometry, across lanes).
    V3 x2(p_.pos[b]);
    if (periodic_ && !nl_.cell_dist[k].isZero())
      x2 = x2 + cell_.shift_pos(nl_.cell_dist[k]);  // se32.position + shift2
    B.v[F::GEOM][j] = 1;
    put(F::X1X, V3(p_.pos[a]));
    put(F::X2X, x2);
    B.v[F::R1][j] = p_.radius[a];
    B.v[F::R2][j] = p_.radius[b];
    B.v[F::RATCHET][j] = 1;
    put(F::V1X, V3(p_.vel[a]));
    put(F::V2X, V3(p_.vel[b]));
    put(F::W1X, V3(p_.angvel[a]));
    put(F::W2X, V3(p_.angvel[b]));
    if (periodic_)  // (a pair inside the cell: no shift; +0 either way)
      put(F::SVX, !nl_.cell_dist[k].isZero() ? cell_.shift_vel(nl_.cell_dist[k]) : V3());
  } else if (!prepare_wall_lane(k, B, j)) {
    return false;
  }
  B.v[F::FRESH][j] = h.real ? 0 : 1;
  put(F::ONX, V3(h.normal));
  put(F::SX, V3(h.shear_force));
  put(F::BX, V3(h.bending));
  const bool twist = cfg_.twist_beta > 0;  // (off: the twisting moments stay zero)
  if (twist) put(F::TX, V3(h.twist));
  const ContactParams& p = params_[k];
  B.v[F::KN][j] = p.kn;
  B.v[F::KS][j] = p.ks;
  B.v[F::KR][j] = p.kr;
  if (cfg_.law == ContactLaw::HertzMindlin) B.v[F::KTW][j] = p.ktw;  // (βs)
  if (twist) {
    B.v[F::KTW][j] = p.ktw;
    B.v[F::MAX_TWIST][j] = p.max_twist;
  }
  B.v[F::TAN_FRICTION][j] = p.tan_friction;
  B.v[F::MAX_ROLL][j] = p.max_roll;
  return true;
}

namespace {

/// False only where the sphere (x, r) cannot touch the wall: what pair_geometry would find a
/// negative penetration for (with a margin far above the rounding where the test is not the
/// geometry's own expression).
[[gnu::always_inline]] inline bool wall_may_touch(const WallState& w, const Eigen::Vector3d& x,
                                                  double r) {
  if (w.spec.shape == WallShape::Plane)  // (plane_sphere_geometry's penetration, bit for bit)
    return !(r - dot(V3(x) - V3(w.pos), V3(w.normal)) < 0);
  if (w.spec.shape == WallShape::Box) {
    const Eigen::Vector3d q = ((x - w.pos).cwiseAbs() - w.spec.half_extents).cwiseMax(0.0);
    const double tol = 1e-9 * (r + (x - w.pos).cwiseAbs().sum());
    return !(q.squaredNorm() > (r + tol) * (r + tol));
  }
  // Facets: the distance to a facet is at least the distance l to its plane.
  const V3 xv(x), wp(w.pos);
  for (const auto& f : w.facets) {
    const V3 cl = xv - (wp + f.offset);
    const double l = std::abs(dot(f.normal, cl));
    const double tol = 1e-9 * (r + std::abs(cl.x) + std::abs(cl.y) + std::abs(cl.z) + w.reach);
    if (!(l > r + tol)) return true;
  }
  return false;
}

}  // namespace

void Simulation::admit_deferred() {
  if (deferred_.empty()) {
    if (pairs_dropped_ && !visit_valid_) {  // (only dropped pairs: the pass's own lists)
      visit_ = pass_pairs_;
      visit_wall_ = pass_wall_pairs_;
      visit_valid_ = true;
    }
    return;
  }
  // A deferred pair's gap has closed by at most its particle's displacement since the build plus
  // the largest wall displacement (NeighborList::stale's bound, per particle): the pairs of each
  // particle whose gap is within that bound this step are visited, the others provably do not
  // touch. The bound holds step by step, so a pair may join the pass and leave it again.
  admitted_prev_.swap(admitted_);
  admitted_.clear();
  const double walls_moved = nl_.walls_moved;
  for (const DeferredGroup& g : deferred_groups_) {
    const double bound =
        std::sqrt((p_.pos[g.particle] - nl_.ref_pos[g.particle]).squaredNorm()) + walls_moved;
    std::uint32_t e = g.begin;
    while (e < g.end && !(facet_gap_[deferred_[e]] > bound)) ++e;
    if (e == g.begin) continue;
    const std::size_t at = admitted_.size();
    admitted_.insert(admitted_.end(), deferred_.begin() + g.begin, deferred_.begin() + e);
    // (in pair order: the groups follow the particles, and so the pairs)
    std::sort(admitted_.begin() + static_cast<std::ptrdiff_t>(at), admitted_.end());
  }
  // Pairs visited in the last step and not in this one: apart, as the pass would have found.
  for (std::size_t i = 0, j = 0; i < admitted_prev_.size(); ++i) {
    while (j < admitted_.size() && admitted_[j] < admitted_prev_[i]) ++j;
    if (j == admitted_.size() || admitted_[j] != admitted_prev_[i])
      hist_[admitted_prev_[i]].real = false;
  }
  if (visit_valid_ && admitted_ == admitted_prev_) return;
  visit_.clear();
  std::merge(pass_pairs_.begin(), pass_pairs_.end(), admitted_.begin(), admitted_.end(),
             std::back_inserter(visit_));
  visit_wall_.clear();
  std::merge(pass_wall_pairs_.begin(), pass_wall_pairs_.end(), admitted_.begin(), admitted_.end(),
             std::back_inserter(visit_wall_));
  visit_valid_ = true;
}

template <bool kIndexed>
int Simulation::fill_batch(std::size_t& i, std::size_t end, ContactBatch& batch,
                           std::uint32_t* lane_pair) {
  // Pass 1 without branches (whether a candidate is within reach is a coin flip that the
  // branch predictor loses): candidates within reach are compacted, the others lose their
  // contact (YADE erases the interaction).
  // Wall candidates are culled here too, where they provably do not touch: a plane by the
  // penetration its geometry computes; a box by the distance to it; a mesh when the sphere is
  // farther than its radius from the plane of every facet (the facet distance is at least that).
  std::uint32_t near[ContactBatch::kLanes];
  int m = 0;
  // A system whose particles do not fit in the cache waits on body 2's state, found through
  // the pair list: it is fetched ahead (the 38 000-grain drum 9–15 % faster). On a small one
  // the prefetches only cost (the 1 000-sphere hopper 2 % slower): not there.
  const bool far = p_.size() >= kFarParticles;
  const bool vector = !periodic_ && lane_gather_available();
  for (; i < end && m < ContactBatch::kLanes; ++i) {
    const std::size_t k = kIndexed ? visit_[i] : i;
    const auto [a, b] = nl_.pairs[k];
    if (far) {
      // (the centre and radius of the body 2 of a pair kAhead further on, read below for the
      // reach, and body 2's motion and loads, which pass 2 and the pass's sums use; a wall's 0)
      constexpr std::size_t kAhead = 16;
      const std::size_t i2 = std::min(i + kAhead, end - 1);
      const std::uint32_t b2 = nl_.pairs[kIndexed ? visit_[i2] : i2].second;
      const std::uint32_t j2 = b2 < kWallBase ? b2 : 0;
      __builtin_prefetch(&p_.pos[j2]);
      __builtin_prefetch(&p_.radius[j2]);
    }
    bool in_reach;
    if (b < kWallBase) {
      if (far) {
        __builtin_prefetch(&p_.vel[b]);
        __builtin_prefetch(&p_.angvel[b]);
        __builtin_prefetch(&p_.force[b], 1);
        __builtin_prefetch(&p_.torque[b], 1);
      }
      const double reach = p_.radius[a] + p_.radius[b];
      if (periodic_) {  // (the image of b)
        const Eigen::Vector3i& cd = nl_.cell_dist[k];
        const V3 d =
            (cd.isZero() ? V3(p_.pos[b]) : V3(p_.pos[b]) + cell_.shift_pos(cd)) - V3(p_.pos[a]);
        in_reach = !(squared_norm(d) > reach * reach * (1 + 1e-12));
      } else {
        in_reach = !((p_.pos[b] - p_.pos[a]).squaredNorm() > reach * reach);
      }
    } else {
      in_reach = !(!facet_gap_.empty() && facet_gap_[k] > nl_.moved) &&
                 wall_may_touch(walls_[b - kWallBase], p_.pos[a], p_.radius[a]);
    }
    // (a contact out of reach ends; hist_[k] untouched for the others out of reach, seldom
    // a branch taken)
    if (was_real_[k] & !in_reach) hist_[k].real = false;
    // (pass 2 reads and writes the history's first 113 bytes, 136 with the twist: fetched now,
    // together for the batch)
    __builtin_prefetch(&hist_[k], 1);
    __builtin_prefetch(reinterpret_cast<const char*>(&hist_[k]) + 64, 1);
    __builtin_prefetch(reinterpret_cast<const char*>(&hist_[k]) + 112, 1);
    __builtin_prefetch(&params_[k]);
    near[m] = static_cast<std::uint32_t>(k);
    m += in_reach;
  }
  // Pass 2: the lanes of the sphere pairs within reach and of the wall pairs that touch.
  int lanes = 0;
  if (!vector) {
    for (int i = 0; i < m; ++i) {
      lane_pair[lanes] = near[i];
      lanes += prepare_pair(near[i], batch, lanes);
    }
    return lanes;
  }
  // With AVX-512 (not on a periodic cell): the wall lanes' geometry one by one, then every
  // lane's history and parameters and the sphere lanes' bodies in eights (gather_lanes): the
  // same values in the same lanes.
  // (the pair and body indices again as 64-bit lanes, for the gathers: passing lane_pair and
  // widening it there ran the hopper 2–3 % slower)
  std::int64_t pair[ContactBatch::kLanes], body1[ContactBatch::kLanes], body2[ContactBatch::kLanes];
  std::uint32_t sphere = 0;
  for (int i = 0; i < m; ++i) {
    const std::uint32_t k = near[i];
    const auto [a, b] = nl_.pairs[k];
    if (b < kWallBase)
      sphere |= 1u << lanes;
    else if (!prepare_wall_lane(k, batch, lanes))
      continue;
    lane_pair[lanes] = k;
    pair[lanes] = k;
    body1[lanes] = a;
    body2[lanes] = b;
    ++lanes;
  }
  LaneSources src;
  src.particles = &p_;
  src.hist = hist_.data();
  src.params = params_.data();
  src.ktw = cfg_.law == ContactLaw::HertzMindlin;
  src.twist = cfg_.twist_beta > 0;
  if (lanes > 0) gather_lanes(src, pair, body1, body2, sphere, lanes, batch);
  return lanes;
}

[[gnu::always_inline]] inline bool Simulation::finish_pair(std::size_t k, const ContactBatch& B,
                                                           int j, ContactLoads& L,
                                                           double& max_overlap_ratio) {
  using F = ContactBatch::Field;
  auto get = [&](F f) { return V3(B.v[f][j], B.v[f + 1][j], B.v[f + 2][j]); };
  ContactHistory& h = hist_[k];
  if (B.v[F::TOUCH][j] == 0) {  // (a sphere pair within reach whose penetration is negative)
    h.real = false;
    return false;
  }
  // The history's geometry of this step.
  get(F::NX).store(h.normal);
  get(F::PTX).store(h.point);
  h.overlap = B.v[F::PEN][j];
  h.real = true;
  active_[k] = 1;
  const double rmin = std::min(B.v[F::R1][j], B.v[F::R2][j]);  // (both the sphere's at a wall)
  if (!(h.overlap <= cfg_.max_overlap_ratio * rmin))  // (the ratio only when it is too large)
    max_overlap_ratio = std::max(max_overlap_ratio, h.overlap / rmin);
  get(F::SX).store(h.shear_force);
  get(F::BX).store(h.bending);
  if (cfg_.twist_beta > 0) get(F::TX).store(h.twist);
  h.fn = B.v[F::FN][j];
  L.force1 = get(F::F1X);
  L.arm1 = get(F::A1X);
  L.arm2 = get(F::A2X);
  L.moment = get(F::MX);
  L.friction_dissipation = B.v[F::FRICTION_DISSIPATION][j];
  L.rolling_dissipation = B.v[F::ROLLING_DISSIPATION][j];
  return true;
}

void Simulation::run_law(ContactBatch& batch, int count, double dt) const {
  if (cfg_.law == ContactLaw::HertzMindlin)
    hertz_mindlin_batch(batch, count, dt, periodic_);
  else
    cohesive_frictional_batch(batch, count, dt, cfg_.twist_beta > 0, periodic_);
}

void Simulation::serial_pass(std::size_t nv, bool indexed, double& max_overlap_out) {
  double max_overlap_ratio = max_overlap_out;  // (a local: the loads' stores cannot alias it)
  const std::size_t n = p_.size();
  const double dt = cfg_.dt;
  for (std::size_t i = 0; i < n; ++i) {
    p_.force[i] = p_.external_force[i];
    p_.torque[i].setZero();
    particle_dissipation_[2 * i] = particle_dissipation_[2 * i + 1] = 0;
  }
  ContactBatch batch;
  std::uint32_t lane_pair[ContactBatch::kLanes];
  // The loads of body 1 stay in registers while its pairs follow each other (pairs are
  // sorted by body 1, and a particle's pairs as body 2 all come before those as body 1):
  // the same additions in the same order.
  std::uint32_t cur = kWallBase;
  V3 f_cur, t_cur;
  double fr_cur = 0, ro_cur = 0;
  auto flush = [&] {
    if (cur == kWallBase) return;
    f_cur.store(p_.force[cur]);
    t_cur.store(p_.torque[cur]);
    particle_dissipation_[2 * cur] = fr_cur;
    particle_dissipation_[2 * cur + 1] = ro_cur;
  };
  for (std::size_t i = 0; i < nv;) {
    const int m = indexed ? fill_batch<true>(i, nv, batch, lane_pair)
                          : fill_batch<false>(i, nv, batch, lane_pair);
    run_law(batch, m, dt);
    for (int j = 0; j < m; ++j) {
      const std::uint32_t kk = lane_pair[j];
      ContactLoads L;
      if (!finish_pair(kk, batch, j, L, max_overlap_ratio)) continue;
      const auto [a, b] = nl_.pairs[kk];
      if (a != cur) {
        flush();
        cur = a;
        f_cur = V3(p_.force[a]);
        t_cur = V3(p_.torque[a]);
        fr_cur = particle_dissipation_[2 * a];
        ro_cur = particle_dissipation_[2 * a + 1];
      }
      fr_cur += L.friction_dissipation;
      ro_cur += L.rolling_dissipation;
      if (b < kWallBase) {
        f_cur += L.force1;
        t_cur += L.arm1;
        t_cur += -L.moment;
        add_to(p_.force[b], -L.force1);
        add_to(p_.torque[b], L.arm2);
        add_to(p_.torque[b], L.moment);
      } else {
        f_cur += -L.force1;
        t_cur += L.arm2;
        t_cur += L.moment;
        wall_loads_.push_back({kk, L});  // for the wall's resultant (in pair order)
      }
    }
  }
  flush();
  max_overlap_out = max_overlap_ratio;
}

// (Without GCC's SLP vectoriser: it packed some of a pair's loads in twos and left the others
// scalar, so it loaded the lane's loads twice and spilled them; without it the threads' pass ran
// 363 M instructions instead of 427 M on the 53k specimen, 21 steps. The one-thread pass keeps
// it: without, it ran 20 M more.)
template <bool kIndexed>
[[gnu::optimize("no-tree-slp-vectorize")]] void Simulation::contact_pass(std::size_t begin,
                                                                         std::size_t end,
                                                                         double& max_overlap_out) {
  double max_overlap_ratio = max_overlap_out;  // (a local: the loads' stores cannot alias it)
  // The particles of this share start from their applied loads.
  const auto t = static_cast<std::size_t>(omp_get_thread_num());
  const std::size_t p0 = split_first_[t], p1 = split_first_[t + 1];
  for (std::size_t i = p0; i < p1; ++i) {
    p_.force[i] = p_.external_force[i];
    p_.torque[i].setZero();
    particle_dissipation_[2 * i] = particle_dissipation_[2 * i + 1] = 0;
  }
  const std::uint8_t* mixed = split_mixed_.data();
  ContactBatch batch;
  std::uint32_t lane_pair[ContactBatch::kLanes];
  // The loads of body 1 stay in registers while its pairs follow each other (pairs are
  // sorted by body 1, and a particle's pairs as body 2 all come before those as body 1):
  // the same additions in the same order. A mixed body 1 is summed the same way, but its sum is
  // not stored: the gather recomputes it (this keeps the per-pair work free of its branches).
  std::uint32_t cur = kWallBase;
  bool cur_mixed = true;
  V3 f_cur, t_cur;
  double fr_cur = 0, ro_cur = 0;
  auto flush = [&] {
    if (cur_mixed) return;
    f_cur.store(p_.force[cur]);
    t_cur.store(p_.torque[cur]);
    particle_dissipation_[2 * cur] = fr_cur;
    particle_dissipation_[2 * cur + 1] = ro_cur;
  };
  // A pair's loads for a mixed particle's gather or a wall's resultant, read from its lane (not
  // from a ContactLoads, which would then be built in memory for every pair).
  auto keep_loads = [&](std::uint32_t k, int j) {
    using F = ContactBatch::Field;
    auto get = [&](F f) { return V3(batch.v[f][j], batch.v[f + 1][j], batch.v[f + 2][j]); };
    const std::uint32_t r = load_slot_[k];
    ContactLoads& L = loads_[r];
    L.force1 = get(F::F1X);
    L.arm1 = get(F::A1X);
    L.arm2 = get(F::A2X);
    L.moment = get(F::MX);
    L.friction_dissipation = dissipation_[2 * r] = batch.v[F::FRICTION_DISSIPATION][j];
    L.rolling_dissipation = dissipation_[2 * r + 1] = batch.v[F::ROLLING_DISSIPATION][j];
  };
  const double dt = cfg_.dt;
  for (std::size_t i = begin; i < end;) {
    const int m = fill_batch<kIndexed>(i, end, batch, lane_pair);
    run_law(batch, m, dt);
    for (int j = 0; j < m; ++j) {
      const std::uint32_t kk = lane_pair[j];
      ContactLoads L;
      if (!finish_pair(kk, batch, j, L, max_overlap_ratio)) continue;
      const auto [a, b] = nl_.pairs[kk];
      if (a != cur) {
        flush();
        cur = a;
        cur_mixed = mixed[a];
        f_cur = V3(p_.force[a]);
        t_cur = V3(p_.torque[a]);
        fr_cur = particle_dissipation_[2 * a];
        ro_cur = particle_dissipation_[2 * a + 1];
      }
      fr_cur += L.friction_dissipation;
      ro_cur += L.rolling_dissipation;
      if (b < kWallBase) {
        f_cur += L.force1;
        t_cur += L.arm1;
        t_cur += -L.moment;
        const bool b_mixed = mixed[b];
        if (!b_mixed) {
          add_to(p_.force[b], -L.force1);
          add_to(p_.torque[b], L.arm2);
          add_to(p_.torque[b], L.moment);
        }
        if (b_mixed || cur_mixed) keep_loads(kk, j);  // (for a mixed one's gather)
      } else {
        f_cur += -L.force1;
        t_cur += L.arm2;
        t_cur += L.moment;
        keep_loads(kk, j);  // (for the wall's resultant, and a mixed one's gather)
      }
    }
  }
  flush();
  max_overlap_out = max_overlap_ratio;
}

bool Simulation::shares_unbalanced() const {
  if (share_steps_ < kShareCheckSteps || share_seconds_.empty()) return false;
  const auto [lo, hi] = std::minmax_element(share_seconds_.begin(), share_seconds_.end());
  return *hi > kShareImbalance * *lo;
}

std::vector<double> balanced_cuts(std::size_t nt, const std::vector<std::size_t>& bounds,
                                  const std::vector<double>& seconds) {
  // The cost per pair is taken as constant within each old share (its seconds over its
  // fraction of the list), and the cuts fall where the cumulative cost reaches t/nt of the total.
  std::vector<double> cut(nt + 1);
  for (std::size_t t = 0; t <= nt; ++t) cut[t] = static_cast<double>(t) / static_cast<double>(nt);
  const std::size_t old_np = bounds.empty() ? 0 : bounds.back();
  if (seconds.size() != nt || bounds.size() != nt + 1 || old_np == 0) return cut;
  double total = 0;
  for (const double s : seconds) {
    if (!(s > 0 && s < HUGE_VAL)) return cut;
    total += s;
  }
  auto frac = [&](std::size_t t) {
    return static_cast<double>(bounds[t]) / static_cast<double>(old_np);
  };
  std::size_t seg = 0;
  double below = 0;  // the cost of the old shares before seg
  for (std::size_t t = 1; t < nt; ++t) {
    const double target = total * static_cast<double>(t) / static_cast<double>(nt);
    while (seg + 1 < nt && below + seconds[seg] < target) below += seconds[seg++];
    const double w = frac(seg + 1) - frac(seg);
    cut[t] = std::clamp(frac(seg) + w * (target - below) / seconds[seg], cut[t - 1], 1.0);
  }
  return cut;
}

void Simulation::split_pairs(std::size_t nt) {
  const std::size_t n = p_.size(), np = nl_.pairs.size();
  // (equal counts of pairs until the shares of the last split have been timed: their seconds
  // are zero until then; the shares' sizes change no result: every split gives the same bits)
  const std::vector<double> cut = balanced_cuts(nt, split_pair_, share_seconds_);
  split_first_.assign(nt + 1, 0);
  split_pair_.assign(nt + 1, 0);
  for (std::size_t t = 1; t < nt; ++t) {
    // The share starts at the body 1 of its first pair by the cut (all pairs of a particle as
    // body 1 stay in one share).
    const std::size_t k =
        std::min(np, static_cast<std::size_t>(std::llround(cut[t] * static_cast<double>(np))));
    const std::uint32_t first = k < np ? nl_.pairs[k].first : static_cast<std::uint32_t>(n);
    split_first_[t] = std::max(first, split_first_[t - 1]);
    split_pair_[t] = static_cast<std::size_t>(
        std::lower_bound(nl_.pairs.begin(), nl_.pairs.end(),
                         std::pair<std::uint32_t, std::uint32_t>{split_first_[t], 0}) -
        nl_.pairs.begin());
  }
  split_first_[nt] = static_cast<std::uint32_t>(n);
  split_pair_[nt] = np;
  split_mixed_.assign(n, 0);
  for (std::size_t t = 0; t < nt; ++t)
    for (std::size_t k = split_pair_[t]; k < split_pair_[t + 1]; ++k) {
      const std::uint32_t b = nl_.pairs[k].second;
      if (b < kWallBase && b >= split_first_[t + 1]) split_mixed_[b] = 1;
    }
  split_mixed_list_.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (split_mixed_[i]) split_mixed_list_.push_back(static_cast<std::uint32_t>(i));
  // Rows for the loads kept per pair: those of a mixed particle's pairs (for its gather) and of
  // the wall pairs (for the walls' resultants); 4 B a pair instead of 128. And each mixed
  // particle's pairs in pair order (entry = pair << 1, | 1 when the particle is the second
  // body), the gather's order: a counting sort of the entries, in pair order, by the particle's
  // place in split_mixed_list_ (a few per cent of the particles: no list for the others).
  with_room(load_slot_, np);
  load_slot_.resize(np);
  const std::size_t nm = split_mixed_list_.size();
  std::vector<std::uint32_t> slot(n);  // (read for the mixed particles only)
  for (std::size_t m = 0; m < nm; ++m) slot[split_mixed_list_[m]] = static_cast<std::uint32_t>(m);
  auto slot_of = [&](std::uint32_t i) { return slot[i]; };
  mixed_start_.assign(nm + 1, 0);
  std::uint32_t rows = 0;
  for (std::size_t k = 0; k < np; ++k) {
    const auto [a, b] = nl_.pairs[k];
    const bool ma = split_mixed_[a] != 0, mb = b < kWallBase && split_mixed_[b] != 0;
    load_slot_[k] = b >= kWallBase || ma || mb ? rows++ : std::numeric_limits<std::uint32_t>::max();
    if (ma) ++mixed_start_[slot_of(a) + 1];
    if (mb) ++mixed_start_[slot_of(b) + 1];
  }
  for (std::size_t m = 0; m < nm; ++m) mixed_start_[m + 1] += mixed_start_[m];
  mixed_pairs_.resize(mixed_start_[nm]);
  std::vector<std::uint32_t> fill(mixed_start_.begin(), mixed_start_.end() - 1);
  for (std::size_t k = 0; k < np; ++k) {
    if (load_slot_[k] == std::numeric_limits<std::uint32_t>::max()) continue;
    const auto [a, b] = nl_.pairs[k];
    if (split_mixed_[a]) mixed_pairs_[fill[slot_of(a)]++] = static_cast<std::uint32_t>(k << 1);
    if (b < kWallBase && split_mixed_[b])
      mixed_pairs_[fill[slot_of(b)]++] = static_cast<std::uint32_t>(k << 1 | 1u);
  }
  with_room(loads_, rows);
  loads_.resize(rows);
  with_room(dissipation_, 2 * std::size_t{rows});
  dissipation_.resize(2 * std::size_t{rows});
  split_version_ = pairs_version_;
  split_threads_ = nt;
  share_seconds_.assign(nt, 0.0);
  share_steps_ = 0;
}

void Simulation::step() {
  if (periodic_) cell_.integrate(cfg_.dt);  // (YADE: Scene::moveToNextTimeStep, before engines)
  if (walls_dirty_) classify_walls();
  nl_.absent = roles_.empty() ? nullptr : &absent_;  // (a copied Simulation points at its own)
  bool stale = nl_.stale(p_, walls_, cell_ptr(), &moving_walls_);
  if (domain_) stale = domain_->stale(stale);
  if (stale) rebuild_neighbors();
  for (const std::uint32_t k : dropped_) hist_[k].real = false;  // (what the build would drop)
  dropped_.clear();
  admit_deferred();
  const double dt = cfg_.dt;
  const std::size_t np = nl_.pairs.size();
  // The pairs the contact pass visits: all, or visit_ while some facet pairs are deferred.
  const bool indexed = indexed_pass();
  const std::size_t nv = indexed ? visit_.size() : np;
  const int threads = std::max(1, cfg_.threads);
  // Which pairs were contacts: the last step's active_ (only a step sets ContactHistory::real
  // true, and it sets active_ with it; what clears real between steps leaves a superset), or
  // after a build or restore, hist_ read once.
  if (active_valid_ && active_.size() == np) {
    was_real_.swap(active_);
  } else {
    with_room(was_real_, np);
    was_real_.resize(np);
    for (std::size_t k = 0; k < np; ++k) was_real_[k] = hist_[k].real;
  }
  active_valid_ = false;  // (until this step ends)
  with_room(active_, np);
  active_.resize(np);  // (zeroed in the region below, each thread its share of the pairs)
  // (one thread keeps no loads per pair, only its walls'; threads keep the rows split_pairs
  // gives)
  wall_loads_.clear();
  const std::size_t n = p_.size();
  // Ledger terms summed per particle (a pair's dissipation goes to its body 1, in pair order),
  // then per chunk of kChunk particles, then over the chunks in order: the same sums for any
  // number of threads, and for any Verlet list holding the same contacts (a resumed run).
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  chunk_sums_.resize(kSums * chunks);
  particle_dissipation_.resize(2 * n);
  double max_overlap_ratio = 0;
  bool finite = true;
  // One parallel region per step (a region per loop lets the idle thread fall asleep between
  // them, and waking it costs more than the loops on small systems); with one thread, none
  // (run_on_team: the constructs below then run orphaned).
  const bool resplit = threads > 1 && (split_version_ != pairs_version_ || shares_unbalanced() ||
                                       split_threads_ != static_cast<std::size_t>(threads));
  if (threads > 1 && !resplit) ++share_steps_;
  auto region = [&] {
    const std::size_t nt = static_cast<std::size_t>(omp_get_num_threads());
    if (nt == 1) {
      // One thread: the loads go straight onto the particles, in pair order, which is the
      // order the gather below sums them in, so the results are the same as with more threads.
      std::fill(active_.begin(), active_.end(), std::uint8_t{0});
      serial_pass(nv, indexed, max_overlap_ratio);
    } else {
      // Each thread takes a share of the particles with their pairs as body 1 and sums their
      // loads straight onto them, as one thread does; the few particles also loaded by another
      // share's pairs (mixed) are gathered afterwards from loads_ in pair order. The sums are
      // the serial pass's for any number of threads.
      // (a new split only when the list, the team or the balance changed: decided before the
      // region, so that the step's other loops pay no barrier for it)
      if (resplit || nt != static_cast<std::size_t>(threads)) {
#pragma omp single
        {
          split_pairs(nt);
          ++share_steps_;
        }
      }
      const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
      std::size_t begin = split_pair_[t], end = split_pair_[t + 1];
      if (indexed) {  // (the positions in visit_ of the share's pairs)
        begin = static_cast<std::size_t>(
            std::lower_bound(visit_.begin(), visit_.end(), static_cast<std::uint32_t>(begin)) -
            visit_.begin());
        end = static_cast<std::size_t>(
            std::lower_bound(visit_.begin(), visit_.end(), static_cast<std::uint32_t>(end)) -
            visit_.begin());
      }
      std::fill(active_.begin() + static_cast<std::ptrdiff_t>(split_pair_[t]),
                active_.begin() + static_cast<std::ptrdiff_t>(split_pair_[t + 1]), std::uint8_t{0});
      double my_max_overlap = 0;
      const double start = omp_get_wtime();
      if (indexed)
        contact_pass<true>(begin, end, my_max_overlap);
      else
        contact_pass<false>(begin, end, my_max_overlap);
      share_seconds_[t] += omp_get_wtime() - start;  // (for the next split's balance)
#pragma omp critical(gs_max_overlap)
      max_overlap_ratio = std::max(max_overlap_ratio, my_max_overlap);
#pragma omp barrier

      // The mixed particles' loads gathered in pair order (the pairs of each particle are
      // listed in that order).
      const std::size_t nm = split_mixed_list_.size();
#pragma omp for schedule(static)
      for (std::size_t m = 0; m < nm; ++m) {
        const std::uint32_t i = split_mixed_list_[m];
        V3 f(p_.external_force[i]), tq;
        double fr = 0, ro = 0;  // dissipation of the pairs whose body 1 this particle is
        for (std::uint32_t e = mixed_start_[m]; e < mixed_start_[m + 1]; ++e) {
          const std::uint32_t k = mixed_pairs_[e] >> 1;
          if (!active_[k]) continue;
          const std::uint32_t r = load_slot_[k];
          const ContactLoads& L = loads_[r];
          if ((mixed_pairs_[e] & 1u) == 0) {
            fr += dissipation_[2 * r];
            ro += dissipation_[2 * r + 1];
          }
          const bool first = (mixed_pairs_[e] & 1u) == 0 && nl_.pairs[k].second < kWallBase;
          if (first) {  // body 1 of a sphere pair
            f += L.force1;
            tq += L.arm1;
            tq += -L.moment;
          } else {  // body 2: the second sphere, or the sphere of a wall pair
            f += -L.force1;
            tq += L.arm2;
            tq += L.moment;
          }
        }
        f.store(p_.force[i]);
        tq.store(p_.torque[i]);
        particle_dissipation_[2 * i] = fr;
        particle_dissipation_[2 * i + 1] = ro;
      }
    }

    // The walls' loads and work, the servos, the clumps' loads and the cell's field: one thread.
    auto walls_and_fields = [&] {
      if (domain_) {
        zero_all_walls_ = true;  // (a wall loaded elsewhere has loads here after the sum)
        // (exact sums are formed from every process's wall contacts: no sums of its own first)
        if (!exact_wall_loads()) accumulate_walls();
        domain_->reduce_walls(*this);
      } else {
        accumulate_walls();
      }
      update_servos();
      if (!clumps_.empty()) gather_clump_loads();  // (before the integration moves members)
      if (periodic_) {
        // NewtonIntegrator's start: a pending gradient becomes current, and the change of the
        // mean field since the last step is added to velocities and spins.
        cell_.apply_pending_gradient();
        field_.prev_vel_grad = cell_.prev_vel_grad;
        field_.d_vel_grad = cell_.vel_grad - cell_.prev_vel_grad;
        const Eigen::Matrix3d r = 0.5 * (field_.d_vel_grad - field_.d_vel_grad.transpose());
        field_.d_spin = Eigen::Vector3d(-r(1, 2), r(0, 2), -r(0, 1));
      }
      // (a wall not in moving_walls_ has a zero velocity: its term is ±0). The power a wall
      // gives the particles: −(F·v + T·ω), F and T the loads on it, T about its position, v that
      // position's velocity (a mesh turns about its rotation centre); ω = 0 adds an exact 0.
      for (const std::uint32_t w : moving_walls_) {
        const WallState& ws = walls_[w];
        const Eigen::Vector3d& om = ws.spec.angular_velocity;
        Eigen::Vector3d v = ws.vel;
        if (ws.spec.shape == WallShape::Facets) v += om.cross(ws.pos - ws.rot_center);
        ledger_.wall_work += -(ws.force.dot(v) + ws.torque.dot(om)) * dt;
      }
    };
    // Without clumps, a periodic cell or processes the integration reads none of what that
    // thread writes: the walls come after it, on the thread that ends its share first (below).
    const bool walls_after = clumps_.empty() && !periodic_ && !domain_;
    if (!walls_after) {
#pragma omp single
      walls_and_fields();  // (implicit barrier: the integration uses the clumps' and cell's)
    }

    // Integration, with the work of gravity and of applied loads over this step (velocities of
    // the step, before the update) and the damping dissipation, summed per fixed chunk.
    auto integrate_chunk = [&](std::size_t c) {
      double fr = 0, ro = 0;
      const std::size_t begin = c * kChunk, end = std::min(n, (c + 1) * kChunk);
      const std::uint8_t* roles = roles_.empty() ? nullptr : roles_.data();
      for (std::size_t i = begin; i < end; ++i) {
        if (roles && roles[i] != kOwned) continue;  // (a ghost's are its owner's to count)
        fr += particle_dissipation_[2 * i];
        ro += particle_dissipation_[2 * i + 1];
      }
      const IntegrationSums sums =
          periodic_ || planar_ ? integrate_particles_homogeneous(p_, begin, end, cfg_.gravity,
                                                                 cfg_.damping, dt, field_, roles)
                               : integrate_particles(p_, begin, end, cfg_.gravity, cfg_.damping, dt,
                                                     !clumps_.empty(), roles);
      chunk_sums_[kSums * c] = fr;
      chunk_sums_[kSums * c + 1] = ro;
      chunk_sums_[kSums * c + 2] = sums.gravity_power;
      chunk_sums_[kSums * c + 3] = sums.external_power;
      chunk_sums_[kSums * c + 4] = sums.damping;
      return sums.finite;
    };
    if (nt > 1 && split_first_.size() == nt + 1) {
      // Each thread the chunks that start in its share of the contact pass: the particles whose
      // loads it has just summed, still in its core's cache (taken as they came, half the
      // chunks were the other core's, and the integration of the 53k box cost 1.8 times the
      // one thread's). Each chunk's sums are its own, whichever thread forms them.
      const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
      const std::size_t c0 = (split_first_[t] + kChunk - 1) / kChunk;
      const std::size_t c1 = (split_first_[t + 1] + kChunk - 1) / kChunk;
      bool mine = true;
      for (std::size_t c = c0; c < c1; ++c) mine = integrate_chunk(c) && mine;
      if (!mine) {
#pragma omp atomic write
        finite = false;
      }  // (the region's end is the barrier)
    } else {
#pragma omp for schedule(dynamic) reduction(&& : finite)
      for (std::size_t c = 0; c < chunks; ++c) finite = integrate_chunk(c) && finite;
    }
    if (walls_after) {
#pragma omp single nowait
      walls_and_fields();  // (the region's end is the barrier)
    }
  };
  run_on_team(threads, region);
  const bool hertz = cfg_.law == ContactLaw::HertzMindlin;
  for (std::size_t c = 0; c < chunks; ++c) {
    ledger_.friction_dissipation += chunk_sums_[kSums * c];
    (hertz ? ledger_.viscous_dissipation : ledger_.rolling_dissipation) +=
        chunk_sums_[kSums * c + 1];  // (the Hertz-Mindlin law has no contact moments)
    ledger_.gravity_work += chunk_sums_[kSums * c + 2] * dt;
    ledger_.external_work += chunk_sums_[kSums * c + 3] * dt;
    ledger_.damping_dissipation += chunk_sums_[kSums * c + 4];
  }
  if (!clumps_.empty()) finite = integrate_clumps() && finite;
  // The owners' new states to the processes holding them as ghosts (before the cell's stress,
  // whose branch vectors need them).
  if (domain_) domain_->exchange(*this);
  if (periodic_) cell_.prev_vel_grad = cell_.vel_grad;  // (NewtonIntegrator's end)
  if (cell_servo_) {
    // The next step's diagonal from this step's stress (forces of this step, positions and
    // cell after it, as YADE's getStress() there).
    const CellServo& sv = *cell_servo_;
    Eigen::Matrix3d sigma;
    Eigen::Vector3d k;  // (one pass over the contacts for the stress and the stiffness)
    cell_sums(sigma, sv.stiffness_fraction > 0 ? &k : nullptr, domain_ && !roles_.empty());
    Eigen::Matrix3d l = servo_base_gradient_;
    Eigen::Vector3d gain = Eigen::Vector3d::Constant(sv.gain);
    if (sv.stiffness_fraction > 0) {
      for (int i = 0; i < 3; ++i)
        gain[i] = k[i] > 0 ? sv.stiffness_fraction / (k[i] * dt)
                           : std::numeric_limits<double>::infinity();
    }
    for (int i = 0; i < 3; ++i) {
      const double error = sv.target[i] - sigma(i, i);
      l(i, i) = !sv.stress[i]         ? sv.target[i]
                : std::isinf(gain[i]) ? (error > 0   ? sv.max_rate
                                         : error < 0 ? -sv.max_rate
                                                     : 0.0)
                                      : std::clamp(gain[i] * error, -sv.max_rate, sv.max_rate);
    }
    cell_.set_velocity_gradient(l);
  }
  if (domain_) domain_->agree(max_overlap_ratio, finite);
  if (!(max_overlap_ratio <= cfg_.max_overlap_ratio))
    throw BlowUp("step " + std::to_string(step_) + ": overlap of " +
                 std::to_string(max_overlap_ratio) + " radius exceeds " +
                 std::to_string(cfg_.max_overlap_ratio) +
                 " (time step too large or walls too fast?)");
  if (!finite) throw BlowUp("step " + std::to_string(step_) + ": non-finite particle state");
  for (const std::uint32_t wi : moving_walls_) {
    WallState& w = walls_[wi];
    w.pos += w.vel * dt;
    const double om = w.spec.angular_velocity.norm();
    if (!(om > 0)) continue;
    const Eigen::AngleAxisd turn(om * dt, w.spec.angular_velocity / om);
    if (w.spec.shape == WallShape::Plane) {
      w.normal = (turn * w.normal).normalized();
    } else if (w.spec.shape == WallShape::Facets) {
      // Rigid rotation about the moving centre, from the initial triangles (no drift).
      w.rot_center += w.vel * dt;
      w.ori = (Eigen::Quaterniond(turn) * w.ori).normalized();
      place_rotated_facets(w);
    }
  }
  active_valid_ = true;  // (what clears real from here to the next step leaves a superset)
  time_ += dt;
  ++step_;
  for (const std::uint32_t w : timed_walls_)
    if (walls_[w].active && time_ >= walls_[w].spec.off_at_s) set_wall_active(w, false);
  if (outlet_) remove_outflow();
}

void Simulation::run(std::int64_t steps) {
  for (std::int64_t s = 0; s < steps; ++s) step();
}

std::size_t Simulation::contact_count() const {
  std::size_t c = 0;
  for (const auto& h : hist_) c += h.real;
  return c;
}

std::size_t Simulation::sphere_contact_count() const {
  std::size_t c = 0;
  for (const auto& h : hist_) c += (h.real && h.b < kWallBase);
  return c;
}

double Simulation::kinetic_energy_of(const std::vector<std::uint8_t>* touching) const {
  double e = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (p_.clump[i] >= 0 || (touching && !(*touching)[i])) continue;
    e += particle_kinetic_energy(i);
  }
  for (const auto& c : clumps_) {  // (members skipped, as YADE)
    bool t = !touching;
    for (std::size_t m = 0; !t && m < c.members.size(); ++m) t = (*touching)[c.members[m]] != 0;
    if (t) e += clump_kinetic_energy(c);
  }
  return e;
}

double Simulation::particle_kinetic_energy(std::size_t i) const {
  // In a cell: the fluctuations about the mean field (YADE's utils.kineticEnergy).
  const Eigen::Vector3d v =
      periodic_ ? Eigen::Vector3d(p_.vel[i] - cell_.vel_grad * p_.pos[i]) : p_.vel[i];
  return 0.5 * p_.mass[i] * v.squaredNorm() + 0.5 * p_.inertia[i] * p_.angvel[i].squaredNorm();
}

double Simulation::kinetic_energy() const {
  return kinetic_energy_of(nullptr);
}

double Simulation::kinetic_energy_in_contact() const {
  std::vector<std::uint8_t> touching(p_.size(), 0);
  for (const auto& h : hist_) {
    if (!h.real) continue;
    touching[h.a] = 1;
    if (h.b < kWallBase) touching[h.b] = 1;
  }
  return kinetic_energy_of(&touching);
}

double Simulation::inertial_number() const {
  // Over the particles in the scene (not those removed or waiting to be inserted).
  std::size_t n = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) n += p_.removed[i] == 0;
  if (n < 4) return std::numeric_limits<double>::quiet_NaN();
  // Affine fit v ≈ v0 + L·(x − x̄): L = (Σ v'x'ᵀ)(Σ x'x'ᵀ)⁻¹.
  Eigen::Vector3d xm = Eigen::Vector3d::Zero(), vm = Eigen::Vector3d::Zero();
  double dsum = 0;
  std::size_t first = p_.size();
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (p_.removed[i]) continue;
    first = std::min(first, i);
    xm += p_.pos[i];
    vm += p_.vel[i];
    dsum += 2 * p_.radius[i];
  }
  xm /= static_cast<double>(n);
  vm /= static_cast<double>(n);
  Eigen::Matrix3d xx = Eigen::Matrix3d::Zero(), vx = Eigen::Matrix3d::Zero();
  Eigen::Vector3d lo = p_.pos[first], hi = p_.pos[first];
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (p_.removed[i]) continue;
    const Eigen::Vector3d x = p_.pos[i] - xm, v = p_.vel[i] - vm;
    xx += x * x.transpose();
    vx += v * x.transpose();
    lo = lo.cwiseMin((p_.pos[i].array() - p_.radius[i]).matrix());
    hi = hi.cwiseMax((p_.pos[i].array() + p_.radius[i]).matrix());
  }
  const Eigen::Matrix3d L = vx * xx.completeOrthogonalDecomposition().pseudoInverse();
  const Eigen::Matrix3d D = 0.5 * (L + L.transpose());
  const Eigen::Matrix3d Dd = D - D.trace() / 3 * Eigen::Matrix3d::Identity();
  const double rate = std::sqrt(2 * (Dd.array() * Dd.array()).sum());
  // Mean stress p = tr(σ)/3 with σ = (1/V)·Σ f ⊗ l over sphere contacts (l: branch 1 → 2, f on 2).
  double tr = 0;
  for (const auto& h : hist_) {
    if (!h.real || h.b >= kWallBase) continue;
    const Eigen::Vector3d f = h.fn * h.normal + h.shear_force;
    tr += f.dot(p_.pos[h.b] - p_.pos[h.a]);
  }
  const double volume = (hi - lo).prod();
  const double pressure = tr / 3 / volume;
  if (!(pressure > 0) || !(volume > 0)) return std::numeric_limits<double>::quiet_NaN();
  return rate * (dsum / static_cast<double>(n)) / std::sqrt(pressure / cfg_.material.density);
}

Eigen::Matrix3d Simulation::wall_contact_moment(std::size_t first, std::size_t count) const {
  // Wall pairs: the sphere is the law's body 2 and receives Fn n + Fs (n from the wall to it).
  auto term = [](const ContactHistory& h) -> Eigen::Matrix3d {
    return h.point * (h.fn * h.normal + h.shear_force).transpose();
  };
  auto mine = [&](const ContactHistory& h) {
    return h.real && h.b >= kWallBase && h.b - kWallBase >= first &&
           h.b - kWallBase < first + count;
  };
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  if (!domain_ || roles_.empty() || gathered_) {
    for (const auto& h : hist_)
      if (mine(h)) m += term(h);
    return m;
  }
  // Under a domain (collective): each sphere's wall contacts are its owner's; their terms,
  // merged in pair order from every process, are added in it, as one process adds them.
  std::vector<double> records;
  for (const auto& h : hist_) {
    if (!mine(h)) continue;
    const Eigen::Matrix3d t = term(h);
    records.push_back(static_cast<double>(h.a));
    records.insert(records.end(), t.data(), t.data() + 9);
  }
  const std::vector<double> all = domain_->merge_records(records, 10);
  for (std::size_t j = 0; j + 10 <= all.size(); j += 10)
    m += Eigen::Map<const Eigen::Matrix3d>(&all[j + 1]);
  return m;
}

double Simulation::unbalanced_force() const {
  double sum_f = 0;
  std::size_t nf = 0;
  for (std::size_t i = 0; i < p_.size(); ++i) {
    if (p_.fixed[i]) continue;
    sum_f += (p_.force[i] + p_.mass[i] * cfg_.gravity).norm();
    ++nf;
  }
  // Clumps count as bodies (their members are fixed, so skipped above, as in YADE).
  for (const auto& c : clumps_) {
    Eigen::Vector3d f = c.mass * cfg_.gravity;
    for (const std::uint32_t i : c.members) f += p_.force[i];
    sum_f += f.norm();
    ++nf;
  }
  double sum_c = 0;
  std::size_t nc = 0;
  for (const auto& h : hist_) {
    if (!h.real) continue;
    sum_c += (h.fn * h.normal + h.shear_force).norm();
    ++nc;
  }
  if (nf == 0 || nc == 0 || sum_c == 0) return std::numeric_limits<double>::quiet_NaN();
  return (sum_f / static_cast<double>(nf)) / (sum_c / static_cast<double>(nc));
}

Simulation::Measures Simulation::approximate_measures(bool kinetic_in_contact) const {
  const bool split = domain_ && !roles_.empty() && !gathered_;
  // The contacts' Σ|f|, number and elastic energy, each counted at the owner of its first body.
  std::vector<double> c(3, 0.0);
  std::vector<std::uint8_t> touching(kinetic_in_contact ? p_.size() : 0, 0);
  for (std::size_t k = 0; k < hist_.size(); ++k) {
    const auto& h = hist_[k];
    if (!h.real) continue;
    if (kinetic_in_contact) {  // (an owned body's contacts are all here)
      touching[h.a] = 1;
      if (h.b < kWallBase) touching[h.b] = 1;
    }
    if (split && roles_[h.a] != kOwned) continue;
    c[0] += (h.fn * h.normal + h.shear_force).norm();
    c[1] += 1;
    c[2] += contact_elastic_energy(k).sum();
  }
  if (split) domain_->add_over_processes(c);
  // The free bodies' Σ|F|, number and kinetic energy (each process's own, summed over them).
  const auto b = owned_sums<3>(
      [&](std::size_t i, double* t) {
        const bool free = !p_.fixed[i];
        t[0] = free ? (p_.force[i] + p_.mass[i] * cfg_.gravity).norm() : 0.0;
        t[1] = free ? 1.0 : 0.0;
        t[2] = p_.clump[i] >= 0 || (kinetic_in_contact && !touching[i])
                   ? 0.0
                   : particle_kinetic_energy(i);
      },
      [&](std::size_t k, double* t) {
        const ClumpBody& cl = clumps_[k];
        Eigen::Vector3d f = cl.mass * cfg_.gravity;
        bool touches = !kinetic_in_contact;
        for (const std::uint32_t m : cl.members) {
          f += p_.force[m];
          touches = touches || touching[m] != 0;
        }
        t[0] = f.norm();
        t[1] = 1.0;
        t[2] = touches ? clump_kinetic_energy(cl) : 0.0;
      },
      false);
  Measures m;
  m.unbalanced_force = b[1] == 0 || c[1] == 0 || c[0] == 0
                           ? std::numeric_limits<double>::quiet_NaN()
                           : (b[0] / b[1]) / (c[0] / c[1]);
  m.kinetic_J = b[2];
  m.elastic_J = c[2];
  m.contacts = static_cast<std::size_t>(c[1]);
  return m;
}

Eigen::Vector3d Simulation::contact_elastic_energy(std::size_t k) const {
  const auto& h = hist_[k];
  const auto& p = params_[k];
  Eigen::Vector3d e = Eigen::Vector3d::Zero();  // normal, shear, rolling (J)
  if (cfg_.law == ContactLaw::HertzMindlin) {   // (kn, ks hold kno, kso: Fn = kno·δ^1.5)
    e[0] = 0.4 * p.kn * std::pow(h.overlap, 2.5);
    const double ks = p.ks * std::sqrt(h.overlap);
    if (ks > 0) e[1] = 0.5 * h.shear_force.squaredNorm() / ks;
    return e;
  }
  e[0] = 0.5 * h.fn * h.fn / p.kn;
  if (p.ks > 0) e[1] = 0.5 * h.shear_force.squaredNorm() / p.ks;
  if (p.kr > 0) e[2] = 0.5 * h.bending.squaredNorm() / p.kr;
  return e;
}

void Simulation::drop_clumps(const std::vector<std::uint8_t>& gone) {
  std::vector<std::int32_t> renumber(clumps_.size(), -1);
  std::vector<ClumpBody> kept;
  for (std::size_t k = 0; k < clumps_.size(); ++k) {
    if (gone[k]) continue;
    renumber[k] = static_cast<std::int32_t>(kept.size());
    kept.push_back(std::move(clumps_[k]));
  }
  for (std::size_t i = 0; i < p_.size(); ++i)
    if (p_.clump[i] >= 0) p_.clump[i] = renumber[static_cast<std::size_t>(p_.clump[i])];
  clumps_ = std::move(kept);
}

void Simulation::remove_particles(const std::vector<std::size_t>& indices) {
  const std::size_t n = p_.size();
  std::vector<std::uint8_t> gone(n, 0), clump_gone(clumps_.size(), 0);
  for (const std::size_t i : indices) {
    if (i >= n) throw std::invalid_argument("no particle " + std::to_string(i));
    if (p_.removed[i]) continue;
    gone[i] = 1;
    if (p_.clump[i] >= 0) {
      const auto c = static_cast<std::size_t>(p_.clump[i]);
      clump_gone[c] = 1;
      for (const std::uint32_t m : clumps_[c].members) gone[m] = 1;
    }
  }
  // The energy they take away: their kinetic energy (a clump's as a rigid body) and the elastic
  // energy of their contacts, which end now. (Under a domain every process removes the same
  // particles, and the energy is counted once: by the owner of a body, or of a contact's first
  // body, as the ledger's particle terms are; the counts and masses on every process.)
  const bool split = !roles_.empty();
  for (std::size_t k = 0; k < hist_.size(); ++k) {
    auto& h = hist_[k];
    if (!h.real || !(gone[h.a] || (h.b < kWallBase && gone[h.b]))) continue;
    if (!split || roles_[h.a] == kOwned) ledger_.outflow += contact_elastic_energy(k).sum();
    h.real = false;
  }
  for (std::size_t c = 0; c < clumps_.size(); ++c) {
    if (!clump_gone[c]) continue;
    if (clump_owned(c))
      ledger_.outflow += 0.5 * clumps_[c].mass * clumps_[c].vel.squaredNorm() +
                         0.5 * clumps_[c].angvel.dot(clumps_[c].angmom);
    removed_mass_ += clumps_[c].mass;  // (the clump's, not its members' summed)
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!gone[i]) continue;
    if (!split || roles_[i] == kOwned) {
      retire(i);
      continue;
    }
    if (p_.clump[i] < 0) removed_mass_ += p_.mass[i];  // (retire's, but for the energy)
    freeze(i);
    ++removed_count_;
  }
  drop_clumps(clump_gone);
  invalidate_neighbors();
}

const EnergyLedger& Simulation::energy() {
  ledger_.kinetic = kinetic_energy();
  ledger_.elastic_normal = ledger_.elastic_shear = ledger_.elastic_rolling = 0;
  for (std::size_t k = 0; k < hist_.size(); ++k) {
    if (!hist_[k].real) continue;
    const Eigen::Vector3d e = contact_elastic_energy(k);
    ledger_.elastic_normal += e[0];
    ledger_.elastic_shear += e[1];
    ledger_.elastic_rolling += e[2];
  }
  if (!ledger_started_) {
    ledger_started_ = true;
    ledger_.initial = ledger_.stored();
    if (step_ == 0) {
      // Overlaps present in the initial packing become contacts in the first step: their
      // normal elastic energy ½·Kn·u² belongs to the initial state.
      if (nl_.stale(p_, walls_, cell_ptr(), walls_dirty_ ? nullptr : &moving_walls_)) {
        if (domain_)
          rebuild_local({}, true);  // (this process's own: not a collective rebuild)
        else
          rebuild_neighbors();
      }
      for (std::size_t k = 0; k < nl_.pairs.size(); ++k) {
        ContactGeometry g;
        BodyMotion m1, m2;
        if (!pair_geometry(k, g, m1, m2)) continue;
        if (g.penetration > 0)
          ledger_.initial += cfg_.law == ContactLaw::HertzMindlin
                                 ? 0.4 * params_[k].kn * std::pow(g.penetration, 2.5)
                                 : 0.5 * params_[k].kn * g.penetration * g.penetration;
      }
    }
  }
  return ledger_;
}

void Simulation::check_energy() {
  // In a periodic cell the ledger does not carry the work of the cell's deformation (the mean
  // field is imposed, not a load): the check would fire on a correct run.
  if (periodic_) return;
  const auto& e = energy();
  const double turnover =
      e.stored() + e.dissipated() + std::abs(e.gravity_work) + std::abs(e.wall_work) + e.initial;
  if (turnover > 0 && std::abs(e.residual()) > cfg_.max_energy_residual * turnover)
    throw BlowUp("step " + std::to_string(step_) + ": energy ledger residual " +
                 std::to_string(e.residual()) + " J exceeds " +
                 std::to_string(cfg_.max_energy_residual) + " of the energy turnover " +
                 std::to_string(turnover) + " J");
}

Frame Simulation::frame() const {
  Frame f = frame_head();
  Frame piece;
  // (one piece: every particle and every pair)
  frame_piece(0, std::max<std::size_t>({p_.size(), hist_.size(), 1}), piece);
  f.particles = std::move(piece.particles);
  f.contacts = std::move(piece.contacts);
  return f;
}

bool Simulation::frame_piece(std::size_t i, std::size_t rows, Frame& piece) const {
  if (rows == 0) throw std::invalid_argument("frame_piece: rows must be positive");
  const std::size_t n = p_.size(), np = hist_.size();
  const std::size_t i0 = std::min(n, i * rows), i1 = std::min(n, i0 + rows);
  piece.particles.reserve(piece.particles.size() + (i1 - i0));
  for (std::size_t j = i0; j < i1; ++j) {
    if (p_.removed[j]) continue;  // (left through the outlet)
    auto& q = piece.particles.emplace_back();
    q.id = p_.id[j];
    q.position = periodic_ ? cell_.wrap(p_.pos[j]) : p_.pos[j];
    q.radius = p_.radius[j];
    // In a cell the velocity carries the mean flow L·x at the unwrapped position; the image in
    // the cell moves with v − L·(x − x_wrapped) (YADE's image shift velocity), so that the
    // frame's velocities are a field over its wrapped positions.
    q.velocity = periodic_ ? Eigen::Vector3d(p_.vel[j] - cell_.vel_grad * (p_.pos[j] - q.position))
                           : p_.vel[j];
    q.angular_velocity = p_.angvel[j];
    q.orientation = p_.ori[j];
    q.rotation = p_.rot[j];
    q.mass = p_.mass[j];
    q.material_id = p_.material[j];
    q.clump_id = p_.clump[j] >= 0 ? clumps_[static_cast<std::size_t>(p_.clump[j])].id : -1;
  }
  const std::size_t k0 = std::min(np, i * rows), k1 = std::min(np, k0 + rows);
  std::size_t real = 0;
  for (std::size_t k = k0; k < k1; ++k) real += hist_[k].real;
  piece.contacts.reserve(piece.contacts.size() + real);
  for (std::size_t k = k0; k < k1; ++k) {
    const auto& h = hist_[k];
    if (!h.real) continue;
    Contact c;
    if (h.b >= kWallBase) {
      c.id1 = wall_id(h.b - kWallBase);
      c.id2 = p_.id[h.a];
    } else {
      c.id1 = p_.id[h.a];
      c.id2 = p_.id[h.b];
    }
    c.point = h.point;
    c.normal = h.normal;
    c.normal_force = h.fn * h.normal;
    c.shear_force = h.shear_force;
    c.bending_moment = h.bending;
    c.twisting_moment = h.twist;
    c.overlap = h.overlap;
    piece.contacts.push_back(c);
  }
  return i1 < n || k1 < np;
}

Frame Simulation::frame_head() const {
  Frame f;
  f.time = time_;
  f.step = step_;
  f.dt = cfg_.dt;
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    const auto& ws = walls_[w];
    Wall wall;
    wall.id = wall_id(w);
    wall.kind = ws.spec.shape == WallShape::Box      ? WallKind::Box
                : ws.spec.shape == WallShape::Facets ? WallKind::Facet
                                                     : WallKind::Plane;
    wall.a = ws.pos;
    wall.b = ws.spec.shape == WallShape::Box      ? ws.spec.half_extents
             : ws.spec.shape == WallShape::Facets ? ws.facets.at(0).normal.eigen()
                                                  : ws.normal;
    wall.force = ws.force;
    wall.torque = ws.torque;
    f.walls.push_back(wall);
  }
  if (facet_forces_)  // per-triangle forces of the facet walls, at each triangle's incircle centre
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      const auto& ws = walls_[w];
      for (std::size_t k = 0; k < ws.facet_force.size(); ++k) {
        FacetLoad l;
        l.wall_id = wall_id(w);
        l.facet = static_cast<std::int32_t>(k);
        l.centroid = ws.pos + ws.facets[k].offset.eigen();
        l.force = ws.facet_force[k];
        f.facet_loads.push_back(l);
      }
    }
  f.clumps.reserve(clumps_.size());
  for (const auto& c : clumps_) {
    auto& q = f.clumps.emplace_back();
    q.id = c.id;
    q.template_name = c.template_name;
    q.position = c.pos;
    q.orientation = c.ori;
    q.velocity = c.vel;
    q.angular_velocity = c.angvel;
    q.mass = c.mass;
    q.principal_inertia = c.inertia;
  }
  if (periodic_) {  // the cell, with the positions wrapped into it
    f.domain.periodic = true;
    f.domain.cell = cell_.hsize;
    f.domain.velocity_gradient = cell_.vel_grad;  // the one the velocities carry
    f.domain.lo = Eigen::Vector3d::Zero();
    f.domain.hi = cell_.hsize.rowwise().sum();
    f.two_d = planar_;
    return f;
  }
  // The spheres' bounds (particle_bounds of the whole frame, without building it).
  const auto [lo, hi] = sphere_bounds(
      p_.size(), [&](std::size_t i) -> const Eigen::Vector3d& { return p_.pos[i]; },
      [&](std::size_t i) { return p_.radius[i]; },
      [&](std::size_t i) { return p_.removed[i] != 0; });
  f.domain.lo = lo;
  f.domain.hi = hi;
  return f;
}

// ------------------------------------------------------------------ checkpoints

namespace {
constexpr char kMagic[8] = {'G', 'S', 'C', 'K', 'P', 'T', '0', '7'};
constexpr char kMagicV06[8] = {'G', 'S', 'C', 'K', 'P', 'T', '0', '6'};  // (no cell servo)
constexpr char kMagicV05[8] = {'G', 'S', 'C', 'K', 'P', 'T', '0', '5'};  // (no periodic cell)
constexpr char kMagicV04[8] = {'G', 'S', 'C', 'K', 'P', 'T', '0', '4'};  // (no wall rotation)
constexpr char kMagicV03[8] = {'G', 'S', 'C', 'K', 'P', 'T', '0', '3'};  // (no clumps)

template <class T>
void put(std::ostream& o, const T& v) {
  o.write(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void get(std::istream& i, T& v, const std::string& file) {
  i.read(reinterpret_cast<char*>(&v), sizeof(T));
  if (!i) throw InputError(file, "truncated checkpoint");
}
template <class T>
void put_vec(std::ostream& o, const std::vector<T>& v) {
  put(o, static_cast<std::uint64_t>(v.size()));
  o.write(reinterpret_cast<const char*>(v.data()),
          static_cast<std::streamsize>(v.size() * sizeof(T)));
}
template <class T>
void get_vec(std::istream& i, std::vector<T>& v, std::size_t expect, const std::string& file) {
  std::uint64_t n = 0;
  get(i, n, file);
  if (n != expect)
    throw InputError(file, "checkpoint does not match the scene (array length)", std::to_string(n));
  v.resize(n);
  i.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T)));
  if (!i) throw InputError(file, "truncated checkpoint");
}
// A contact's history in the checkpoint: the record of format 07 (176 bytes: the pair, `real`
// and 7 zero bytes, normal, shear force, bending, twist, point, fn, overlap, and three doubles
// kept as zero), field by field, whatever the layout of ContactHistory in memory.
constexpr std::size_t kHistoryRecord = 176;
void put_history(std::ostream& o, const ContactHistory& h) {
  char rec[kHistoryRecord] = {};
  char* x = rec;
  auto w = [&x](const auto& v) {
    std::memcpy(x, &v, sizeof v);
    x += sizeof v;
  };
  w(h.a);
  w(h.b);
  w(static_cast<std::uint8_t>(h.real ? 1 : 0));
  x += 7;
  for (const Eigen::Vector3d* v : {&h.normal, &h.shear_force, &h.bending, &h.twist, &h.point})
    for (int c = 0; c < 3; ++c) w((*v)(c));
  w(h.fn);
  w(h.overlap);
  o.write(rec, kHistoryRecord);
}
void get_history(std::istream& i, ContactHistory& h, const std::string& file) {
  char rec[kHistoryRecord];
  i.read(rec, kHistoryRecord);
  if (!i) throw InputError(file, "truncated checkpoint");
  const char* x = rec;
  auto r = [&x](auto& v) {
    std::memcpy(&v, x, sizeof v);
    x += sizeof v;
  };
  r(h.a);
  r(h.b);
  std::uint8_t real = 0;
  r(real);
  h.real = real != 0;
  x += 7;
  for (Eigen::Vector3d* v : {&h.normal, &h.shear_force, &h.bending, &h.twist, &h.point})
    for (int c = 0; c < 3; ++c) r((*v)(c));
  r(h.fn);
  r(h.overlap);
}
}  // namespace

void Simulation::save_checkpoint(const std::filesystem::path& path,
                                 const std::string& extra) const {
  AtomicOutput out(path);
  {
    std::ofstream o(out.temp_path(), std::ios::binary);
    o.write(kMagic, 8);
    put(o, step_);
    put(o, time_);
    put(o, ledger_);
    put(o, static_cast<std::uint8_t>(ledger_started_));
    put_vec(o, p_.pos);
    put_vec(o, p_.vel);
    put_vec(o, p_.angvel);
    put_vec(o, p_.rot);
    put_vec(o, p_.ori);
    put_vec(o, p_.fixed);
    put_vec(o, p_.rot_blocked);
    put_vec(o, p_.external_force);
    put(o, cfg_.material.friction_deg);
    put(o, cfg_.damping);
    put(o, cfg_.gravity);
    put(o, static_cast<std::uint64_t>(walls_.size()));
    for (const auto& w : walls_) {
      put(o, w.pos);
      put(o, w.spec.half_extents);  // a test may size its walls when loading starts (clamps)
      put(o, w.normal);
      put(o, w.vel);
      put(o, static_cast<std::uint8_t>(w.active));
      put(o, w.force);  // loads of the last step: what a servo reads before the next one
      put(o, w.torque);
      put(o, w.contact_stiffness);
      put(o, static_cast<std::uint64_t>(w.contacts));
      put(o, w.ori);
      put(o, w.rot_center);
    }
    // Contact histories of real contacts, sorted by pair.
    std::vector<ContactHistory> real;
    for (const auto& h : hist_)
      if (h.real) real.push_back(h);
    put(o, static_cast<std::uint64_t>(real.size()));
    for (const auto& h : real) put_history(o, h);
    put(o, static_cast<std::uint64_t>(clumps_.size()));
    for (const auto& c : clumps_) {
      put(o, c.pos);
      put(o, c.ori);
      put(o, c.vel);
      put(o, c.angvel);
      put(o, c.angmom);
    }
    put_vec(o, p_.removed);
    put(o, static_cast<std::uint64_t>(removed_count_));
    put(o, removed_mass_);
    put(o, static_cast<std::uint8_t>(periodic_));
    if (periodic_) {
      put(o, cell_.hsize);
      put(o, cell_.trsf);
      put(o, cell_.vel_grad);
      put(o, cell_.next_vel_grad);
      put(o, static_cast<std::uint8_t>(cell_.vel_grad_changed));
      put(o, cell_.prev_vel_grad);
      put(o, cell_.prev_hsize);
      put(o, cell_.vgrad_times_prev_h);
      put(o, static_cast<std::uint8_t>(cell_servo_.has_value()));
      if (cell_servo_) {
        for (const bool b : cell_servo_->stress) put(o, static_cast<std::uint8_t>(b));
        put(o, cell_servo_->target);
        put(o, cell_servo_->gain);
        put(o, cell_servo_->max_rate);
        put(o, cell_servo_->stiffness_fraction);
        put(o, servo_base_gradient_);
      }
    }
    put(o, static_cast<std::uint64_t>(extra.size()));
    o.write(extra.data(), static_cast<std::streamsize>(extra.size()));
    if (!o.flush()) throw InputError(path.string(), "cannot write checkpoint");
  }
  out.commit();
}

std::string Simulation::load_checkpoint(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, "cannot open checkpoint");
  char magic[8];
  in.read(magic, 8);
  const bool v03 = in && std::memcmp(magic, kMagicV03, 8) == 0;
  const bool v04 = in && std::memcmp(magic, kMagicV04, 8) == 0;
  const bool v05 = in && std::memcmp(magic, kMagicV05, 8) == 0;
  const bool v06 = in && std::memcmp(magic, kMagicV06, 8) == 0;
  if (!in || (!v03 && !v04 && !v05 && !v06 && std::memcmp(magic, kMagic, 8) != 0))
    throw InputError(file, "not a granoscope checkpoint");
  get(in, step_, file);
  get(in, time_, file);
  get(in, ledger_, file);
  std::uint8_t started = 0;
  get(in, started, file);
  ledger_started_ = started != 0;
  const std::size_t n = p_.size();
  get_vec(in, p_.pos, n, file);
  get_vec(in, p_.vel, n, file);
  get_vec(in, p_.angvel, n, file);
  get_vec(in, p_.rot, n, file);
  get_vec(in, p_.ori, n, file);
  get_vec(in, p_.fixed, n, file);
  get_vec(in, p_.rot_blocked, n, file);
  get_vec(in, p_.external_force, n, file);
  get(in, cfg_.material.friction_deg, file);
  get(in, cfg_.damping, file);
  get(in, cfg_.gravity, file);
  std::uint64_t nw = 0;
  get(in, nw, file);
  if (nw != walls_.size())
    throw InputError(file, "checkpoint does not match the scene (walls)", std::to_string(nw));
  for (auto& w : walls_) {
    get(in, w.pos, file);
    get(in, w.spec.half_extents, file);
    get(in, w.normal, file);
    get(in, w.vel, file);
    std::uint8_t active = 1;
    get(in, active, file);
    w.active = active != 0;
    get(in, w.force, file);
    get(in, w.torque, file);
    get(in, w.contact_stiffness, file);
    std::uint64_t contacts = 0;
    get(in, contacts, file);
    w.contacts = static_cast<std::size_t>(contacts);
    if (v03 || v04) {  // (walls did not rotate about a centre)
      w.rot_center = w.pos - (w.spec.center - w.spec.rotation_center);
    } else {
      get(in, w.ori, file);
      get(in, w.rot_center, file);
    }
    if (w.spec.shape == WallShape::Facets && w.spec.angular_velocity.norm() > 0)
      place_rotated_facets(w);
  }
  std::uint64_t nc = 0;
  get(in, nc, file);
  if (nc > (1ull << 32))
    throw InputError(file, "corrupt checkpoint (contact count)", std::to_string(nc));
  std::vector<ContactHistory> real(nc);
  for (auto& h : real) get_history(in, h, file);
  std::uint64_t ncl = 0;
  if (!v03) get(in, ncl, file);
  // A run that removed clumps (remove_particles) saved fewer than the scene has: those whose
  // members the saved removal flags mark gone are dropped below, before the counts are compared.
  if (ncl > clumps_.size())
    throw InputError(file, "checkpoint does not match the scene (clumps)", std::to_string(ncl));
  std::vector<ClumpBody> saved(static_cast<std::size_t>(ncl));
  for (auto& c : saved) {
    get(in, c.pos, file);
    get(in, c.ori, file);
    get(in, c.vel, file);
    get(in, c.angvel, file);
    get(in, c.angmom, file);
  }
  if (!v03) {
    get_vec(in, p_.removed, n, file);
    std::uint64_t removed = 0;
    get(in, removed, file);
    removed_count_ = static_cast<std::size_t>(removed);
    get(in, removed_mass_, file);
  }
  if (ncl < clumps_.size()) {
    std::vector<std::uint8_t> gone(clumps_.size(), 0);
    for (std::size_t k = 0; k < clumps_.size(); ++k)
      gone[k] = std::all_of(clumps_[k].members.begin(), clumps_[k].members.end(),
                            [&](std::uint32_t i) { return p_.removed[i] == 1; });
    drop_clumps(gone);
    if (ncl != clumps_.size())
      throw InputError(file, "checkpoint does not match the scene (clumps)", std::to_string(ncl));
  }
  for (std::size_t k = 0; k < clumps_.size(); ++k) {
    ClumpBody& c = clumps_[k];
    c.pos = saved[k].pos;
    c.ori = saved[k].ori;
    c.vel = saved[k].vel;
    c.angvel = saved[k].angvel;
    c.angmom = saved[k].angmom;
  }
  std::uint8_t periodic = 0;
  if (!v03 && !v04 && !v05) get(in, periodic, file);
  if ((periodic != 0) != periodic_)
    throw InputError(file, "checkpoint does not match the scene (periodic cell)",
                     std::to_string(periodic));
  if (periodic_) {
    get(in, cell_.hsize, file);
    get(in, cell_.trsf, file);
    get(in, cell_.vel_grad, file);
    get(in, cell_.next_vel_grad, file);
    std::uint8_t changed = 0;
    get(in, changed, file);
    cell_.vel_grad_changed = changed != 0;
    get(in, cell_.prev_vel_grad, file);
    get(in, cell_.prev_hsize, file);
    get(in, cell_.vgrad_times_prev_h, file);
    std::uint8_t has_servo = 0;
    if (!v06) {  // (a v06 checkpoint keeps the scene's servo, set before loading)
      get(in, has_servo, file);
      if (has_servo > 1) throw InputError(file, "corrupt checkpoint (cell servo flag)");
      if (has_servo) {
        CellServo sv;
        for (auto& b : sv.stress) {
          std::uint8_t v = 0;
          get(in, v, file);
          b = v != 0;
        }
        get(in, sv.target, file);
        get(in, sv.gain, file);
        get(in, sv.max_rate, file);
        get(in, sv.stiffness_fraction, file);
        get(in, servo_base_gradient_, file);
        cell_servo_ = sv;
      } else {
        cell_servo_.reset();
      }
    }
    if (!cell_.hsize.allFinite() || !(cell_.hsize.determinant() > 0))
      throw InputError(file, "corrupt checkpoint (periodic cell)");
  }
  std::uint64_t extra_size = 0;
  get(in, extra_size, file);
  if (extra_size > (1ull << 30))
    throw InputError(file, "corrupt checkpoint (scene state size)", std::to_string(extra_size));
  std::string extra(extra_size, '\0');
  in.read(extra.data(), static_cast<std::streamsize>(extra_size));
  if (!in) throw InputError(file, "truncated checkpoint");
  // Rebuild the neighbour list from the restored state and put the histories back.
  nl_.build(p_, walls_, cell_ptr(), planar_);
  attach_histories(&real);
  walls_dirty_ = true;
  return extra;
}

}  // namespace gs::solver
