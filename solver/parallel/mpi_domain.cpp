#include "mpi_domain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace gs::solver {

namespace {

// A particle's state as the contact law and the integrator read it: position, velocity,
// angular velocity, rotation vector, orientation (w, x, y, z).
constexpr int kState = 16;
// With the loads (for output on process 0).
constexpr int kFullState = kState + 6;
// A contact history.
constexpr int kHistory = 20;

void put3(double*& o, const Eigen::Vector3d& v) {
  *o++ = v[0];
  *o++ = v[1];
  *o++ = v[2];
}
Eigen::Vector3d get3(const double*& i) {
  const Eigen::Vector3d v(i[0], i[1], i[2]);
  i += 3;
  return v;
}

void pack_state(const ParticleState& p, std::size_t k, double*& o, bool loads) {
  put3(o, p.pos[k]);
  put3(o, p.vel[k]);
  put3(o, p.angvel[k]);
  put3(o, p.rot[k]);
  const Eigen::Quaterniond& q = p.ori[k];
  *o++ = q.w();
  *o++ = q.x();
  *o++ = q.y();
  *o++ = q.z();
  if (loads) {
    put3(o, p.force[k]);
    put3(o, p.torque[k]);
  }
}

void unpack_state(ParticleState& p, std::size_t k, const double*& i, bool loads) {
  p.pos[k] = get3(i);
  p.vel[k] = get3(i);
  p.angvel[k] = get3(i);
  p.rot[k] = get3(i);
  p.ori[k] = Eigen::Quaterniond(i[0], i[1], i[2], i[3]);
  i += 4;
  if (loads) {
    p.force[k] = get3(i);
    p.torque[k] = get3(i);
  }
}

void pack_history(const ContactHistory& h, std::vector<double>& o) {
  const std::size_t at = o.size();
  o.resize(at + kHistory);
  double* x = o.data() + at;
  *x++ = h.a;
  *x++ = h.b;
  *x++ = h.real ? 1.0 : 0.0;
  put3(x, h.normal);
  put3(x, h.shear_force);
  put3(x, h.bending);
  put3(x, h.twist);
  put3(x, h.point);
  *x++ = h.fn;
  *x++ = h.overlap;
}

std::vector<ContactHistory> unpack_histories(const std::vector<double>& in) {
  std::vector<ContactHistory> out(in.size() / kHistory);
  const double* x = in.data();
  for (ContactHistory& h : out) {
    h.a = static_cast<std::uint32_t>(x[0]);
    h.b = static_cast<std::uint32_t>(x[1]);
    h.real = x[2] != 0;
    x += 3;
    h.normal = get3(x);
    h.shear_force = get3(x);
    h.bending = get3(x);
    h.twist = get3(x);
    h.point = get3(x);
    h.fn = *x++;
    h.overlap = *x++;
  }
  return out;
}

/// The ledger's terms summed over particles and contacts (the walls' work is the same on every
/// process, from the summed wall loads).
void zero_particle_terms(EnergyLedger& e) {
  e.friction_dissipation = e.rolling_dissipation = e.damping_dissipation = 0;
  e.viscous_dissipation = e.gravity_work = e.external_work = e.outflow = 0;
}

void check(int code, const char* what) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + what + " failed");
}

/// This process's owned particles: each its index and state (with the loads: for output).
std::vector<double> pack_owned(const ParticleState& p, const std::vector<int>& owner, int rank,
                               bool loads) {
  std::vector<double> out;
  const int width = 1 + (loads ? kFullState : kState);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (owner[i] != rank) continue;
    const std::size_t at = out.size();
    out.resize(at + static_cast<std::size_t>(width));
    double* o = out.data() + at;
    *o++ = static_cast<double>(i);
    pack_state(p, i, o, loads);
  }
  return out;
}

/// A clump's state (what the integrator advances): index, centre of mass, velocity, spin,
/// angular momentum, orientation (w, x, y, z).
constexpr int kClump = 1 + 16;

