#pragma once
// A block run by a team of OpenMP threads, or by the calling thread alone when one is asked.
//
// A team of one is not free: libgomp ends its parallel region (and each loop without nowait)
// with a barrier whose last thread wakes the barrier's futex unconditionally, a system call
// even with no one waiting (measured: two a step, 2-4 % of the 1 000-sphere hopper's time on
// one thread). Called outside any parallel region, the block's worksharing constructs (omp
// for, single, barrier, critical) run orphaned: as a team of one, without those calls, and
// omp_get_num_threads() / omp_get_thread_num() give 1 and 0 as in a team of one.

namespace gs::solver {

template <class Block>
void run_on_team(int threads, Block&& block) {
  if (threads <= 1) {
    block();
    return;
  }
#pragma omp parallel num_threads(threads)
  block();
}

}  // namespace gs::solver
