#include <clothsim/thread_choice.hpp>

#include <algorithm>
#include <chrono>

namespace clothsim {

namespace {
constexpr double kSlow = 1e9;  // s: what a step with a broken time counts as
}

ThreadChooser::ThreadChooser(int cores) : cores_(cores > 1 ? cores : 1), current_(cores_) {
  if (cores_ == 1) phase_ = Phase::Hold;
}

void ThreadChooser::start_trial_of(int count) {
  current_ = count;
  warm_left_ = kWarm;
  timed_ = 0;
  sum_ = 0.0;
}

void ThreadChooser::step_took(double seconds) {
  ++steps_[current_ == 1 ? 0 : 1];
  if (cores_ == 1) return;
  const double t = seconds >= 0.0 ? std::min(seconds, kSlow) : kSlow;
  if (phase_ == Phase::Hold) {
    held_ += t;
    if (held_ < hold_) return;
    // Time for a new trial: the count in use first (it is warm), then the other one.
    phase_ = Phase::First;
    trial_time_ = 0.0;
    start_trial_of(current_);
    return;
  }
  trial_time_ += t;
  if (warm_left_ > 0) {
    --warm_left_;
    return;
  }
  sum_ += t;
  if (++timed_ < static_cast<std::uint64_t>(kTrialSteps) || sum_ < kTrialSeconds) return;
  mean_[current_ == 1 ? 0 : 1] = sum_ / static_cast<double>(timed_);
  if (phase_ == Phase::First) {
    phase_ = Phase::Second;
    start_trial_of(current_ == 1 ? cores_ : 1);
    return;
  }
  // Both measured: keep the faster.
  ++trials_;
  const int winner = mean_[1] < kMargin * mean_[0] ? cores_ : 1;
  if (winner != 1) ++won_many_;
  const double base = std::max(kHoldSeconds, kHoldPerTrial * trial_time_);
  hold_ = winner == last_winner_ ? std::max(base, std::min(2.0 * hold_, std::max(kHoldMaxSeconds, base))) : base;
  last_winner_ = winner;
  current_ = winner;
  phase_ = Phase::Hold;
  held_ = 0.0;
}

StepStatus chosen_step(ThreadChooser& chooser, const Model& model, State& state, Workspace& ws) {
  ws.threads = chooser.threads();
  if (chooser.cores() == 1) {  // nothing to measure: no clock
    const StepStatus st = step(model, state, ws);
    chooser.step_took(0.0);
    return st;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const StepStatus st = step(model, state, ws);
  chooser.step_took(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return st;
}

}  // namespace clothsim
