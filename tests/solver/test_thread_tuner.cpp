// `threads = "auto"`: the run's thread count picked by timing its steps (thread_tuner.hpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "scene_file.hpp"
#include "scene_run.hpp"
#include "text_parse.hpp"
#include "thread_tuner.hpp"

namespace {

using gs::solver::ThreadTuner;
using gs::solver::ThreadTunerOptions;

/// Feeds `tuner` steps that take `seconds(count)` on `count` threads until `steps` have been
/// recorded; returns the count after each step.
template <class Seconds>
std::vector<int> feed_by(ThreadTuner& tuner, Seconds seconds, int steps) {
  std::vector<int> counts;
  for (int i = 0; i < steps; ++i) counts.push_back(tuner.record(seconds(tuner.threads())));
  return counts;
}

/// The same with `one_s` on one thread and `most_s` on more.
std::vector<int> feed(ThreadTuner& tuner, double one_s, double most_s, int steps) {
  return feed_by(
      tuner, [&](int count) { return count == 1 ? one_s : most_s; }, steps);
}

ThreadTunerOptions windows() {
  ThreadTunerOptions o;
  o.window_s = 1.0;
  o.window_steps = 2;
  o.hold_s = 5.0;
  o.margin = 0.02;
  return o;
}

}  // namespace

// Exact answer, the contended machine (two threads four times slower than one, as when a second
// run holds the other core; times exact in binary): the tuner measures two steps of 0.5 s on two
// threads (1 s), tries one thread for eight steps of 0.125 s (1 s), keeps it, holds it for 40
// steps (5 s), measures it again (8 steps), tries two threads for two steps, goes back to one.
TEST(ThreadTuner, LeavesTwoThreadsThatAreSlowerThanOne) {
  ThreadTuner t(2, 2, windows());
  std::vector<int> c = feed(t, 0.125, 0.5, 2);
  EXPECT_EQ(c, (std::vector<int>{2, 1}));  // (the window's second step ends it: the probe)
  c = feed(t, 0.125, 0.5, 8);
  EXPECT_EQ(c.back(), 1);
  EXPECT_EQ(t.comparisons(), 1);
  EXPECT_EQ(t.switches(), 1);
  c = feed(t, 0.125, 0.5, 40 + 7);  // the hold, and the fresh measure but its last step
  for (const int n : c) EXPECT_EQ(n, 1);
  EXPECT_EQ(feed(t, 0.125, 0.5, 1).back(), 2);  // the measure's last step: the probe of two
  c = feed(t, 0.125, 0.5, 2);
  EXPECT_EQ(c, (std::vector<int>{2, 1}));  // two slower again: back to one
  EXPECT_EQ(t.comparisons(), 2);
  EXPECT_EQ(t.switches(), 1);
  EXPECT_EQ(t.steps_on(2), 4);
  EXPECT_EQ(t.steps_on(1), 8 + 47 + 1);
}

// Exact answer, the quiet machine: two threads 25 % faster (0.09375 s a step against 0.125 s)
// are taken from one after its 8-step measure and their 11-step probe, and kept at each later
// comparison (a cycle of 73 steps: a hold of 54 steps, a measure of 11, a probe of one thread
// of 8); two threads within the margin (1.6 % faster) are never taken.
TEST(ThreadTuner, TakesTwoThreadsThatAreFasterByTheMargin) {
  ThreadTuner t(1, 2, windows());
  feed(t, 0.125, 0.09375, 8 + 11);
  EXPECT_EQ(t.threads(), 2);
  EXPECT_EQ(t.comparisons(), 1);
  EXPECT_EQ(t.switches(), 1);
  feed(t, 0.125, 0.09375, 6 * 73 + 62);  // six cycles, and a hold and most of a measure
  EXPECT_EQ(t.threads(), 2);
  EXPECT_EQ(t.comparisons(), 7);
  EXPECT_EQ(t.switches(), 1);  // (each later probe of one thread went back to two)
  EXPECT_EQ(t.steps_on(1), 8 + 6 * 8);
  EXPECT_EQ(t.steps_on(2), 8 + 11 + 6 * 73 + 62 - (8 + 6 * 8));

  ThreadTuner close(1, 2, windows());
  feed(close, 0.125, 0.123, 1000);
  EXPECT_GT(close.comparisons(), 5);
  EXPECT_EQ(close.switches(), 0);
  EXPECT_EQ(close.threads(), 1);
}

// A machine of one core, or a start above the cores: nothing to choose, or the cores. The
// ladder is 1, 2, 4, … below the cores and the cores; a start between two counts takes the lower.
TEST(ThreadTuner, OneCoreNeverSwitchesAndTheStartIsClamped) {
  ThreadTuner t(1, 1, windows());
  const std::vector<int> c = feed(t, 0.125, 0.001, 100);
  for (const int n : c) EXPECT_EQ(n, 1);
  EXPECT_EQ(t.comparisons(), 0);
  EXPECT_EQ(t.steps_on(1), 100);
  EXPECT_EQ(t.counts(), (std::vector<int>{1}));
  EXPECT_EQ(ThreadTuner(8, 2).threads(), 2);
  EXPECT_EQ(ThreadTuner(0, 4).threads(), 1);
  EXPECT_EQ(ThreadTuner(3, 4).threads(), 2);
  EXPECT_EQ(ThreadTuner(1, 12).counts(), (std::vector<int>{1, 2, 4, 8, 12}));
  EXPECT_EQ(ThreadTuner(12, 12).threads(), 12);
  EXPECT_EQ(ThreadTuner(1, 2).counts(), (std::vector<int>{1, 2}));
}

