// Domain decomposition over MPI (issue 23; docs/scale.md): the particles are split into bricks,
// a grid of processes along the sides of the packing's box chosen for the least cut area (one
// row of slabs along the longest side when the count is prime; in a periodic cell along its
// base vectors that wrap, in the fractional coordinates, the last brick next to the first
// across the boundary). The sides are cut at equal counts, nested (x, then y within each slab,
// then z). Each process owns the particles in its brick and holds those within 2 r_max + skin
// of it as ghosts. Every process builds the same Simulation from the scene (the particle arrays
// are replicated, indexed as in a one-process run), and steps only its part:
//  * each step, the owners send their ghosts' new states to the processes that hold them;
//  * at each neighbour-list rebuild (when any process's list is stale), the owned states are
//    gathered by all, particles migrate to the brick they are in, and the contact histories go
//    to the processes that compute their pairs from then on;
//  * each step, the walls' loads are summed over processes; where the run reads them as it
//    steps (servos, a laboratory programme), over every process's wall contacts in pair order,
//    as one process sums them.
// A clump is owned by the process of its centre of mass, with its members (ghosted by their
// own positions; the ghost layer is wider by the clumps' extent).
// A pair is computed by the owner of each of its bodies, from the same states and history, and
// each particle's loads are summed in pair order as in one process: the trajectories are the
// one-process run's bit for bit. Output (gather) puts the whole state on process 0.
#pragma once

#include <array>

#include <mpi.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "domain.hpp"
#include "simulation.hpp"

namespace gs::solver {

/// The bricks along x, y and z for `processes` processes (their product), for a box of sides
/// `extent`: the grid with the least cut area Σ_k (g_k − 1)·A_k (A_k the box's section across
/// k), only along the sides that may be cut; ties go to more bricks along the earlier sides.
std::array<int, 3> brick_grid(int processes, const Eigen::Vector3d& extent,
                              const std::array<bool, 3>& cuttable);

class MpiDomain : public Domain {
 public:
  explicit MpiDomain(MPI_Comm comm = MPI_COMM_WORLD);
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const override { return rank_ == 0; }

  /// Splits `sim`'s particles (the same on every process) into bricks of equal counts (the
  /// grid brick_grid gives; counted over the particles in the scene, not those removed or
  /// waiting to enter), and makes `sim` step only this process's part. Collective.
  void attach(Simulation& sim);
  /// Bricks along x, y and z (their product is size()). In a periodic cell the bricks are cut
  /// in the fractional coordinates s = H⁻¹·x wrapped into [0, 1): they deform with the cell.
  const std::array<int, 3>& grid() const { return grid_; }
  bool periodic() const { return periodic_; }
  double ghost_width() const { return ghost_width_; }
  /// Owning process of each particle (as of the last rebuild).
  const std::vector<int>& owners() const { return owner_; }

  /// Collective: process 0's simulation then holds the whole state (every particle's, every
  /// contact's, the ledger's particle terms summed, an outlet's latest removals counted) as a
  /// one-process run would, for output and checkpoints; the others keep theirs. release()
  /// undoes it.
  void gather(Simulation& sim) override;
  /// Process 0 back to the very state it stepped with before gather() (its part, its
  /// neighbour list and everything built from it), but for the ledger, which keeps the sums.
  /// (Rebuilding its part's list instead would build it from the particles' present positions,
  /// not from those of the last rebuild, as the other processes' are: other candidate pairs,
  /// other deferred facet pairs, and once in a while another contact; an output cadence then
  /// changed the run.)
  void release(Simulation& sim) override;
  /// Bytes this process sent in the halo exchanges since attach (per-step traffic), and at
  /// rebuilds (migration and histories).
  std::uint64_t halo_bytes() const { return halo_bytes_; }
  std::uint64_t rebuild_bytes() const { return rebuild_bytes_; }
  std::int64_t rebuilds() const { return rebuilds_; }

  /// True when any process's `mine` is (an OR over processes).
  bool any(bool mine);
  bool stale(bool mine) override;
  void rebuild(Simulation& sim) override;
  void reduce_walls(Simulation& sim) override;
  void reduce_cell(Eigen::Matrix3d& stress, Eigen::Vector3d* stiffness) override;
  void agree(double& max_overlap_ratio, bool& finite) override;
  void exchange(Simulation& sim) override;
  void share(std::vector<double>& values) override;
  void add_over_processes(std::vector<double>& sums) override;
  void broadcast(std::vector<double>& values) override;
  std::vector<double> merge_records(const std::vector<double>& mine, std::size_t size) override;

 private:
  /// A brick's bounds in the coordinates the bricks cut (±∞, or 0 and 1 in a cell, where a
  /// side is not cut).
  struct Brick {
    Eigen::Vector3d lo, hi;
  };
  /// The process whose brick holds coordinates c (coords()).
  int brick_of(const Eigen::Vector3d& c) const;
  /// Whether a particle at coordinates c is within the ghost width of process r's brick.
  bool near_brick(const Eigen::Vector3d& c, int r) const;
  /// The coordinates the bricks cut: x, or in a cell the wrapped s = H⁻¹·x (with the cell of
  /// the last rebuild: update_cell()).
  Eigen::Vector3d coords(const Eigen::Vector3d& x) const;
  /// Each particle's owner now: its brick's process (c: coords() of each particle), a clump
  /// member its clump's (the process of the clump's centre of mass).
  std::vector<int> owners_of(const Simulation& sim, const std::vector<Eigen::Vector3d>& c) const;
  /// In a cell: H⁻¹ and the ghost width in each s_k from the cell as it is now.
  void update_cell(const Simulation& sim);
  /// Whom this process sends its ghosts to and receives its ghosts from (c: coords() of each
  /// particle).
  void set_lists(const std::vector<Eigen::Vector3d>& c);

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::array<int, 3> grid_{1, 1, 1};
  // cuts_[k][node]: the cuts along k of the node-th piece of the levels before (x: one piece;
  // y: each slab along x; z: each of those pieces), grid_[k] − 1 of them
  std::array<std::vector<std::vector<double>>, 3> cuts_;
  std::vector<Brick> bricks_;  // per process
  double ghost_width_ = 0;
  bool periodic_ = false;
  Eigen::Matrix3d inv_ = Eigen::Matrix3d::Identity();  // H⁻¹ (a cell)
  Eigen::Vector3d reach_ = Eigen::Vector3d::Zero();    // the ghost width in each coordinate
  std::vector<int> owner_;
  std::unique_ptr<Simulation> stepping_;  // process 0's own simulation, kept while gathered
  std::vector<std::vector<std::uint32_t>> send_, recv_;  // per process: particle indices
  std::vector<double> send_buf_, recv_buf_;
  std::uint64_t halo_bytes_ = 0, rebuild_bytes_ = 0;
  std::int64_t rebuilds_ = 0;
  bool split_ = false;  // the scene split since attach (the first rebuild does it)
};

}  // namespace gs::solver
