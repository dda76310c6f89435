// The real-time loop's bookkeeping: how many fixed steps a frame takes, and the counts and
// rates the viewer shows. Pure arithmetic so it can be tested without a clock or a window.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace clothsim::view {

/// Whether a GL_RENDERER string names a renderer that draws on the CPU (Mesa's llvmpipe and
/// softpipe, SwiftShader, ...): there every frame's pixels cost the simulation CPU time.
bool software_renderer(std::string_view gl_renderer);

class StepClock {
 public:
  StepClock(double dt, double max_work_per_frame) : dt_(dt), max_work_(max_work_per_frame) {}

  /// Steps to take now, given the wall time since the last frame and the measured cost of one
  /// step (s; 0 if unknown: then at most one step, which the caller times, and the rest stays
  /// owed). The remainder is carried to the next frame; when the steps would cost more than
  /// max_work_per_frame they are capped and the backlog dropped, so a slow machine runs
  /// slower than real time instead of spiralling (behind() says so).
  long steps_due(double elapsed_wall, double step_cost);

  void reset() { accumulator_ = 0.0; behind_ = false; }  ///< after a pause
  bool behind() const { return behind_; }
  double carried() const { return accumulator_; }        ///< s of simulated time still owed
  /// s of simulated time given up since construction: backlogs dropped because the steps
  /// would have cost more than max_work_per_frame, and frame gaps beyond 0.25 s. 0 means the
  /// simulation kept up with the wall clock (it lags it only by the time still owed).
  double dropped() const { return dropped_; }

 private:
  double dt_, max_work_;
  double accumulator_ = 0.0;
  double dropped_ = 0.0;
  bool behind_ = false;
};

/// The step-cost estimate after a frame whose steps cost `measured` s each, from `previous`
/// (0: none yet): smoothed as it rises (0.8 previous + 0.2 measured), followed at once as it
/// falls. The first step builds the contact caches and costs several later ones; smoothing
/// it down capped the following frames below real time.
double next_step_cost(double previous, double measured);

/// Counts in steps of the user's dt. With substeps > 1 the model's dt is dt / substeps (the
/// stability guard splits each step) and State::steps counts those model steps; the headless
/// summary, the report and the OBJ numbering count steps of dt, so every text the viewer shows
/// converts with these. A substeps below 1 counts as 1.
struct StepsOfDt {
  int substeps = 1;

  /// Steps of dt completed after `model_steps` finite model steps (a partial one does not count).
  std::uint64_t completed(std::uint64_t model_steps) const;
  /// The step of dt (1-based) that model step `model_step` (1-based) is a substep of: where a
  /// failure in any of its substeps is reported, as the headless run names the failed step.
  std::uint64_t containing(std::uint64_t model_step) const;
  /// Steps of dt completed when the state went non-finite at model step `model_step`: those
  /// before the failing one, as the report's `steps` of a failed run.
  std::uint64_t completed_before_failure(std::uint64_t model_step) const;
  /// "step 11" for model step `model_step` (1-based), with substeps "step 11, substep 3 of 4":
  /// the step of dt it belongs to, and which of its substeps it is.
  std::string step_label(std::uint64_t model_step) const;
};

/// Rates over a stretch of wall time, per step of the user's dt (all its substeps).
struct StepRates {
  double steps_per_s = 0.0;  ///< steps of dt per second of wall time
  double ms_per_step = 0.0;  ///< ms of stepping per step of dt
  double realtime = 0.0;     ///< simulated seconds per wall second
};

/// The rates of `model_steps` model steps that took `step_seconds` of stepping, advanced the
/// simulation by `sim_seconds`, within `wall_seconds` of wall time. Zero where nothing was
/// measured (no steps, no wall time).
StepRates step_rates(const StepsOfDt& steps, std::uint64_t model_steps, double step_seconds,
                     double sim_seconds, double wall_seconds);

/// The first line of the window title and the overlay: scene, framebuffer size, simulated time,
/// the rates, and `status` (" | paused", ... or empty).
std::string stats_text(std::string_view scene, int width, int height, double t, const StepRates& rates,
                       std::string_view status);

}  // namespace clothsim::view
