#include "thread_tuner.hpp"

#include <algorithm>

namespace gs::solver {

ThreadTuner::ThreadTuner(int start, int most, ThreadTunerOptions options)
    : most_(std::max(1, most)), current_(std::clamp(start, 1, std::max(1, most))), o_(options) {
  if (current_ != 1) current_ = most_;
  if (most_ == 1) phase_ = Phase::Hold;  // (nothing to compare)
}

void ThreadTuner::start_window() {
  window_seconds_ = 0;
  window_count_ = 0;
}

int ThreadTuner::record(double seconds) {
  (current_ == 1 ? steps_one_ : steps_most_) += 1;
  if (most_ == 1) return current_;
  window_seconds_ += seconds;
  ++window_count_;
  const bool done = phase_ == Phase::Hold
                        ? window_seconds_ >= o_.hold_s
                        : window_seconds_ >= o_.window_s && window_count_ >= o_.window_steps;
  if (!done) return current_;
  const double per_step = window_seconds_ / static_cast<double>(window_count_);
  switch (phase_) {
    case Phase::Hold:  // measure the held count afresh before the other is tried
      phase_ = Phase::Measure;
      break;
    case Phase::Measure:  // try the other count
      measured_ = per_step;
      current_ = other();
      phase_ = Phase::Probe;
      break;
    case Phase::Probe:  // keep the probed count only if it was faster by the margin
      ++comparisons_;
      if (!(per_step < (1 - o_.margin) * measured_))
        current_ = other();
      else
        ++switches_;
      phase_ = Phase::Hold;
      break;
  }
  start_window();
  return current_;
}

}  // namespace gs::solver
