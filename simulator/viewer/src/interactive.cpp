// The interactive window's loop: each turn takes the input, steps in real time or plays the
// look-ahead, draws a frame and keeps the title's rates; the closing line says how it went.
#include "viewer_impl.hpp"

#include "png_io.hpp"

#include <GL/glew.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace clothsim {

// The window's loop until it is closed (a key, the window manager, a timed run's end, Ctrl-C).
int Viewer::run_interactive() {
  interactive_ = true;
  install_callbacks();
  plan_lookahead();
  // A first picture before the clock starts: a GL may compile the shaders at their first
  // draw (llvmpipe does), time the simulation would otherwise owe from t = 0.
  render();
  glFinish();
  loop_ = LoopClock{};
  loop_.last = loop_.run_start = loop_.last_frame = loop_.window_start = Clock::now();
  loop_.window_shown_start = loop_.previous_shown = shown_time();
  update_title(view::StepRates{});
  while (!glfwWindowShouldClose(window_)) {
    glfwPollEvents();
    if (stop_asked()) {
      interrupted_ = true;
      break;
    }
    enter_playback();
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - loop_.last).count();
    loop_.last = now;
    bool draw = true;
    if (in_playback_) draw = play(now, elapsed);
    else if (!step_in_real_time(now, elapsed)) continue;
    const double shown = shown_time();  // (R sets it back: no advance)
    loop_.shown_advanced += std::max(shown - loop_.previous_shown, 0.0);
    loop_.previous_shown = shown;
    if (draw) draw_frame();
    update_rates();
  }
  return end_of_run();
}

// GLFW's window callbacks: a new size for the picture, and the input (input.cpp).
void Viewer::install_callbacks() {
  glfwSetWindowUserPointer(window_, this);
  glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int width, int height) {
    auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
    self->gpu_.target.resize(width, height);
    self->update_title();  // the title shows the size: tests wait for it
  });
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_PRESS || action == GLFW_REPEAT)
      static_cast<Viewer*>(glfwGetWindowUserPointer(w))->input({Input::Key, key, action, 0, 0.0, 0.0});
  });
  glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int mods) {
    static_cast<Viewer*>(glfwGetWindowUserPointer(w))->input({Input::Button, button, action, mods, 0.0, 0.0});
  });
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
    static_cast<Viewer*>(glfwGetWindowUserPointer(w))->input({Input::Cursor, 0, 0, 0, x, y});
  });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
    static_cast<Viewer*>(glfwGetWindowUserPointer(w))->input({Input::Scroll, 0, 0, 0, 0.0, dy});
  });
}

// The look-ahead (--lookahead): a ring of states the picture plays while the simulation runs
// ahead of it (view/playback.hpp), as large as its memory allows.
void Viewer::plan_lookahead() {
  if (opt_.lookahead <= 0.0) return;
  const view::StateRing::Plan plan =
      view::StateRing::plan(model_, opt_.lookahead, kRingBytes, static_cast<std::uint64_t>(std::max(opt_.substeps, 1)));
  if (plan.lookahead >= view::Playback::kMinLookahead) {
    ring_.emplace(model_, plan.capacity);
    snap_every_ = plan.every;
    playback_.emplace(plan.lookahead, 0.5 * plan.lookahead);
  }
  // what the memory allowed, said (a larger model keeps fewer states)
  if (plan.lookahead < opt_.lookahead - 0.05) {
    char cut[48] = "off (under 0.25 s)";
    if (playback_) std::snprintf(cut, sizeof cut, "cut to %.2f s", plan.lookahead);
    std::fprintf(stderr, "clothsim: look-ahead %s: %zu states of %.1f MB each fit in %zu MB\n", cut,
                 plan.capacity, static_cast<double>(view::StateRing::bytes_per_state(model_)) / 1e6,
                 kRingBytes >> 20);
  }
}

// Into the look-ahead when running freely; out of it (the picture's state taken back, in the
// key and mouse handlers) to pause, single-step or drag.
void Viewer::enter_playback() {
  if (!playback_ || in_playback_ || paused_ || dragging_ || non_finite_) return;
  ring_->clear();
  ring_->push(state_);
  playback_->restart(state_.t, preroll_next_);  // the first start and every R pre-roll
  preroll_next_ = false;
  in_playback_ = true;
  update_title();  // ("buffering")
}

