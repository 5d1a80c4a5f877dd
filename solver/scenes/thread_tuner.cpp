#include "thread_tuner.hpp"

#include <algorithm>

namespace gs::solver {

ThreadTuner::ThreadTuner(int start, int most, ThreadTunerOptions options) : o_(options) {
  most = std::max(1, most);
  for (int c = 1; c < most; c *= 2) counts_.push_back(c);
  counts_.push_back(most);
  steps_.assign(counts_.size(), 0);
  while (current_ + 1 < counts_.size() && counts_[current_ + 1] <= start) ++current_;
  upward_ = current_ == 0;  // (from the top the first probe goes down, from 1 up)
  if (counts_.size() == 1) phase_ = Phase::Hold;  // (nothing to compare)
}

std::int64_t ThreadTuner::steps_on(int count) const {
  const auto it = std::find(counts_.begin(), counts_.end(), count);
  return it == counts_.end() ? 0 : steps_[static_cast<std::size_t>(it - counts_.begin())];
}

void ThreadTuner::start_window() {
  window_seconds_ = 0;
  window_count_ = 0;
}

int ThreadTuner::record(double seconds) {
  ++steps_[current_];
  if (counts_.size() == 1) return threads();
  window_seconds_ += seconds;
  ++window_count_;
  const bool done = phase_ == Phase::Hold
                        ? window_seconds_ >= o_.hold_s
                        : window_seconds_ >= o_.window_s && window_count_ >= o_.window_steps;
  if (!done) return threads();
  const double per_step = window_seconds_ / static_cast<double>(window_count_);
  switch (phase_) {
    case Phase::Hold:  // measure the held count afresh before a neighbour is tried
      phase_ = Phase::Measure;
      break;
    case Phase::Measure:  // try the neighbour in this turn's direction (the other at an end)
      measured_ = per_step;
      held_ = current_;
      if (current_ == 0) upward_ = true;
      if (current_ + 1 == counts_.size()) upward_ = false;
      current_ = upward_ ? current_ + 1 : current_ - 1;
      upward_ = !upward_;  // (the next comparison looks the other way)
      phase_ = Phase::Probe;
      break;
    case Phase::Probe:  // keep the probed count only if it was faster by the margin
      ++comparisons_;
      if (per_step < (1 - o_.margin) * measured_)
        ++switches_;
      else
        current_ = held_;
      phase_ = Phase::Hold;
      break;
  }
  start_window();
  return threads();
}

}  // namespace gs::solver
