// --threads auto: which thread count to step with, chosen by measuring the steps themselves.
// step() gives the same bits for any count, so switching changes only the speed. Pure
// bookkeeping (no clock, no threads); chosen_step() is the timed step that feeds it.
#pragma once

#include <clothsim/step.hpp>

#include <cstdint>

namespace clothsim {

/// Chooses between one thread and `cores` threads while a run steps. Each candidate runs a
/// trial: kWarm steps left out, then at least kTrialSteps steps and kTrialSeconds of stepping
/// timed; the one with the lower mean step time (the throughput) is kept for a while
/// (kHoldSeconds of stepping, doubled each time the same count wins again, up to
/// kHoldMaxSeconds; at least kHoldPerTrial times what the trial took, so that slow steps do
/// not spend their time in trials), then both are tried again, so that a change in the load
/// (another process taking a core) or in the scene (a cloth reaching its collider) is
/// followed. Many threads must be faster by kMargin to be kept: a near tie leaves the second
/// core free.
///
/// The mean, not the median: with a busy core most steps of two threads are fast, but every
/// few milliseconds one waits a whole time slice at a barrier for the descheduled thread,
/// and those waits are where the time goes (skirt_hires beside a busy loop: two threads
/// 1.4-2.0 ms per step against 0.79 on one, while their median step looked faster). A trial
/// spans several of the scheduler's time slices for that reason.
///
/// Use: chosen_step(), or before each step ws.threads = chooser.threads() and after it
/// chooser.step_took(seconds).
class ThreadChooser {
 public:
  static constexpr int kWarm = 3;                  ///< steps after a switch left out (caches settling)
  static constexpr int kTrialSteps = 31;           ///< at least this many steps timed per candidate
  static constexpr double kTrialSeconds = 0.05;    ///< and at least this much stepping time
  static constexpr double kHoldSeconds = 1.0;      ///< stepping time between trials, at first
  static constexpr double kHoldMaxSeconds = 16.0;  ///< ... doubled while the same count wins
  static constexpr double kHoldPerTrial = 8.0;      ///< hold >= this x the last trial's time
  static constexpr double kMargin = 0.95;  ///< many threads kept when mean(many) < kMargin mean(one)

  /// cores <= 1 (or a model too small to split): always one thread, nothing measured.
  explicit ThreadChooser(int cores);

  /// The thread count for the next step.
  int threads() const { return current_; }
  /// Records the wall time of the step just taken with threads(). A negative or NaN time (a
  /// clock gone wrong) counts as a very slow step.
  void step_took(double seconds);

  /// Steps taken with one thread and with `cores` threads (trials included).
  std::uint64_t steps_one() const { return steps_[0]; }
  std::uint64_t steps_many() const { return steps_[1]; }
  /// The share of those steps taken with `cores` threads (0 before any step).
  double share_many() const {
    const std::uint64_t all = steps_[0] + steps_[1];
    return all > 0 ? static_cast<double>(steps_[1]) / static_cast<double>(all) : 0.0;
  }
  int cores() const { return cores_; }
  /// Finished trials (each measured both counts), and how many of them kept many threads.
  std::uint64_t trials() const { return trials_; }
  std::uint64_t trials_won_by_many() const { return won_many_; }

 private:
  enum class Phase { First, Second, Hold };
  void start_trial_of(int count);

  int cores_;
  int current_;
  Phase phase_ = Phase::First;
  int warm_left_ = kWarm;
  std::uint64_t timed_ = 0;
  double sum_ = 0.0;
  double mean_[2] = {0.0, 0.0};  ///< [0] one thread, [1] many, of the current trial
  double hold_ = kHoldSeconds, held_ = 0.0;
  double trial_time_ = 0.0;  ///< s of stepping in the current trial, both counts, warm steps too
  int last_winner_ = 0;
  std::uint64_t steps_[2] = {0, 0};
  std::uint64_t trials_ = 0, won_many_ = 0;
};

/// step() with chooser.threads() threads, timed (steady clock) and recorded in the chooser.
StepStatus chosen_step(ThreadChooser& chooser, const Model& model, State& state, Workspace& ws);

}  // namespace clothsim
