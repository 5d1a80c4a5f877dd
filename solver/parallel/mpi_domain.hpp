// Domain decomposition over MPI (issue 23; docs/scale.md): the particles are split into slabs
// along the longest axis of the packing, each process owns the particles in its slab and holds
// those within 2 r_max + skin of it as ghosts. Every process builds the same Simulation from the
// scene (the particle arrays are replicated, indexed as in a one-process run), and steps only
// its part:
//  * each step, the owners send their ghosts' new states to the processes that hold them;
//  * at each neighbour-list rebuild (when any process's list is stale), the owned states are
//    gathered by all, particles migrate to the slab they are in, and the contact histories go to
//    the processes that compute their pairs from then on;
//  * the walls' loads are summed over processes each step, so that servos see the whole.
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
  /// The slab boundaries (m) along axis(): size() - 1 increasing values.
  const std::vector<double>& cuts() const { return cuts_; }
  int axis() const { return axis_; }
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
  void agree(double& max_overlap_ratio, bool& finite) override;
  void exchange(Simulation& sim) override;

 private:
  int slab_of(double x) const;
  /// Whether a particle at coordinate x is within the ghost width of process r's slab.
  bool near_slab(double x, int r) const;
  void set_lists(const Simulation& sim);

  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  int axis_ = 0;
  std::vector<double> cuts_;
  double ghost_width_ = 0;
  std::vector<int> owner_;
  std::vector<std::uint8_t> my_roles_;                   // process 0's part, kept while gathered
  std::vector<std::vector<std::uint32_t>> send_, recv_;  // per process: particle indices
  std::vector<double> send_buf_, recv_buf_;
  std::uint64_t halo_bytes_ = 0, rebuild_bytes_ = 0;
  std::int64_t rebuilds_ = 0;
  bool split_ = false;  // the scene split since attach (the first rebuild does it)
};

}  // namespace gs::solver