/// This process's clumps (a clump is its first member's owner's): each its index and state.
std::vector<double> pack_owned_clumps(const std::vector<ClumpBody>& clumps,
                                      const std::vector<int>& owner, int rank) {
  std::vector<double> out;
  for (std::size_t k = 0; k < clumps.size(); ++k) {
    const ClumpBody& c = clumps[k];
    if (c.members.empty() || owner[c.members[0]] != rank) continue;
    const std::size_t at = out.size();
    out.resize(at + kClump);
    double* o = out.data() + at;
    *o++ = static_cast<double>(k);
    put3(o, c.pos);
    put3(o, c.vel);
    put3(o, c.angvel);
    put3(o, c.angmom);
    *o++ = c.ori.w();
    *o++ = c.ori.x();
    *o++ = c.ori.y();
    *o++ = c.ori.z();
  }
  return out;
}

void unpack_clumps(std::vector<ClumpBody>& clumps, const std::vector<double>& in) {
  for (const double* i = in.data(); i < in.data() + in.size();) {
    ClumpBody& c = clumps[static_cast<std::size_t>(*i++)];
    c.pos = get3(i);
    c.vel = get3(i);
    c.angvel = get3(i);
    c.angmom = get3(i);
    c.ori = Eigen::Quaterniond(i[0], i[1], i[2], i[3]);
    i += 4;
  }
}

/// Counts of `mine` from every process and their offsets (what the v-collectives take).
int counts_of(MPI_Comm comm, int size, int root, const std::vector<double>& mine,
              std::vector<int>& counts, std::vector<int>& displs) {
  const int n = static_cast<int>(mine.size());
  counts.assign(static_cast<std::size_t>(size), 0);
  displs.assign(static_cast<std::size_t>(size), 0);
  if (root < 0)
    check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm), "allgather");
  else
    check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, root, comm), "gather");
  int total = 0;
  for (int r = 0; r < size; ++r) {
    displs[static_cast<std::size_t>(r)] = total;
    total += counts[static_cast<std::size_t>(r)];
  }
  return total;
}

/// Every process's `mine` to every process, concatenated in process order.
std::vector<double> all_gather(MPI_Comm comm, int size, const std::vector<double>& mine) {
  std::vector<int> counts, displs;
  std::vector<double> all(
      static_cast<std::size_t>(counts_of(comm, size, -1, mine, counts, displs)));
  check(MPI_Allgatherv(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(),
                       counts.data(), displs.data(), MPI_DOUBLE, comm),
        "allgatherv");
  return all;
}

/// Every process's `mine` on process 0, concatenated in process order (empty elsewhere).
std::vector<double> gather_at_root(MPI_Comm comm, int size, int rank,
                                   const std::vector<double>& mine) {
  std::vector<int> counts, displs;
  const int total = counts_of(comm, size, 0, mine, counts, displs);
  std::vector<double> all(rank == 0 ? static_cast<std::size_t>(total) : 0);
  check(MPI_Gatherv(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(),
                    counts.data(), displs.data(), MPI_DOUBLE, 0, comm),
        "gatherv");
  return all;
}

/// `to[r]` sent to process r; returns what every process sent to this one, in process order.
std::vector<double> all_to_all(MPI_Comm comm, int size, const std::vector<std::vector<double>>& to,
                               std::uint64_t& bytes) {
  const auto n = static_cast<std::size_t>(size);
  std::vector<int> sc(n), sd(n), rc(n), rd(n);
  std::vector<double> flat;
  for (std::size_t r = 0; r < n; ++r) {
    sd[r] = static_cast<int>(flat.size());
    sc[r] = static_cast<int>(to[r].size());
    flat.insert(flat.end(), to[r].begin(), to[r].end());
    bytes += to[r].size() * sizeof(double);
  }
  check(MPI_Alltoall(sc.data(), 1, MPI_INT, rc.data(), 1, MPI_INT, comm), "alltoall");
  int total = 0;
  for (std::size_t r = 0; r < n; ++r) {
    rd[r] = total;
    total += rc[r];
  }
  std::vector<double> in(static_cast<std::size_t>(total));
  check(MPI_Alltoallv(flat.data(), sc.data(), sd.data(), MPI_DOUBLE, in.data(), rc.data(),
                      rd.data(), MPI_DOUBLE, comm),
        "alltoallv");
  return in;
}

}  // namespace

