#include <clothsim/view/pacing.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
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
  accumulator_ += std::min(elapsed_wall, kMaxFrameGap);
  const long due = static_cast<long>(std::floor(accumulator_ / dt_ + 1e-9));
  // At least one step always fits, otherwise a slow step would freeze the picture; with the
  // cost not yet measured, one step (the first frame's backlog on a loaded machine froze the
  // window for seconds before any step was timed).
  const long affordable =
      step_cost > 0.0 ? std::max(1L, static_cast<long>(max_work_ / step_cost)) : 1L;
  const long n = std::min(due, affordable);
  behind_ = due > affordable;
  accumulator_ -= static_cast<double>(n) * dt_;
  if (behind_) accumulator_ = std::fmod(accumulator_, dt_);  // drop the backlog: no spiral
  accumulator_ = std::max(accumulator_, 0.0);
  return n;
}

}  // namespace clothsim::view
