// --threads auto: ThreadChooser's decisions from step times given to it (no clock here).
#include <clothsim/thread_choice.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace clothsim {
namespace {

using StepTime = std::function<double(int threads, std::uint64_t step)>;

// Steps the chooser `steps` times; a step with t threads takes time(t, step index).
void feed(ThreadChooser& c, std::uint64_t steps, const StepTime& time) {
  for (std::uint64_t i = 0; i < steps; ++i) c.step_took(time(c.threads(), i));
}

// Steps until the next trial has finished; returns the steps taken (0: none within `limit`).
std::uint64_t feed_to_next_trial(ThreadChooser& c, const StepTime& time, std::uint64_t limit = 10000000) {
  const std::uint64_t before = c.trials();
  for (std::uint64_t i = 0; i < limit; ++i) {
    c.step_took(time(c.threads(), i));
    if (c.trials() > before) return i + 1;
  }
  return 0;
}

// Step times that add up exactly (powers of two), so that the counts below are exact.
constexpr double kOne = 1.0 / 1024, kMany = 1.0 / 2048;
const StepTime kManyTwiceAsFast = [](int t, std::uint64_t) { return t == 1 ? kOne : kMany; };

// Steps timed in a trial of steps taking `step` s each.
std::uint64_t trial_steps(double step) {
  return std::max<std::uint64_t>(ThreadChooser::kTrialSteps,
                                 static_cast<std::uint64_t>(std::ceil(ThreadChooser::kTrialSeconds / step)));
}

TEST(ThreadChooser, OneCoreStaysOnOneThreadAndMeasuresNothing) {
  ThreadChooser c(1);
  EXPECT_EQ(c.threads(), 1);
  feed(c, 50000, [](int, std::uint64_t) { return 1e-3; });
  EXPECT_EQ(c.threads(), 1);
  EXPECT_EQ(c.steps_one(), 50000u);
  EXPECT_EQ(c.steps_many(), 0u);
  EXPECT_EQ(c.trials(), 0u);
  ThreadChooser none(0);  // no cores reported: one thread
  EXPECT_EQ(none.threads(), 1);
}

TEST(ThreadChooser, KeepsManyThreadsWhenTheyAreFaster) {
  ThreadChooser c(2);
  EXPECT_EQ(c.threads(), 2);  // the first trial starts with all cores
  // a trial: kWarm steps, then at least kTrialSteps steps and kTrialSeconds, per candidate
  const std::uint64_t first = feed_to_next_trial(c, kManyTwiceAsFast);
  EXPECT_EQ(first, 2 * ThreadChooser::kWarm + trial_steps(kMany) + trial_steps(kOne));
  EXPECT_EQ(c.threads(), 2);
  EXPECT_EQ(c.steps_one(), ThreadChooser::kWarm + trial_steps(kOne));
  // held 1 s of stepping (2048 steps), then tried again, many threads first
  const auto held = static_cast<std::uint64_t>(ThreadChooser::kHoldSeconds / kMany);
  feed(c, held - 1, kManyTwiceAsFast);
  EXPECT_EQ(c.trials(), 1u);
  EXPECT_EQ(c.threads(), 2);
  EXPECT_EQ(feed_to_next_trial(c, kManyTwiceAsFast), 1 + first);
  // the same winner: held twice as long
  EXPECT_EQ(feed_to_next_trial(c, kManyTwiceAsFast), 2 * held + first);
  EXPECT_EQ(c.trials_won_by_many(), 3u);
  // nearly all steps ran on two threads
  EXPECT_GT(c.share_many(), 0.95);
  EXPECT_DOUBLE_EQ(c.share_many(), static_cast<double>(c.steps_many()) /
                                       static_cast<double>(c.steps_many() + c.steps_one()));
  EXPECT_EQ(ThreadChooser(2).share_many(), 0.0);  // before any step
}

TEST(ThreadChooser, TakesOneThreadWhenManyAreSlowerOrOnlyAsFast) {
  for (const double many : {2e-3, 1e-3, 0.97e-3}) {  // slower, equal, within kMargin
    ThreadChooser c(4);
    const StepTime time = [many](int t, std::uint64_t) { return t == 4 ? many : 1e-3; };
    ASSERT_GT(feed_to_next_trial(c, time), 0u);
    EXPECT_EQ(c.threads(), 1) << "many threads at " << many << " s per step against 1e-3";
    feed(c, 500, time);
    EXPECT_EQ(c.threads(), 1);
  }
}

TEST(ThreadChooser, TheMeanDecidesNotTheMedian) {
  // A busy core: most steps of two threads are fast (0.35 ms), but every 8th waits a time
  // slice (4 ms) for the descheduled thread: 0.81 ms per step on the whole, against 0.79 on
  // one thread. Their median step (0.35 ms) looks faster; their mean is not.
  ThreadChooser c(2);
  const StepTime busy = [](int t, std::uint64_t i) { return t == 1 ? 0.79e-3 : (i % 8 == 7 ? 4e-3 : 0.35e-3); };
  ASSERT_GT(feed_to_next_trial(c, busy), 0u);
  EXPECT_EQ(c.threads(), 1);
  // and every 10th: 0.715 ms, faster than one thread by more than the margin
  ThreadChooser d(2);
  const StepTime less = [](int t, std::uint64_t i) { return t == 1 ? 0.79e-3 : (i % 10 == 9 ? 4e-3 : 0.35e-3); };
  ASSERT_GT(feed_to_next_trial(d, less), 0u);
  EXPECT_EQ(d.threads(), 2);
}

TEST(ThreadChooser, TheFirstStepsOfATrialDoNotCount) {
  // The first kWarm steps after a switch are slow (caches, a contact cache being built):
  // left out, many threads still win.
  ThreadChooser c(2);
  std::uint64_t since_switch = 0;
  int last = c.threads();
  const StepTime time = [&](int t, std::uint64_t) {
    if (t != last) last = t, since_switch = 0;
    const bool warm = since_switch++ < static_cast<std::uint64_t>(ThreadChooser::kWarm);
    return warm ? 1.0 : (t == 1 ? 1e-3 : 0.5e-3);
  };
  ASSERT_GT(feed_to_next_trial(c, time), 0u);
  EXPECT_EQ(c.threads(), 2);
}

TEST(ThreadChooser, FollowsAChangeOfLoad) {
  ThreadChooser c(2);
  bool loaded = false;  // another process takes a core: two threads wait on each other
  const StepTime time = [&loaded](int t, std::uint64_t) { return t == 2 ? (loaded ? 5e-3 : 0.5e-3) : 1e-3; };
  ASSERT_GT(feed_to_next_trial(c, time), 0u);
  ASSERT_EQ(c.threads(), 2);
  loaded = true;
  ASSERT_GT(feed_to_next_trial(c, time), 0u);
  EXPECT_EQ(c.threads(), 1);
  loaded = false;
  ASSERT_GT(feed_to_next_trial(c, time), 0u);
  EXPECT_EQ(c.threads(), 2);
  EXPECT_EQ(c.trials(), 3u);
  EXPECT_EQ(c.trials_won_by_many(), 2u);
}

TEST(ThreadChooser, ABrokenClockCountsAsSlow) {
  // NaN or negative times for many threads: they must not win, and the trial still ends.
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), -1.0}) {
    ThreadChooser c(2);
    ASSERT_GT(feed_to_next_trial(c, [bad](int t, std::uint64_t) { return t == 2 ? bad : 1e-3; }), 0u);
    EXPECT_EQ(c.threads(), 1) << bad;
  }
}