MpiDomain::MpiDomain(MPI_Comm comm) : comm_(comm) {
  check(MPI_Comm_rank(comm_, &rank_), "comm_rank");
  check(MPI_Comm_size(comm_, &size_), "comm_size");
}

int MpiDomain::brick_of(const Eigen::Vector3d& c) const {
  // Down the nested cuts: the slab along x, then the piece of it along y, then along z.
  std::size_t node = 0;
  for (int k = 0; k < 3; ++k) {
    const std::vector<double>& cuts = cuts_[static_cast<std::size_t>(k)][node];
    const auto i =
        static_cast<std::size_t>(std::upper_bound(cuts.begin(), cuts.end(), c[k]) - cuts.begin());
    node = node * static_cast<std::size_t>(grid_[static_cast<std::size_t>(k)]) + i;
  }
  return static_cast<int>(node);
}

bool MpiDomain::near_brick(const Eigen::Vector3d& c, int r) const {
  const Brick& box = bricks_[static_cast<std::size_t>(r)];
  for (int k = 0; k < 3; ++k) {
    if (grid_[static_cast<std::size_t>(k)] == 1) continue;  // (not cut along k)
    const double lo = box.lo[k] - reach_[k], hi = box.hi[k] + reach_[k];
    bool near = c[k] > lo && c[k] < hi;
    // (in a cell the bricks are of [0, 1) along k, the first next to the last: the images too;
    // the images along each axis shift independently, so the test is one per axis)
    if (periodic_)
      near = near || (c[k] - 1 > lo && c[k] - 1 < hi) || (c[k] + 1 > lo && c[k] + 1 < hi);
    if (!near) return false;
  }
  return true;
}

std::vector<int> MpiDomain::owners_of(const Simulation& sim,
                                      const std::vector<Eigen::Vector3d>& c) const {
  std::vector<int> owner(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) owner[i] = brick_of(c[i]);
  for (const ClumpBody& c : sim.clumps()) {
    const int o = brick_of(coords(c.pos));
    for (const std::uint32_t m : c.members) owner[m] = o;
  }
  return owner;
}

Eigen::Vector3d MpiDomain::coords(const Eigen::Vector3d& x) const {
  if (!periodic_) return x;
  const Eigen::Vector3d s = inv_ * x;
  return s - s.array().floor().matrix();
}

void MpiDomain::update_cell(const Simulation& sim) {
  if (!periodic_) {
    reach_ = Eigen::Vector3d::Constant(ghost_width_);
    return;
  }
  // The planes s_k = const are 1/|row k of H⁻¹| apart: a distance d is d·|row k| in s_k.
  inv_ = sim.cell().hsize.inverse();
  for (int k = 0; k < 3; ++k) reach_[k] = ghost_width_ * inv_.row(k).norm();
}

std::array<int, 3> brick_grid(int processes, const Eigen::Vector3d& extent,
                              const std::array<bool, 3>& cuttable) {
  // The cut faces' area Σ_k (g_k − 1)·A_k, A_k the box's section across k, is what the ghost
  // layers grow with; the smallest wins, ties to the larger counts on the earlier axes (so one
  // slab cut goes along the longest side, the first of equal ones).
  std::array<int, 3> best{1, 1, 1};
  double best_area = HUGE_VAL;
  const Eigen::Vector3d section(extent[1] * extent[2], extent[0] * extent[2],
                                extent[0] * extent[1]);
  for (int gx = processes; gx >= 1; --gx) {
    if (processes % gx != 0 || (gx > 1 && !cuttable[0])) continue;
    for (int gy = processes / gx; gy >= 1; --gy) {
      if ((processes / gx) % gy != 0 || (gy > 1 && !cuttable[1])) continue;
      const int gz = processes / gx / gy;
      if (gz > 1 && !cuttable[2]) continue;
      const double area = (gx - 1) * section[0] + (gy - 1) * section[1] + (gz - 1) * section[2];
      if (area < best_area) {
        best_area = area;
        best = {gx, gy, gz};
      }
    }
  }
  return best;
}

