// The real-time loop's bookkeeping: how many fixed steps a frame takes. Pure arithmetic so it
// can be tested without a clock.
#pragma once

#include <string_view>

namespace clothsim::view {

/// Whether a GL_RENDERER string names a renderer that draws on the CPU (Mesa's llvmpipe and
/// softpipe, SwiftShader, ...): there every frame's pixels cost the simulation CPU time.
bool software_renderer(std::string_view gl_renderer);

class StepClock {
 public:
  StepClock(double dt, double max_work_per_frame) : dt_(dt), max_work_(max_work_per_frame) {}

  /// Steps to take now, given the wall time since the last frame and the measured cost of one
  /// step (s, 0 if unknown: then at most one step, which the caller times). The remainder is carried to the next frame; when the steps would
  /// cost more than max_work_per_frame they are capped and the backlog dropped, so a slow
  /// machine runs slower than real time instead of spiralling (behind() says so).
  long steps_due(double elapsed_wall, double step_cost);

  void reset() { accumulator_ = 0.0; behind_ = false; }  ///< after a pause
  bool behind() const { return behind_; }
  double carried() const { return accumulator_; }        ///< s of simulated time still owed

 private:
  double dt_, max_work_;
  double accumulator_ = 0.0;
  bool behind_ = false;
};

}  // namespace clothsim::view
