// What the engine asks of a domain decomposition during a step (issue 23): the collective calls
// a process makes so that its part of the scene steps as the whole would. Implemented over MPI
// in solver/parallel/mpi_domain.hpp; without one (the default) a Simulation owns every particle.
#pragma once

#include <vector>

#include "dem_types.hpp"

namespace gs::solver {

class Simulation;

/// Roles of particles in a process (Simulation::set_roles).
enum ParticleRole : unsigned char {
  kAbsent = 0,  // held by other processes only: not in this process's contacts
  kGhost = 1,   // a copy of another process's particle, refreshed every step
  kOwned = 2,   // integrated here; the loads on it are complete here
};

class Domain {
 public:
  virtual ~Domain() = default;
  /// Whether the neighbour lists are rebuilt this step: when any process's own is stale
  /// (`mine`), so that every process rebuilds, and particles migrate, at the same steps.
  virtual bool stale(bool mine) = 0;
  /// The neighbour-list rebuild: particles migrate to their new owners, roles are set, the list
  /// is rebuilt (Simulation::rebuild_local) with the contact histories other processes held.
  virtual void rebuild(Simulation& sim) = 0;
  /// The walls' loads summed over processes (each process summed its own particles' contacts),
  /// the same bits on every process: where Simulation::exact_wall_loads(), every process's wall
  /// contacts merged in pair order and summed in it, the sums one process forms
  /// (Simulation::wall_load_records); else each process's sums added in process order.
  virtual void reduce_walls(Simulation& sim) = 0;
  /// A periodic cell's stress (and affine stiffness, if not null) summed over processes, each
  /// having summed its owned contacts (before the division by the volume).
  virtual void reduce_cell(Eigen::Matrix3d& stress, Eigen::Vector3d* stiffness) = 0;
  /// The largest overlap ratio and whether every state is finite, over processes (so that a
  /// blow-up stops every process at the same step).
  virtual void agree(double& max_overlap_ratio, bool& finite) = 0;
  /// After the integration: the owned particles' new states to the processes holding them as
  /// ghosts.
  virtual void exchange(Simulation& sim) = 0;
  /// Values each process set for its own bodies, zero elsewhere, to every process: an
  /// element-wise sum over processes, exact (every entry is non-zero on one process at most).
  virtual void share(std::vector<double>& values) = 0;
  /// Each process's `sums` replaced by their sums over processes, added in process order (the
  /// same bits on every process).
  virtual void add_over_processes(std::vector<double>& sums) = 0;
  /// Process 0's simulation then holds the whole assembly (every particle's state and loads,
  /// every contact), as one process's would; the others keep theirs. release() undoes it.
  virtual void gather(Simulation& sim) = 0;
  /// Whether this is process 0, the one that holds the whole after gather().
  virtual bool root() const = 0;
  virtual void release(Simulation& sim) = 0;
  /// Process 0's `values` (any length) to every process.
  virtual void broadcast(std::vector<double>& values) = 0;
  /// Every process's records (`size` doubles each, the first a particle index, in this
  /// process's pair order) to every process, merged in pair order: sorted by the particle,
  /// stably (a particle's records all come from one process, its owner).
  virtual std::vector<double> merge_records(const std::vector<double>& mine, std::size_t size) = 0;
};

}  // namespace gs::solver