// A turn of the look-ahead: the picture moves on through the ring, then the steps or the wait
// until the next frame is due. Whether to draw a frame now.
bool Viewer::play(Clock::time_point now, double elapsed) {
  const double dt = h();
  const bool was_prerolling = playback_->prerolling();
  playback_->advance(elapsed, ring_->back().t, !at_end() && !non_finite_ && failure_.empty());
  if (!paused_ && !was_prerolling) loop_.run_wall += elapsed;
  if (was_prerolling != playback_->prerolling()) update_title();
  ring_->show(playback_->shown(), 0.5 * dt);
  // a timed run closes once the picture shows its last state; a failure ahead is met once the
  // picture shows the last finite one
  if (at_end() && ring_->size() == 1) glfwSetWindowShouldClose(window_, GLFW_TRUE);
  if (!failure_.empty() && !non_finite_ && ring_->size() == 1 && playback_->shown() >= ring_->back().t)
    fail_now();
  const bool stepping = !paused_ && !non_finite_ && failure_.empty() && !at_end();
  const auto act = playback_->next(std::chrono::duration<double>(now - loop_.last_frame).count(),
                                   ring_->back().t, state_.t, stepping && room(), frame_cost_);
  if (act.kind == view::Playback::Action::Draw || glfwWindowShouldClose(window_)) return true;
  const auto due = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(act.seconds));
  if (act.kind == view::Playback::Action::Step) {
    // steps until the next frame is due (at most 50 ms, for the events), the look-ahead is
    // full, or the ring has no room for the next state
    const auto until = std::min(due, now + std::chrono::milliseconds(50));
    step_while([&](long) {
      return failure_.empty() && !at_end() && playback_->wants_steps(state_.t) && room() && Clock::now() < until;
    });
  } else {
    glfwWaitEventsTimeout(std::max(act.seconds, 1e-3));
  }
  return false;
}

// A turn without the look-ahead: the steps real time asks for (or the N presses while paused).
// False when it waited for events instead (paused, nothing to do, a frame drawn just now).
bool Viewer::step_in_real_time(Clock::time_point now, double elapsed) {
  const double dt = h();
  if (!paused_) loop_.run_wall += elapsed;
  long n = 0;
  if (!paused_) {
    n = clock_.steps_due(elapsed, step_cost_);
  } else {
    clock_.reset();
    n = pending_steps_;  // N presses, each one step of dt, even several within one frame
  }
  // paused with nothing to step: frames at most 60 per second (else it draws as fast as it
  // can); a requested screenshot is drawn at once
  if (paused_ && pending_steps_ == 0 && !dragging_ && !screenshot_request_) {
    const double since = std::chrono::duration<double>(now - loop_.last_frame).count();
    if (since < view::Playback::kMinFrameInterval) {
      glfwWaitEventsTimeout(view::Playback::kMinFrameInterval - since);
      return false;
    }
  }
  pending_steps_ = 0;
  if (opt_.seconds >= 0.0) {  // a timed run: stop exactly at the requested time
    const long left = static_cast<long>(std::llround((opt_.seconds - state_.t) / dt));
    n = std::min(n, std::max(left, 0L));
    if (left <= 0) glfwSetWindowShouldClose(window_, GLFW_TRUE);
  }
  if (n > 0) step_while([&](long done) { return done < n; });
  return true;
}

// Steps while more(steps done so far) says so, timed together: the cost estimate, the counts,
// the look-ahead's ring, and a non-finite state (failed now, or when the picture reaches it).
template <class More>
void Viewer::step_while(More more) {
  update_drag_target();
  const auto t0 = Clock::now();
  long done = 0;
  for (; more(done); ++done) {
    if (!timed_step().finite) {
      char what[160];
      std::snprintf(what, sizeof what, "the simulation became non-finite at t = %.3f s (%s)", state_.t,
                    of_dt_.step_label(state_.steps).c_str());
      failure_ = what;
      // Ahead of the picture: the picture plays the finite states up to it, then fails.
      if (!in_playback_) fail_now();
      break;
    }
    // (room() made room for it; a full ring here would be a rounding room() did not foresee:
    // then this state is not kept, and the picture ends one state early)
    if (in_playback_ && (state_.steps % snap_every_ == 0 || at_end()) && !ring_->full()) ring_->push(state_);
  }
  const double spent = std::chrono::duration<double>(Clock::now() - t0).count();
  if (done > 0) step_cost_ = view::next_step_cost(step_cost_, spent / static_cast<double>(done));
  loop_.window_steps += static_cast<std::uint64_t>(done);
  loop_.window_step_time += spent;
  total_steps_ += static_cast<std::uint64_t>(done);
  total_step_time_ += spent;
}

// Whether the ring has room for what the next step leaves: a state every snap_every_ model
// steps, and the last one of a timed run (judged early, never late: keeps_state()).
bool Viewer::room() const {
  return !ring_->full() ||
         !view::keeps_state(state_.steps + 1, snap_every_, state_.t, h(), opt_.seconds);
}