void MpiDomain::attach(Simulation& sim) {
  const ParticleState& p = sim.particles();
  const std::size_t n = p.size();
  // The bricks: a grid of processes along the sides of the particles' box (in a cell: its base
  // vectors that wrap, in the fractional coordinates), each side cut at equal counts (midway
  // between neighbouring centres), nested: the slabs along x, each slab's particles along y,
  // each piece's along z. Every process computes the same from the same particles.
  // (the box and the counts of the particles in the scene: those waiting to enter sit at one
  // point until they do, those removed where they left; the ghost layer fits every radius)
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  double rmax = 0;
  std::vector<std::uint32_t> in_scene;
  in_scene.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    rmax = std::max(rmax, p.radius[i]);
    if (p.removed[i] != 0) continue;
    lo = lo.cwiseMin(p.pos[i]);
    hi = hi.cwiseMax(p.pos[i]);
    in_scene.push_back(static_cast<std::uint32_t>(i));
  }
  periodic_ = sim.periodic();
  Eigen::Vector3d extent = !in_scene.empty() ? Eigen::Vector3d(hi - lo) : Eigen::Vector3d::Zero();
  std::array<bool, 3> cuttable{true, true, true};
  if (periodic_) {
    extent = sim.cell().widths();
    cuttable[2] = !sim.planar();  // (the third base vector of a planar cell does not wrap)
  }
  // A clump's members are owned with it (by the process of its centre of mass), so a member
  // may lie up to the clump's extent outside its owner's brick: the ghost layer grows by it.
  double clump_extent = 0;
  for (const ClumpBody& c : sim.clumps())
    for (const std::uint32_t m : c.members)
      clump_extent = std::max(clump_extent, (p.pos[m] - c.pos).norm());
  ghost_width_ = (2 * rmax + sim.skin() + clump_extent) * (1 + 1e-9);
  // (the centres' box grown by a ghost layer: a flat packing still has sections to compare)
  if (!periodic_) extent.array() += ghost_width_;
  grid_ = brick_grid(size_, extent, cuttable);
  update_cell(sim);
  std::vector<Eigen::Vector3d> c(n);
  for (std::size_t i = 0; i < n; ++i) c[i] = coords(p.pos[i]);
  std::vector<std::vector<std::uint32_t>> groups(1, std::move(in_scene));
  const double open_lo = periodic_ ? 0.0 : -HUGE_VAL, open_hi = periodic_ ? 1.0 : HUGE_VAL;
  std::vector<Brick> boxes(
      1, Brick{Eigen::Vector3d::Constant(open_lo), Eigen::Vector3d::Constant(open_hi)});
  for (int k = 0; k < 3; ++k) {
    const int g = grid_[static_cast<std::size_t>(k)];
    auto& level = cuts_[static_cast<std::size_t>(k)];
    level.assign(groups.size(), {});
    std::vector<std::vector<std::uint32_t>> next;
    std::vector<Brick> next_boxes;
    for (std::size_t node = 0; node < groups.size(); ++node) {
      std::vector<double> x;
      x.reserve(groups[node].size());
      for (const std::uint32_t i : groups[node]) x.push_back(c[i][k]);
      std::sort(x.begin(), x.end());
      const std::size_t m = x.size();
      for (int r = 1; r < g; ++r) {
        const std::size_t at = m * static_cast<std::size_t>(r) / static_cast<std::size_t>(g);
        level[node].push_back(at == 0 ? -HUGE_VAL : at >= m ? HUGE_VAL : 0.5 * (x[at - 1] + x[at]));
      }
      const std::vector<double>& cuts = level[node];
      for (int r = 0; r < g; ++r) {
        Brick box = boxes[node];
        if (r > 0) box.lo[k] = cuts[static_cast<std::size_t>(r - 1)];
        if (r < g - 1) box.hi[k] = cuts[static_cast<std::size_t>(r)];
        next_boxes.push_back(box);
        next.emplace_back();
      }
      for (const std::uint32_t i : groups[node]) {
        const auto r = static_cast<std::size_t>(
            std::upper_bound(cuts.begin(), cuts.end(), c[i][k]) - cuts.begin());
        next[next.size() - static_cast<std::size_t>(g) + r].push_back(i);
      }
    }
    groups = std::move(next);
    boxes = std::move(next_boxes);
  }
  bricks_ = std::move(boxes);
  // A pair is a candidate when its centres are closer than r_a + r_b + skin: the ghosts of a
  // brick are the particles within 2 r_max + skin of it (a hair more, for the candidates' own
  // relative slack; ghost_width_ above).
  owner_ = owners_of(sim, c);
  // The ledger's particle terms: process 0 keeps the totals (those of a checkpoint too), the
  // others count what they add from now on (summed on process 0 at each gather).
  if (rank_ != 0) zero_particle_terms(sim.ledger_terms());
  split_ = false;
  send_.assign(static_cast<std::size_t>(size_), {});
  recv_.assign(static_cast<std::size_t>(size_), {});
  sim.set_domain(this);  // (throws for what is not handled; the first step rebuilds)
}

