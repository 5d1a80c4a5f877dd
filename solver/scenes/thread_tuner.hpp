#pragma once
// `threads = "auto"`: the thread count of a run chosen by timing its own steps.
//
// The engine gives the same bits on any number of threads (docs/physics.md), so a run may change
// its count between any two steps without changing a result. Which count is faster depends on
// the scene and on the machine's other load: on a quiet 2-core machine two threads ran the
// laptop scenes of 1 000-2 800 particles 6-28 % faster than one, but with a second run beside
// them each run's two threads spun at the step's barriers while the other run held a core, and
// both ran 4-33 times slower than on one thread each (docs/scale.md, "Picked by timing"). The
// tuner measures the steps on its current count and on a neighbouring one, one short window
// each, keeps the faster, and measures again after a hold, so that a run adapts when another
// starts or ends beside it.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace gs::solver {

struct ThreadTunerOptions {
  double window_s = 0.25;  // a measurement lasts at least this long (wall-clock) ...
  int window_steps = 3;    // ... and this many steps
  double hold_s = 10.0;    // between the end of one comparison and the next
  double margin = 0.02;    // the probed count must be this much faster (relative) to be kept
};

/// Chooses among 1, 2, 4, … threads and `most` (the counts() ladder) from the wall-clock time of
/// each step: a hill climb that compares its count with the next lower and the next higher in
/// turn, so that two runs on a machine of many cores can each settle on part of it.
class ThreadTuner {
 public:
  /// Starts on the ladder's count nearest `start` from below (1 or `most`: the size rule's);
  /// `most` ≤ 1 never changes the count.
  ThreadTuner(int start, int most, ThreadTunerOptions options = {});

  /// The thread count for the next step.
  int threads() const { return counts_[current_]; }
  /// The step just taken on threads() took `seconds`; returns the count for the next step.
  int record(double seconds);
  /// The counts it chooses among (increasing), and the steps recorded on each.
  const std::vector<int>& counts() const { return counts_; }
  std::int64_t steps_on(int count) const;
  /// Comparisons made, and how many of them changed the count.
  int comparisons() const { return comparisons_; }
  int switches() const { return switches_; }

 private:
  enum class Phase { Measure, Probe, Hold };
  void start_window();

  std::vector<int> counts_;
  std::vector<std::int64_t> steps_;
  std::size_t current_ = 0;  // index in counts_
  std::size_t held_ = 0;     // the count measured before a probe
  bool upward_ = false;      // the direction of the next probe
  ThreadTunerOptions o_;
  Phase phase_ = Phase::Measure;
  double window_seconds_ = 0;  // this phase's time and steps so far
  std::int64_t window_count_ = 0;
  double measured_ = 0;  // seconds per step on the held count, from the Measure window
  int comparisons_ = 0, switches_ = 0;
};

}  // namespace gs::solver