// A frame in the window: the picture's state drawn and shown, a requested screenshot saved.
void Viewer::draw_frame() {
  const auto t0 = Clock::now();
  if (!non_finite_)
    gpu_.upload_state(scene_, model_, in_playback_ ? ring_->front() : state_, show_springs_ || dragging_);
  render();
  gpu_.target.blit_to_window();
  if (screenshot_request_) {
    screenshot_request_ = false;
    save_numbered_screenshot();
    replay_deferred();
  }
  glfwSwapBuffers(window_);
  // A software renderer drawing on the cores the simulation's threads all use: it finishes
  // the frame before the next steps, as its threads would otherwise stall the steps' barriers
  // (skirt_hires, two threads on two cores, llvmpipe: 0.385-0.401 -> 0.367-0.370 ms per
  // step). With a core to spare the overlap pays (one thread: 0.54x real time with it,
  // 0.48-0.52x without).
  if (finish_frames()) glFinish();
  loop_.last_frame = t0;  // intervals run from a frame's start (Playback::next)
  const double cost = std::chrono::duration<double>(Clock::now() - t0).count();
  frame_cost_ = frame_cost_ > 0.0 ? 0.8 * frame_cost_ + 0.2 * cost : cost;
  ++loop_.frames;
}

// glFinish() after each frame: a software renderer while the steps' threads take every core.
bool Viewer::finish_frames() const {
  return software_ && ws_.threads > 1 && ws_.threads >= core_count();
}

// The title's rates, measured every 0.5 s (and started again by R).
void Viewer::update_rates() {
  const double wall = std::chrono::duration<double>(Clock::now() - loop_.window_start).count();
  if (stats_reset_) {  // R: the rates start again from the reset state
    stats_reset_ = false;
    loop_.window_start = Clock::now();
    loop_.window_shown_start = shown_time();
    loop_.previous_shown = loop_.window_shown_start;
    loop_.window_steps = 0;
    loop_.window_step_time = 0.0;
  } else if (wall >= 0.5) {
    const double dropped_now = dropped();
    behind_ = dropped_now > loop_.window_dropped || clock_.behind();
    loop_.window_dropped = dropped_now;
    update_title(view::step_rates(of_dt_, loop_.window_steps, loop_.window_step_time,
                                  shown_time() - loop_.window_shown_start, wall));
    loop_.window_start = Clock::now();
    loop_.window_shown_start = shown_time();
    loop_.window_steps = 0;
    loop_.window_step_time = 0.0;
  }
}

// The closing line (time, steps, rates, pace, frames) and the exit code of the window's run.
int Viewer::end_of_run() {
  const double wall = std::chrono::duration<double>(Clock::now() - loop_.run_start).count();
  // The picture's state: the one the user saw last (the simulation may have gone ahead).
  const State& seen = in_playback_ && !non_finite_ ? ring_->front() : state_;
  // Steps of the user's dt (substeps x the model's dt), as the headless summary counts them;
  // a failed run counts those before the failing one, as its report does.
  const std::uint64_t steps_done =
      non_finite_ ? of_dt_.completed_before_failure(state_.steps) : of_dt_.completed(seen.steps);
  // The real-time factor over the time it ran: pauses, pre-rolls and resets do not count.
  const std::string of_sub =
      opt_.substeps > 1 ? " of " + std::to_string(opt_.substeps) + " substeps each" : std::string();
  const view::StepRates rates =
      view::step_rates(of_dt_, total_steps_, total_step_time_, loop_.shown_advanced, loop_.run_wall);
  const std::string pace = pace_text();
  char ahead[64] = "";
  if (!non_finite_ && state_.t >= seen.t + 0.005)  // (what two decimals tell apart)
    std::snprintf(ahead, sizeof ahead, " (simulated ahead to %.2f s)", state_.t);
  // --threads auto on a model that splits: how the steps were shared
  char thread_note[96] = "";
  // (of the steps it took: R sets State::steps back, the chooser keeps counting)
  if (chooser_ && chooser_->cores() > 1 && chooser_->steps_one() + chooser_->steps_many() > 0)
    std::snprintf(thread_note, sizeof thread_note, "; threads auto: %d for %.1f %% of the steps",
                  chooser_->cores(), 100.0 * chooser_->share_many());
  // what a frame cost besides its steps: drawing, the copy to the screen, events, waits
  char per_frame[64] = "";
  if (loop_.frames > 0)
    std::snprintf(per_frame, sizeof per_frame, ", %.1f ms each besides the steps",
                  1e3 * std::max(wall - total_step_time_, 0.0) / static_cast<double>(loop_.frames));
  std::printf("clothsim: viewer closed at t = %.2f s after %llu steps%s%s (%.3f ms/step, %.2fx real "
              "time over %.2f s running, %s; %ld frames in %.2f s%s%s)%s\n",
              non_finite_ ? state_.t : seen.t, static_cast<unsigned long long>(steps_done), of_sub.c_str(), ahead,
              rates.ms_per_step, rates.realtime, loop_.run_wall, pace.c_str(), loop_.frames, wall, per_frame,
              thread_note, non_finite_ ? " (state non-finite)" : "");
  if (interrupted_) {
    std::fflush(stdout);
    std::fprintf(stderr, "clothsim: interrupted at t = %.3f s\n", seen.t);
    return kInterrupted;
  }
  // closed before the picture reached a failure of the simulation ahead of it: still a failure
  if (!failure_.empty() && !non_finite_) {
    std::fflush(stdout);
    std::fprintf(stderr, "clothsim: %s, ahead of the picture\n", failure_.c_str());
    return 1;
  }
  return non_finite_ ? 1 : 0;
}