TEST(ThreadChooser, TheHoldDoublesUpToItsCap) {
  ThreadChooser c(2);
  const std::uint64_t trial = feed_to_next_trial(c, kManyTwiceAsFast);
  // held 1, 2, 4, 8, 16, 16 ... s of stepping between trials
  for (const double held : {1.0, 2.0, 4.0, 8.0, 16.0, 16.0, 16.0})
    EXPECT_EQ(feed_to_next_trial(c, kManyTwiceAsFast), static_cast<std::uint64_t>(held / kMany) + trial) << held;
}

TEST(ThreadChooser, SlowStepsAreHeldLongerThanTheirTrials) {
  // 1/8 s per step on many threads, 1/4 on one (a huge model): a trial takes 34 steps of
  // each, 12.75 s; held only 1 s, the run would spend most of its time in trials. The hold
  // is kHoldPerTrial times the trial: 102 s = 816 steps, and the doubling stays there.
  ThreadChooser c(2);
  const StepTime slow = [](int t, std::uint64_t) { return t == 1 ? 0.25 : 0.125; };
  const std::uint64_t trial = feed_to_next_trial(c, slow);
  ASSERT_EQ(trial, 2u * (ThreadChooser::kWarm + ThreadChooser::kTrialSteps));
  EXPECT_EQ(c.threads(), 2);
  const double trial_seconds = (ThreadChooser::kWarm + ThreadChooser::kTrialSteps) * (0.25 + 0.125);
  const auto held = static_cast<std::uint64_t>(ThreadChooser::kHoldPerTrial * trial_seconds / 0.125);
  EXPECT_EQ(feed_to_next_trial(c, slow), held + trial);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(feed_to_next_trial(c, slow), held + trial);
  // over these ten holds the slower count's trials take under 9 % of the time (7.4 % per
  // hold and trial); held 1 s they would take two thirds of it
  EXPECT_LT(0.25 * static_cast<double>(c.steps_one()),
            0.09 * (0.25 * static_cast<double>(c.steps_one()) + 0.125 * static_cast<double>(c.steps_many())));
}

}  // namespace
}  // namespace clothsim