// Exact answer, 8 cores shared with another run (times exact in binary): all 8 threads spin
// (0.5 s a step), 4 run best (0.125 s), 2 and 1 slower (0.25, 0.5). From 8 the tuner probes 4
// (kept), then 8 above it (slower: back), then 2 below it (slower: back), and stays on 4: it
// neither keeps the spinning count nor falls to one thread.
TEST(ThreadTuner, ClimbsToTheFastestCountOfManyCores) {
  auto seconds = [](int count) {
    switch (count) {
      case 1:
        return 0.5;
      case 2:
        return 0.25;
      case 4:
        return 0.125;
      default:
        return 0.5;
    }
  };
  ThreadTuner t(8, 8, windows());
  EXPECT_EQ(t.counts(), (std::vector<int>{1, 2, 4, 8}));
  feed_by(t, seconds, 2);  // measure 8 (two steps, 1 s): then the probe of 4
  EXPECT_EQ(t.threads(), 4);
  feed_by(t, seconds, 8);  // probe 4 (8 steps, 1 s): kept
  EXPECT_EQ(t.threads(), 4);
  EXPECT_EQ(t.switches(), 1);
  feed_by(t, seconds, 40 + 8);  // hold (5 s), measure 4: then the probe above, 8
  EXPECT_EQ(t.threads(), 8);
  feed_by(t, seconds, 2);  // probe 8: slower, back to 4
  EXPECT_EQ(t.threads(), 4);
  feed_by(t, seconds, 40 + 8);  // hold, measure 4: then the probe below, 2
  EXPECT_EQ(t.threads(), 2);
  feed_by(t, seconds, 4);  // probe 2 (4 steps, 1 s): slower, back to 4
  EXPECT_EQ(t.threads(), 4);
  EXPECT_EQ(t.comparisons(), 3);
  EXPECT_EQ(t.switches(), 1);
  feed_by(t, seconds, 1000);
  EXPECT_EQ(t.switches(), 1);
  EXPECT_GT(t.steps_on(4), 10 * (t.steps_on(8) + t.steps_on(2)));
  EXPECT_EQ(t.steps_on(1), 0);  // (never two rungs away)
}

// The engine gives the same bits on any number of threads, so a run whose count changes between
// steps is the run on one thread: with windows of one step and no hold, the count changes every
// few steps (which way depends on the timing), and the histories of a filling with an outlet,
// the silo (mesh teeth, a moving bottom) and a triaxial test (preparation, servo, loading) are
// byte for byte those of one thread.
TEST(ThreadTuner, ARunChangingItsThreadsIsTheRunOnOneThread) {
  namespace fs = std::filesystem;
  const fs::path data = fs::path(GS_TEST_DATA_DIR) / "scenes";
  const fs::path tmp = fs::temp_directory_path() / "gs_thread_tuner";
  fs::remove_all(tmp);
  for (const char* name : {"fill_drain", "silo_tiny", "triaxial_tiny"}) {
    SCOPED_TRACE(name);
    std::string summary;
    for (const bool tuned : {false, true}) {
      gs::solver::Scene scene = gs::solver::load_scene(data / (std::string(name) + ".toml"));
      scene.config.threads = tuned ? 0 : 1;  // ("auto", or one)
      gs::solver::RunOptions o;
      o.out = tmp / (std::string(name) + (tuned ? "_tuned" : "_one"));
      o.steps = 3000;
      o.thread_tuning.window_s = 0;
      o.thread_tuning.window_steps = 1;
      o.thread_tuning.hold_s = 0;
      o.thread_tuning.margin = -1e9;  // (every probe kept: a change every second step)
      o.print = [&](const std::string& line) {
        if (line.find("particle-steps/s") != std::string::npos) summary = line;
      };
      gs::solver::run_scene(std::move(scene), o);
    }
    const std::string one =
        gs::text::read_text_file(tmp / (std::string(name) + "_one") / "history.csv");
    ASSERT_GT(one.size(), 100u);
    EXPECT_EQ(one, gs::text::read_text_file(tmp / (std::string(name) + "_tuned") / "history.csv"));
    if (gs::solver::machine_threads() > 1) {
      // (half the steps on each: measure, probe kept, hold, measure, ...: 1, 2, 2, 1, 1, 2, ...)
      EXPECT_NE(summary.find("picked by timing: 50 % of the steps on 1, 50 % on"),
                std::string::npos)
          << summary;
    }
  }
  fs::remove_all(tmp);
}