// Whether the run kept up (a clock that never dropped time lags the wall clock only by what a
// frame owes: the first picture, the last frame), and what the look-ahead did.
std::string Viewer::pace_text() const {
  char pace[160];
  if (dropped() > 0.0)
    std::snprintf(pace, sizeof pace, "fell behind: %.3g s of simulated time dropped", dropped());
  else
    std::snprintf(pace, sizeof pace, "kept up: no time dropped");
  if (playback_) {
    const std::string p = pace;
    char lowest[32] = "";  // (none when everything was computed during the pre-roll)
    if (std::isfinite(playback_->lowest_ahead()))
      std::snprintf(lowest, sizeof lowest, " (lowest %.2f s)", playback_->lowest_ahead());
    char preroll[40] = "";  // (a few milliseconds: not worth a word)
    if (playback_->preroll_wall() >= 0.005)
      std::snprintf(preroll, sizeof preroll, ", %.2f s of pre-roll", playback_->preroll_wall());
    std::snprintf(pace, sizeof pace, "%s; look-ahead %.2f s%s%s", p.c_str(), playback_->lookahead(), lowest, preroll);
  }
  return pace;
}

// The failure the simulation met (failure_), said and shown: paused on the last finite
// picture; a timed run has nobody to press R: it ends, and the exit code says it failed.
void Viewer::fail_now() {
  non_finite_ = true;
  paused_ = true;
  std::fprintf(stderr, "clothsim: %s; paused, R resets (try a smaller --dt)\n", failure_.c_str());
  if (opt_.seconds >= 0.0) glfwSetWindowShouldClose(window_, GLFW_TRUE);
  update_title();
}

// Out of the look-ahead: the state on screen becomes the simulation's (a pause, a single
// step or a drag starts from what the user sees); what was computed ahead is dropped.
void Viewer::take_back_shown() {
  if (!in_playback_) return;
  if (playback_->prerolling()) preroll_next_ = true;  // (paused before it moved: the resume pre-rolls in full)
  failure_.clear();  // (met again when it steps there)
  if (!non_finite_) state_ = ring_->front();
  ring_->clear();
  in_playback_ = false;
  clock_.reset();
}

// The title and the overlay: scene, size, time, rates, state and the keys. Keys redraw it
// with the last measured rates.
void Viewer::update_title(const view::StepRates& rates) {
  last_rates_ = rates;
  const char* status = non_finite_ ? " | NON-FINITE STATE: paused (R resets)"
                       : paused_   ? " | paused"
                       : in_playback_ && playback_->prerolling() ? " | buffering"
                       : behind_ ? " | slower than real time"
                                         : "";
  // --threads auto on a model that splits: the count it steps with now
  const std::string threads_now =
      chooser_ && chooser_->cores() > 1 ? " | " + std::to_string(ws_.threads) + (ws_.threads == 1 ? " thread" : " threads") + " (auto)"
                                        : std::string();
  const std::string stats = view::stats_text(model_.scene_name, gpu_.target.width, gpu_.target.height, shown_time(),
                                             rates, status + threads_now);
  const std::string keys = "Space pause  N step  R reset  W wire  S springs  P shot  H text  Esc quit";
  glfwSetWindowTitle(window_, (stats + " | " + keys).c_str());
  overlay_ = stats + "\n" + keys +
             "\nleft drag: pull the cloth (elsewhere: orbit)  right: orbit  middle/Shift: pan  wheel: zoom";
}

// P: the frame just drawn into clothsim_NNNN.png (the first free number) in the current folder.
void Viewer::save_numbered_screenshot() {
  for (int i = 0; i < 10000; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "clothsim_%04d.png", i);
    if (std::filesystem::exists(name)) continue;
    const std::string err = view::write_png(name, gpu_.target.width, gpu_.target.height, gpu_.target.read_rgb());
    if (err.empty()) std::printf("clothsim: wrote %s\n", name);
    else std::fprintf(stderr, "clothsim: %s\n", err.c_str());
    return;
  }
}

}  // namespace clothsim
