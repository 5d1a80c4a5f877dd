// Domain decomposition over MPI (issue 23; docs/scale.md): the particles are split into slabs
// along the longest axis of the packing (in a periodic cell: along its widest base vector, in
// the fractional coordinate, the last slab next to the first across the boundary), each process
// owns the particles in its slab and holds those within 2 r_max + skin of it as ghosts. Every
// process builds the same Simulation from the scene (the particle arrays are replicated, indexed as
// in a one-process run), and steps only its part:
//  * each step, the owners send their ghosts' new states to the processes that hold them;
//  * at each neighbour-list rebuild (when any process's list is stale), the owned states are
//    gathered by all, particles migrate to the slab they are in, and the contact histories go to
//    the processes that compute their pairs from then on;
//  * the walls' loads are summed over processes each step, so that servos see the whole.
// A clump is owned by the process of its centre of mass, with its members (ghosted by their
// own positions; the ghost layer is wider by the clumps' extent).
// A pair is computed by the owner of each of its bodies, from the same states and history, and
// each particle's loads are summed in pair order as in one process: the trajectories are the
// one-process run's bit for bit. Output (gather) puts the whole state on process 0.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <vector>

#include "domain.hpp"
#include "simulation.hpp"

namespace gs::solver {

class MpiDomain : public Domain {
 public:
  explicit MpiDomain(MPI_Comm comm = MPI_COMM_WORLD);
  int rank() const { return rank_; }
  int size() const { return size_; }

  /// Splits `sim`'s particles (the same on every process) into slabs of equal counts along the
  /// longest axis of their box, and makes `sim` step only this process's part. Collective.
  /// Throws std::invalid_argument for what the decomposition does not handle (see
  /// Simulation::set_domain).
  void attach(Simulation& sim);
  /// The slab boundaries along axis(): size() - 1 increasing values, in m; in a periodic cell
  /// in the fractional coordinate s_k = (H⁻¹·x)_k of the cell's base vector k = axis(), wrapped
  /// into [0, 1) (the slabs deform with the cell, and the first and last are neighbours).
  const std::vector<double>& cuts() const { return cuts_; }
  int axis() const { return axis_; }
  bool periodic() const { return periodic_; }
  double ghost_width() const { return ghost_width_; }
  /// Owning process of each particle (as of the last rebuild).
  const std::vector<int>& owners() const { return owner_; }

  /// Collective: process 0's simulation then holds the whole state (every particle's, every
  /// contact's, the ledger's particle terms summed) as a one-process run would, for output and
  /// checkpoints; the others keep theirs. release() undoes it.
  void gather(Simulation& sim);
  /// Process 0 back to its own part after gather().
  void release(Simulation& sim);
  /// Bytes this process sent in the halo exchanges since attach (per-step traffic), and at
  /// rebuilds (migration and histories).
  std::uint64_t halo_bytes() const { return halo_bytes_; }
  std::uint64_t rebuild_bytes() const { return rebuild_bytes_; }
  std::int64_t rebuilds() const { return rebuilds_; }

  /// True when any process's `mine` is (an OR over processes).
  bool any(bool mine);
  bool stale(bool mine) override;
  void rebuild(Simulation& sim) override;
  void reduce_walls(std::vector<WallState>& walls) override;
  void reduce_cell(Eigen::Matrix3d& stress, Eigen::Vector3d* stiffness) override;
  void agree(double& max_overlap_ratio, bool& finite) override;
  void exchange(Simulation& sim) override;

 private:
  int slab_of(double x) const;
  /// Whether a particle at coordinate x is within the ghost width of process r's slab.
  bool near_slab(double x, int r) const;
  /// The coordinate the slabs cut: x_k, or in a cell the wrapped s_k (with the cell of the
  /// last rebuild: update_cell()).
  double coord(const Eigen::Vector3d& x) const;
  /// Each particle's owner now: its slab's process, a clump member its clump's (the process of
  /// the clump's centre of mass).
  std::vector<int> owners_of(const Simulation& sim) const;
  /// In a cell: H⁻¹ and the ghost width in s_k from the cell as it is now.
  void update_cell(const Simulation& sim);
  /// Whom this process sends its ghosts to and receives its ghosts from (coords: coord() of
  /// each particle).
  void set_lists(const std::vector<double>& coords);

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  int axis_ = 0;
  std::vector<double> cuts_;
  double ghost_width_ = 0;
  bool periodic_ = false;
  Eigen::RowVector3d inv_row_ = Eigen::RowVector3d::Zero();  // row axis_ of H⁻¹ (a cell)
  double reach_ = 0;  // the ghost width in the coordinate the slabs cut
  std::vector<int> owner_;
  std::vector<std::uint8_t> my_roles_;                   // process 0's part, kept while gathered
  std::vector<std::vector<std::uint32_t>> send_, recv_;  // per process: particle indices
  std::vector<double> send_buf_, recv_buf_;
  std::uint64_t halo_bytes_ = 0, rebuild_bytes_ = 0;
  std::int64_t rebuilds_ = 0;
  bool split_ = false;  // the scene split since attach (the first rebuild does it)
};

}  // namespace gs::solver
