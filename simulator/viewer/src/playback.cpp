#include <clothsim/view/playback.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace clothsim::view {

Playback::Playback(double lookahead, double preroll)
    : lookahead_(std::isfinite(lookahead) && lookahead > 0.0 ? lookahead : 0.0),
      preroll_(std::clamp(std::isfinite(preroll) ? preroll : 0.0, 0.0, lookahead_)) {}

void Playback::restart(double t, bool preroll) {
  shown_ = t;
  target_ = preroll ? preroll_ : std::min(preroll_, kResumePreroll);
  prerolling_ = target_ > 0.0;
  preroll_wall_ = 0.0;
}

void Playback::advance(double elapsed_wall, double latest, bool can_step) {
  if (!(elapsed_wall > 0.0)) elapsed_wall = 0.0;  // a clock that went backwards, or NaN
  if (prerolling_) {
    preroll_wall_ += elapsed_wall;
    preroll_wall_total_ += elapsed_wall;
    if (latest - shown_ >= target_ || !can_step || preroll_wall_ >= kMaxPrerollWall) prerolling_ = false;
    return;  // the picture holds still until the simulation is preroll() s ahead
  }
  shown_ += elapsed_wall;
  if (shown_ > latest) {
    if (can_step) dropped_ += shown_ - latest;
    shown_ = latest;
  }
  if (can_step) lowest_ahead_ = std::min(lowest_ahead_, latest - shown_);
}

double Playback::frame_interval(double latest, double frame_cost) const {
  if (prerolling_) return kPrerollFrameInterval;
  const double fill = lookahead_ > 0.0 ? std::clamp((latest - shown_) / lookahead_, 0.0, 1.0) : 1.0;
  if (fill >= 1.0) return kMinFrameInterval;
  // 10 % empty to 46 % at 9/10 full, then up to 95 % when full: a simulation that refills the
  // look-ahead at once (the small scenes) leaves the frames nearly all the time
  const double share = fill < 0.9 ? 0.1 + 0.4 * fill : 0.46 + 4.9 * (fill - 0.9);
  const double cost = std::isfinite(frame_cost) && frame_cost > 0.0 ? frame_cost : 0.0;
  return std::clamp(cost / share, kMinFrameInterval, kMaxFrameInterval);
}

Playback::Action Playback::next(double since_frame, double latest, double sim_t, bool can_step,
                                double frame_cost) const {
  const bool step = can_step && wants_steps(sim_t);
  // nothing to step: frames as often as they are worth drawing
  const double interval = step || prerolling_ ? frame_interval(latest, frame_cost) : kMinFrameInterval;
  if (!(since_frame < interval - 1e-6)) return {Action::Draw, 0.0};  // (a microsecond early is due)
  return {step ? Action::Step : Action::Wait, interval - since_frame};
}

bool keeps_state(std::uint64_t next_step, std::uint64_t every, double t, double dt, double end) {
  // (a step early or two: t + dt and the push's test of it may round the other way)
  return (every > 0 && next_step % every == 0) || (end >= 0.0 && t + 2.5 * dt >= end);
}

StateRing::StateRing(const Model& model, std::size_t capacity) {
  if (capacity < 2) throw std::invalid_argument("StateRing: capacity below 2");
  slots_.assign(capacity, make_state(model));
}

void StateRing::push(const State& s) {
  if (full()) throw std::logic_error("StateRing::push(): full");
  slots_[(head_ + count_) % slots_.size()] = s;  // (same sizes: Eigen reuses the slot's memory)
  ++count_;
}

const State& StateRing::back() const { return slots_[(head_ + count_ - 1) % slots_.size()]; }

bool StateRing::show(double t, double tolerance) {
  bool changed = false;
  while (count_ >= 2 && slots_[(head_ + 1) % slots_.size()].t <= t + tolerance) {
    head_ = (head_ + 1) % slots_.size();
    --count_;
    changed = true;
  }
  return changed;
}

std::size_t StateRing::bytes_per_state(const Model& model) {
  return 2 * 3 * sizeof(double) * static_cast<std::size_t>(model.mass_count()) + sizeof(State);
}

StateRing::Plan StateRing::plan(const Model& model, double lookahead, std::size_t max_bytes, std::uint64_t substeps) {
  Plan p;
  const double dt = model.options.dt / static_cast<double>(std::max<std::uint64_t>(substeps, 1));  // a model step
  if (!(lookahead > 0.0) || !(dt > 0.0)) return p;
  const std::size_t bytes = bytes_per_state(model);
  const std::size_t fit = std::max<std::size_t>(2, max_bytes / std::max<std::size_t>(bytes, 1));
  for (const double rate : {60.0, 30.0}) {
    p.every = static_cast<std::uint64_t>(std::max(1.0, std::round(1.0 / (rate * dt))));
    if (substeps > 1) p.every = (p.every + substeps - 1) / substeps * substeps;  // whole steps of dt
    const double spacing = static_cast<double>(p.every) * dt;
    // the one on screen, the look-ahead, and one more so a step never waits for the picture
    // (never more than asked: floor, at least one state ahead)
    const auto want = std::max<std::size_t>(static_cast<std::size_t>(std::floor(lookahead / spacing + 1e-9)), 1) + 2;
    p.capacity = std::min(want, fit);
    p.lookahead = static_cast<double>(p.capacity - 2) * spacing;
    if (want <= fit) break;
  }
  return p;
}

}  // namespace clothsim::view