bool MpiDomain::stale(bool mine) {
  return any(mine || !split_);
}  // (the first step splits)

bool MpiDomain::any(bool mine) {
  int v = mine ? 1 : 0, all = 0;
  check(MPI_Allreduce(&v, &all, 1, MPI_INT, MPI_LOR, comm_), "allreduce");
  return all != 0;
}

void MpiDomain::agree(double& max_overlap_ratio, bool& finite) {
  double in[2] = {max_overlap_ratio, finite ? 0.0 : 1.0}, out[2];
  // (a NaN overlap ratio means a blow-up: counted as infinite)
  if (!(in[0] == in[0])) in[0] = HUGE_VAL;
  check(MPI_Allreduce(in, out, 2, MPI_DOUBLE, MPI_MAX, comm_), "allreduce");
  max_overlap_ratio = out[0];
  finite = out[1] == 0;
}

void MpiDomain::reduce_cell(Eigen::Matrix3d& stress, Eigen::Vector3d* stiffness) {
  // As the walls': each process's sums to all, added in process order.
  constexpr int kC = 12;
  double mine[kC] = {};
  for (int k = 0; k < 9; ++k) mine[k] = stress(k / 3, k % 3);
  if (stiffness)
    for (int k = 0; k < 3; ++k) mine[9 + k] = (*stiffness)[k];
  std::vector<double> all(kC * static_cast<std::size_t>(size_));
  check(MPI_Allgather(mine, kC, MPI_DOUBLE, all.data(), kC, MPI_DOUBLE, comm_), "allgather");
  double s[kC] = {};
  for (int r = 0; r < size_; ++r)
    for (int k = 0; k < kC; ++k) s[k] += all[static_cast<std::size_t>(r) * kC + k];
  for (int k = 0; k < 9; ++k) stress(k / 3, k % 3) = s[k];
  if (stiffness) *stiffness = Eigen::Vector3d(s[9], s[10], s[11]);
}

