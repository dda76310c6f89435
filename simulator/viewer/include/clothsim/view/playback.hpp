// The window's look-ahead: the simulation runs ahead of the picture, and the picture plays the
// states it left behind at the wall clock's pace. A few heavy seconds (the skirt sliding over
// the sphere) then borrow from the cheap ones around them instead of falling behind. GL-free,
// so it is tested without a window or a clock.
#pragma once

#include <clothsim/sim.hpp>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace clothsim::view {

/// The picture's clock against the simulation's. `lookahead` s of simulated time may be
/// computed ahead of the picture; `preroll` s are computed before the picture starts to move
/// (at most kMaxPrerollWall of wall time), after start() and after every restart that asks
/// for it. Pure arithmetic: the caller steps, draws and reads the wall clock.
class Playback {
 public:
  static constexpr double kMaxPrerollWall = 2.0;   ///< s of wall time a pre-roll may hold the picture
  static constexpr double kMinFrameInterval = 1.0 / 60.0;
  static constexpr double kMaxFrameInterval = 0.25;  ///< at least 4 frames a second, however empty
  /// A look-ahead shorter than a few frames is none: the steps between frames could not keep it
  /// (a 0.02 s look-ahead ran at 0.6x real time where none kept up); the window goes without.
  static constexpr double kMinLookahead = 0.25;
  static constexpr double kPrerollFrameInterval = 0.25;  ///< frames while pre-rolling (the title says so)
  /// s computed ahead before a resume's picture moves (a pause, a grab or a step left nothing
  /// ahead: without it the picture would wait for the very next state, and count it dropped)
  static constexpr double kResumePreroll = 0.05;

  Playback(double lookahead, double preroll);

  /// The picture at simulated time t with nothing computed ahead. It holds until preroll() s
  /// (`preroll`; else kResumePreroll at most) are computed ahead, kMaxPrerollWall has passed,
  /// or the simulation cannot go on.
  void restart(double t, bool preroll);
  /// The picture's clock after `elapsed_wall` s of wall time; `latest`: the newest simulated
  /// time; `can_step`: whether the simulation could still go on (false at a timed run's end or
  /// after a failure). A picture that would pass `latest` waits there; while the simulation
  /// could have gone on, that wait is counted as dropped.
  void advance(double elapsed_wall, double latest, bool can_step);

  double shown() const { return shown_; }
  bool prerolling() const { return prerolling_; }
  double lookahead() const { return lookahead_; }
  double preroll() const { return preroll_; }
  /// Whether the simulation should take more steps: less than lookahead() s ahead of the picture.
  bool wants_steps(double latest) const { return latest < shown_ + lookahead_; }
  /// s of wall time between frames: 1/60 s when the look-ahead is full; else a frame costing
  /// `frame_cost` s takes a share of the time that grows with how full it is (10 % empty, 46 %
  /// at 9/10, 95 % nearly full), so that the steps get the rest while the picture eats into
  /// the look-ahead; never more than kMaxFrameInterval.
  double frame_interval(double latest, double frame_cost) const;
  /// What the window does next, `since_frame` s of wall time after its last frame began, the
  /// newest state it may show at `latest`, the simulation at `sim_t`; `can_step`: whether a step
  /// could be taken now (running, not at a timed run's end, room for its state). Draw now, or
  /// step (look-ahead not full) or wait (nothing to step) for `seconds` before drawing.
  struct Action {
    enum Kind { Draw, Step, Wait } kind = Draw;
    double seconds = 0.0;
  };
  Action next(double since_frame, double latest, double sim_t, bool can_step, double frame_cost) const;
  /// s of simulated time the picture waited for the simulation (0: it kept up).
  double dropped() const { return dropped_; }
  /// The least look-ahead (s) the picture had while it moved and the simulation could go on.
  double lowest_ahead() const { return lowest_ahead_; }
  /// s of wall time the picture held still for pre-rolls.
  double preroll_wall() const { return preroll_wall_total_; }

 private:
  double lookahead_, preroll_;
  double shown_ = 0.0;
  double target_ = 0.0;  ///< s ahead that ends this pre-roll
  bool prerolling_ = false;
  double preroll_wall_ = 0.0, preroll_wall_total_ = 0.0;
  double dropped_ = 0.0;
  double lowest_ahead_ = std::numeric_limits<double>::infinity();
};

/// Whether the step that makes model step `next_step` leaves a state the ring keeps: one every
/// `every` steps, and a timed run's last (`end` >= 0: simulated time it ends at; the steps
/// from `t` of `dt` within two and a half steps of it count, early rather than late).
bool keeps_state(std::uint64_t next_step, std::uint64_t every, double t, double dt, double end);

/// The states the simulation left ahead of the picture, one every `every` steps: a ring of
/// State copies (positions, velocities, time, steps) whose memory is reused. The oldest is the
/// one on screen; taking it back (rewind) is how a pause or a drag starts from what the user
/// sees. Bits are kept: a state taken back steps on exactly as it did the first time.
class StateRing {
 public:
  /// Room for `capacity` states (>= 2) of `model`'s size.
  StateRing(const Model& model, std::size_t capacity);
  std::size_t size() const { return count_; }
  std::size_t capacity() const { return slots_.size(); }
  bool full() const { return count_ == slots_.size(); }
  bool empty() const { return count_ == 0; }
  void clear() { count_ = 0; }
  /// Copies `s` in as the newest (the ring must not be full).
  void push(const State& s);
  /// The oldest state (the one on screen) and the newest.
  const State& front() const { return slots_[head_]; }
  const State& back() const;
  /// Drops the states older than the newest one at or before simulated time t (to within
  /// `tolerance`): afterwards front() is the state to show at t. Returns whether front() changed.
  bool show(double t, double tolerance);

  /// The capacity and snapshot spacing for a model: states per simulated second
  /// (60, or 30 when 60 would not fit) and the look-ahead that fits in `max_bytes`.
  struct Plan {
    std::size_t capacity = 2;
    std::uint64_t every = 1;   ///< model steps between states
    double lookahead = 0.0;    ///< s of simulated time the ring holds
  };
  /// `substeps`: model steps per step of the user's dt; the spacing is a multiple of it, so a
  /// state taken back is on a whole step.
  static Plan plan(const Model& model, double lookahead, std::size_t max_bytes, std::uint64_t substeps = 1);
  static std::size_t bytes_per_state(const Model& model);

 private:
  std::vector<State> slots_;
  std::size_t head_ = 0, count_ = 0;
};

}  // namespace clothsim::view
