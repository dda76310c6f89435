#include <clothsim/view/pacing.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

namespace clothsim::view {

namespace {
// A longer gap between frames (a stall: window moved, process stopped) is not caught up.
constexpr double kMaxFrameGap = 0.25;
}

bool software_renderer(std::string_view gl_renderer) {
  std::string r(gl_renderer);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* name : {"llvmpipe", "softpipe", "software", "swiftshader", "swrast", "lavapipe"})
    if (r.find(name) != std::string::npos) return true;
  return false;
}

long StepClock::steps_due(double elapsed_wall, double step_cost) {
  if (!(elapsed_wall > 0.0)) elapsed_wall = 0.0;  // a clock that went backwards, or NaN
  if (elapsed_wall > kMaxFrameGap) dropped_ += elapsed_wall - kMaxFrameGap;
  accumulator_ += std::min(elapsed_wall, kMaxFrameGap);
  const long due = static_cast<long>(std::floor(accumulator_ / dt_ + 1e-9));
  if (!(step_cost > 0.0)) {
    // The cost not yet measured: one step, which the caller times (the first frame's whole
    // backlog, on a loaded machine, would freeze the window for seconds before any step is
    // timed). The rest stays owed, for the next frame to take within max_work_per_frame: it is
    // the first frame's time, not a machine too slow, and dropping it would lose that time in
    // every run.
    const long n = std::min(due, 1L);
    behind_ = false;
    accumulator_ = std::max(accumulator_ - static_cast<double>(n) * dt_, 0.0);
    return n;
  }
  // At least one step always fits, otherwise a slow step would freeze the picture.
  const long affordable = std::max(1L, static_cast<long>(max_work_ / step_cost));
  const long n = std::min(due, affordable);
  behind_ = due > affordable;
  accumulator_ -= static_cast<double>(n) * dt_;
  if (behind_) {  // drop the backlog: no spiral
    const double kept = std::fmod(accumulator_, dt_);
    dropped_ += accumulator_ - kept;
    accumulator_ = kept;
  }
  accumulator_ = std::max(accumulator_, 0.0);
  return n;
}

double next_step_cost(double previous, double measured) {
  return previous > 0.0 ? std::min(measured, 0.8 * previous + 0.2 * measured) : measured;
}

namespace {
std::uint64_t per_dt(int substeps) { return static_cast<std::uint64_t>(std::max(substeps, 1)); }
}  // namespace

std::uint64_t StepsOfDt::completed(std::uint64_t model_steps) const {
  return model_steps / per_dt(substeps);
}

std::uint64_t StepsOfDt::containing(std::uint64_t model_step) const {
  return model_step == 0 ? 0 : (model_step - 1) / per_dt(substeps) + 1;
}

std::uint64_t StepsOfDt::completed_before_failure(std::uint64_t model_step) const {
  return model_step == 0 ? 0 : containing(model_step) - 1;
}

std::string StepsOfDt::step_label(std::uint64_t model_step) const {
  std::string label = "step " + std::to_string(containing(model_step));
  if (const std::uint64_t n = per_dt(substeps); n > 1 && model_step > 0)
    label += ", substep " + std::to_string((model_step - 1) % n + 1) + " of " + std::to_string(n);
  return label;
}

StepRates step_rates(const StepsOfDt& steps, std::uint64_t model_steps, double step_seconds,
                     double sim_seconds, double wall_seconds) {
  // Fractional steps of dt, not completed(): a half-second window seldom ends on a whole step
  // of dt, and rounding down would make the rates jump by one step in every window.
  const double n = static_cast<double>(model_steps) / static_cast<double>(per_dt(steps.substeps));
  StepRates r;
  if (wall_seconds > 0.0) {
    r.steps_per_s = n / wall_seconds;
    r.realtime = sim_seconds / wall_seconds;
  }
  if (model_steps > 0) r.ms_per_step = 1e3 * step_seconds / n;
  return r;
}

std::string stats_text(std::string_view scene, int width, int height, double t, const StepRates& rates,
                       std::string_view status) {
  char buf[160];
  std::snprintf(buf, sizeof buf, " | %dx%d | t %.2f s | %.0f steps/s | %.2f ms/step | %.2fx real time", width,
                height, t, rates.steps_per_s, rates.ms_per_step, rates.realtime);
  return "clothsim " + std::string(scene) + buf + std::string(status);
}

}  // namespace clothsim::view