void MpiDomain::reduce_walls(Simulation& sim) {
  if (!sim.exact_wall_loads()) {
    // Each process's sums to all, added in process order: the same bits on every process
    // (within round-off of one process's sums; nothing reads them while the run steps).
    constexpr int kW = 8;
    const std::vector<WallState>& walls = sim.walls();
    std::vector<double> mine(walls.size() * kW);
    double* o = mine.data();
    for (const WallState& w : walls) {
      put3(o, w.force);
      put3(o, w.torque);
      *o++ = w.contact_stiffness;
      *o++ = static_cast<double>(w.contacts);
    }
    std::vector<double> all(mine.size() * static_cast<std::size_t>(size_));
    check(MPI_Allgather(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(),
                        static_cast<int>(mine.size()), MPI_DOUBLE, comm_),
          "allgather");
    std::vector<double> sums(mine.size(), 0.0);
    for (int r = 0; r < size_; ++r)
      for (std::size_t j = 0; j < mine.size(); ++j)
        sums[j] += all[static_cast<std::size_t>(r) * mine.size() + j];
    sim.set_wall_loads(sums);
    return;
  }
  // Every process's wall contacts to all, merged in pair order and summed in it: the bits one
  // process sums, the same on every process (servos and programmes read them; the meshes'
  // per-triangle forces are summed so too). Per step: the records of the touching wall
  // contacts, 13 doubles each.
  sim.sum_wall_load_records(merge_records(sim.wall_load_records(), Simulation::kWallRecord));
}

std::vector<double> MpiDomain::merge_records(const std::vector<double>& mine, std::size_t size) {
  halo_bytes_ += mine.size() * sizeof(double) * static_cast<std::size_t>(size_ - 1);
  const std::vector<double> all = all_gather(comm_, size_, mine);
  const std::size_t m = all.size() / size;
  std::vector<std::uint32_t> order(m);
  for (std::size_t i = 0; i < m; ++i) order[i] = static_cast<std::uint32_t>(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t x, std::uint32_t y) { return all[x * size] < all[y * size]; });
  std::vector<double> merged(all.size());
  for (std::size_t i = 0; i < m; ++i)
    std::copy_n(all.data() + order[i] * size, size, merged.data() + i * size);
  return merged;
}

void MpiDomain::set_lists(const std::vector<Eigen::Vector3d>& c) {
  send_.assign(static_cast<std::size_t>(size_), {});
  recv_.assign(static_cast<std::size_t>(size_), {});
  for (std::size_t i = 0; i < c.size(); ++i) {
    const Eigen::Vector3d& x = c[i];
    const int o = owner_[i];
    if (o == rank_) {
      for (int r = 0; r < size_; ++r)
        if (r != rank_ && near_brick(x, r))
          send_[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(i));
    } else if (near_brick(x, rank_)) {
      recv_[static_cast<std::size_t>(o)].push_back(static_cast<std::uint32_t>(i));
    }
  }
}

void MpiDomain::rebuild(Simulation& sim) {
  ParticleState& p = sim.particles();
  const std::size_t n = p.size();
  ++rebuilds_;
  split_ = true;
  // 1. Every owned state to every process (the particles may change hands).
  const std::vector<double> mine = pack_owned(p, owner_, rank_, false);
  rebuild_bytes_ += mine.size() * sizeof(double) * static_cast<std::size_t>(size_ - 1);
  const std::vector<double> all = all_gather(comm_, size_, mine);
  for (const double* x = all.data(); x < all.data() + all.size();) {
    const auto i = static_cast<std::size_t>(*x++);
    if (owner_[i] == rank_) {
      x += kState;
      continue;
    }
    unpack_state(p, i, x, false);
  }
  if (!sim.clumps().empty()) {  // and the clumps' (every process then has every state)
    const std::vector<double> mine_c = pack_owned_clumps(sim.clumps(), owner_, rank_);
    rebuild_bytes_ += mine_c.size() * sizeof(double) * static_cast<std::size_t>(size_ - 1);
    unpack_clumps(sim.clump_states(), all_gather(comm_, size_, mine_c));
  }
  sim.count_outflow();  // (an outlet's removals since the last rebuild, known here to all)
  // 2. The new owners, by the brick each particle (each clump's centre of mass) is in now (in a
  //    cell: as it is now).
  update_cell(sim);
  std::vector<Eigen::Vector3d> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = coords(p.pos[i]);
  std::vector<int> owner = owners_of(sim, x);
  // 3. Contact histories to the processes that compute their pairs from now on: each pair goes
  //    from the old owner of its first body (who computed it) to the new owners of its bodies.
  std::vector<std::vector<double>> to(static_cast<std::size_t>(size_));
  const auto& pairs = sim.pairs();
  const auto& hist = sim.histories();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [a, b] = pairs[k];
    if (!hist[k].real || owner_[a] != rank_) continue;
    const int ta = owner[a], tb = b < kWallBase ? owner[b] : ta;
    if (ta != rank_) pack_history(hist[k], to[static_cast<std::size_t>(ta)]);
    if (tb != ta && tb != rank_) pack_history(hist[k], to[static_cast<std::size_t>(tb)]);
  }
  const std::vector<ContactHistory> received =
      unpack_histories(all_to_all(comm_, size_, to, rebuild_bytes_));
  // 4. This process's part, its list, and whom it exchanges ghosts with until the next rebuild.
  owner_ = std::move(owner);
  std::vector<std::uint8_t> roles(n);
  for (std::size_t i = 0; i < n; ++i)
    roles[i] = owner_[i] == rank_ ? kOwned : near_brick(x[i], rank_) ? kGhost : kAbsent;
  sim.set_roles(std::move(roles));
  sim.rebuild_local(received);
  set_lists(x);
}

void MpiDomain::exchange(Simulation& sim) {
  ParticleState& p = sim.particles();
  const auto n = static_cast<std::size_t>(size_);
  std::size_t send_total = 0, recv_total = 0;
  for (std::size_t r = 0; r < n; ++r) {
    send_total += send_[r].size();
    recv_total += recv_[r].size();
  }
  send_buf_.resize(send_total * kState);
  recv_buf_.resize(recv_total * kState);
  std::vector<MPI_Request> requests;
  requests.reserve(2 * n);
  std::size_t at = 0;
  for (std::size_t r = 0; r < n; ++r) {
    if (recv_[r].empty()) continue;
    requests.emplace_back();
    check(MPI_Irecv(recv_buf_.data() + at, static_cast<int>(recv_[r].size() * kState), MPI_DOUBLE,
                    static_cast<int>(r), 7, comm_, &requests.back()),
          "irecv");
    at += recv_[r].size() * kState;
  }
  at = 0;
  for (std::size_t r = 0; r < n; ++r) {
    if (send_[r].empty()) continue;
    double* o = send_buf_.data() + at;
    for (const std::uint32_t i : send_[r]) pack_state(p, i, o, false);
    requests.emplace_back();
    check(MPI_Isend(send_buf_.data() + at, static_cast<int>(send_[r].size() * kState), MPI_DOUBLE,
                    static_cast<int>(r), 7, comm_, &requests.back()),
          "isend");
    at += send_[r].size() * kState;
  }
  halo_bytes_ += send_total * kState * sizeof(double);
  check(MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE),
        "waitall");
  const double* x = recv_buf_.data();
  for (std::size_t r = 0; r < n; ++r)
    for (const std::uint32_t i : recv_[r]) unpack_state(p, i, x, false);
}

void MpiDomain::share(std::vector<double>& values) {
  check(MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE,
                      MPI_SUM, comm_),
        "allreduce");
}

void MpiDomain::add_over_processes(std::vector<double>& sums) {
  const std::size_t m = sums.size();
  std::vector<double> all(m * static_cast<std::size_t>(size_));
  check(MPI_Allgather(sums.data(), static_cast<int>(m), MPI_DOUBLE, all.data(), static_cast<int>(m),
                      MPI_DOUBLE, comm_),
        "allgather");
  std::fill(sums.begin(), sums.end(), 0.0);
  for (int r = 0; r < size_; ++r)
    for (std::size_t j = 0; j < m; ++j) sums[j] += all[static_cast<std::size_t>(r) * m + j];
}

void MpiDomain::broadcast(std::vector<double>& values) {
  auto n = static_cast<std::uint64_t>(values.size());
  check(MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm_), "bcast");
  values.resize(static_cast<std::size_t>(n));
  check(MPI_Bcast(values.data(), static_cast<int>(n), MPI_DOUBLE, 0, comm_), "bcast");
}

void MpiDomain::gather(Simulation& sim) {
  if (rank_ == 0) stepping_ = std::make_unique<Simulation>(sim);  // (release() puts it back)
  sim.set_gathered(true);                                         // (no collective until release)
  ParticleState& p = sim.particles();
  // The owned states with their loads, and the real contacts whose first body is owned here.
  const std::vector<double> states = pack_owned(p, owner_, rank_, true);
  std::vector<double> hist;
  const auto& pairs = sim.pairs();
  const auto& h = sim.histories();
  for (std::size_t k = 0; k < pairs.size(); ++k)
    if (h[k].real && owner_[pairs[k].first] == rank_) pack_history(h[k], hist);
  const std::vector<double> all_states = gather_at_root(comm_, size_, rank_, states);
  const std::vector<double> all_hist = gather_at_root(comm_, size_, rank_, hist);
  if (!sim.clumps().empty()) {
    const std::vector<double> all_clumps =
        gather_at_root(comm_, size_, rank_, pack_owned_clumps(sim.clumps(), owner_, rank_));
    if (rank_ == 0) unpack_clumps(sim.clump_states(), all_clumps);
  }
  if (!sim.exact_wall_loads()) {
    // The meshes' per-triangle forces (for output), summed in process order; the step clears
    // and sums them anew, so process 0's own part need not be kept.
    std::vector<double> facets;
    for (const WallState& w : sim.walls())
      for (const Eigen::Vector3d& f : w.facet_force)
        facets.insert(facets.end(), f.data(), f.data() + 3);
    if (!facets.empty()) {
      const std::vector<double> all = gather_at_root(comm_, size_, rank_, facets);
      if (rank_ == 0) {
        std::fill(facets.begin(), facets.end(), 0.0);
        for (int r = 0; r < size_; ++r)
          for (std::size_t j = 0; j < facets.size(); ++j)
            facets[j] += all[static_cast<std::size_t>(r) * facets.size() + j];
        std::size_t j = 0;
        for (WallState& w : sim.mutable_walls())
          for (Eigen::Vector3d& f : w.facet_force) {
            f = Eigen::Vector3d(facets[j], facets[j + 1], facets[j + 2]);
            j += 3;
          }
      }
    }
  }
  // The ledger's particle terms (each process counted its own particles and their contacts);
  // the walls' work is the same on every process, from the summed wall loads.
  EnergyLedger& e = sim.ledger_terms();
  double terms[7] = {e.friction_dissipation,
                     e.rolling_dissipation,
                     e.damping_dissipation,
                     e.viscous_dissipation,
                     e.gravity_work,
                     e.external_work,
                     e.outflow};
  double sums[7] = {};
  check(MPI_Reduce(terms, sums, 7, MPI_DOUBLE, MPI_SUM, 0, comm_), "reduce");
  if (rank_ != 0) return zero_particle_terms(e);  // (counted on process 0 from now on)
  e.friction_dissipation = sums[0];
  e.rolling_dissipation = sums[1];
  e.damping_dissipation = sums[2];
  e.viscous_dissipation = sums[3];
  e.gravity_work = sums[4];
  e.external_work = sums[5];
  e.outflow = sums[6];
  for (const double* x = all_states.data(); x < all_states.data() + all_states.size();) {
    const auto i = static_cast<std::size_t>(*x++);
    unpack_state(p, i, x, true);
  }
  sim.set_roles({});
  sim.rebuild_local(unpack_histories(all_hist), true);
}

void MpiDomain::release(Simulation& sim) {
  sim.set_gathered(false);
  if (rank_ != 0 || !stepping_) return;
  sim.restore_keeping_ledger(std::move(*stepping_));  // (a copy from before the gather)
  stepping_.reset();
}

}  // namespace gs::solver
