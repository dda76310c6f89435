// The window, the GL resources and the loops (interactive and offscreen). Everything the
// viewer computes without GL lives in camera/pacing/cloth_mesh, which are unit-tested.
#include <clothsim/viewer.hpp>

#include <blender2ogl/scene_types.h>
#include <clothsim/output_file.hpp>
#include <clothsim/sim.hpp>
#include <clothsim/step.hpp>
#include <clothsim/thread_choice.hpp>
#include <clothsim/view/camera.hpp>
#include <clothsim/view/cloth_mesh.hpp>
#include <clothsim/view/pacing.hpp>
#include <clothsim/view/playback.hpp>

#include "gl_scene.hpp"
#include "png_io.hpp"

#include <GL/glew.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <deque>
#include <limits>
#include <optional>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace clothsim {

const char* viewer_help_text() {
  return "Viewer keys and mouse:\n"
         "  Space          pause / resume\n"
         "  N or .         single step (while paused)\n"
         "  R              reset to t = 0\n"
         "  W              wireframe on/off\n"
         "  S              show springs (structural red, bend green)\n"
         "  P              screenshot: clothsim_NNNN.png in the current directory\n"
         "  H              text overlay (time, rates, keys) on/off\n"
         "  Esc or Q       quit\n"
         "  left drag      on the cloth: pull that point; elsewhere: orbit\n"
         "  right drag     orbit\n"
         "  middle drag or Shift+left drag   pan\n"
         "  wheel          zoom\n";
}

namespace {

std::string g_glfw_error;  // the last GLFW error, for the one-line message

void on_glfw_error(int code, const char* what) {
  g_glfw_error = std::string(what ? what : "unknown") + " (GLFW error " + std::to_string(code) + ")";
}

using Clock = std::chrono::steady_clock;

struct GlfwSession {
  GLFWwindow* window = nullptr;
  ~GlfwSession() {
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
  }
};

std::string no_display_hint() {
  const char* d = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  if ((!d || !*d) && (!w || !*w)) return "; no DISPLAY is set: run it under `xvfb-run -a`";
  return "";
}

class Viewer {
 public:
  Viewer(const b2o::Scene& scene, const Model& model, const ViewerOptions& opt)
      : scene_(scene), model_(model), opt_(opt), state_(make_state(model)),
        ws_(make_workspace(model)), clock_(model.options.dt, opt.max_work_per_frame),
        of_dt_{opt.substeps} {
    paused_ = opt.paused;
    if (opt.auto_threads) chooser_.emplace(step_splits(model) ? core_count() : 1);
    // The drag's reach: twice the mean structural rest length (a cursor far away pulls like a
    // spring stretched by that much, so the grabbed point follows instead of being flung).
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t s = 0; s < model.spring_count(); ++s)
      if (model.spring_kind[s] == 0) sum += model.rest_length0[s], ++count;
    if (count > 0 && sum > 0.0) drag_reach_ = 2.0 * sum / static_cast<double>(count);
    wireframe_ = opt.wireframe;
    show_springs_ = opt.show_springs;
  }

  int run(GLFWwindow* window) {
    window_ = window;
    gpu_.init(scene_, model_);  // throws std::runtime_error with a one-line reason
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    const bool offscreen = !opt_.screenshot.empty() || !opt_.frames_dir.empty();
    if (offscreen) {
      fw = opt_.width;
      fh = opt_.height;
    }
    Eigen::Vector3d lo, hi;
    view::framing_box(scene_, model_, lo, hi);
    camera_.frame(lo, hi, static_cast<double>(fw) / std::max(fh, 1));
    // An interactive window on a software renderer draws without multisampling (4x costs
    // ~15 ms of CPU a frame at 1280x720 on llvmpipe), straight into the window (no copy);
    // --screenshot and --frames, drawn offscreen, keep both.
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const bool software = renderer && view::software_renderer(renderer);
    if (!offscreen && software) {
      gpu_.target.max_samples = 0;
      gpu_.target.to_window = true;
      // and keeps the background, floor and colliders of the last camera, so that a frame
      // draws only the cloth again (skirt_hires, llvmpipe, 1280x720: docs/performance.md)
      gpu_.cache_static = true;
    }
    software_ = software;
    if (!gpu_.target.resize(fw, fh))
      throw std::runtime_error("cannot make a " + std::to_string(fw) + "x" + std::to_string(fh) +
                               " OpenGL framebuffer (too large for this GL?)");
    gpu_.upload_state(scene_, model_, state_, true);
    return offscreen ? run_offscreen() : run_interactive();
  }

 private:
  // --- offscreen: --screenshot / --frames ----------------------------------------------
  bool stop_asked() const { return opt_.interrupted != nullptr && *opt_.interrupted != 0; }

  // `written`: what the output holds if it stops here (said when the state blows up).
  bool advance_to(double t, const std::string& written) {
    const double dt = model_.options.dt;
    while (state_.t < t - 0.5 * dt) {
      if (stop_asked()) return false;
      if (!timed_step().finite) {
        std::fprintf(stderr, "clothsim: the simulation became non-finite at t = %.3f s (%s); "
                     "%s (try a smaller --dt)\n", state_.t,
                     of_dt_.step_label(state_.steps).c_str(), written.c_str());
        return false;
      }
    }
    return true;
  }

  bool render_to_png(const std::string& path) {
    gpu_.upload_state(scene_, model_, state_, show_springs_);
    render();
    std::vector<unsigned char> rgb = gpu_.target.read_rgb();
    std::string err = view::write_png(path, gpu_.target.width, gpu_.target.height, rgb);
    if (!err.empty()) {
      std::fprintf(stderr, "clothsim: %s\n", err.c_str());
      return false;
    }
    return true;
  }

  int interrupted_offscreen(const char* what) const {
    std::fprintf(stderr, "clothsim: interrupted at t = %.3f s; %s\n", state_.t, what);
    return kInterrupted;
  }

  int run_offscreen() {
    if (!opt_.screenshot.empty()) {
      if (!advance_to(std::max(opt_.seconds, 0.0), "no picture written"))
        return stop_asked() ? interrupted_offscreen("no picture written") : 1;
      if (!render_to_png(opt_.screenshot)) return 1;
    }
    if (!opt_.frames_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(opt_.frames_dir, ec);
      if (ec) {
        std::fprintf(stderr, "clothsim: %s: cannot create the frames directory: %s\n",
                     opt_.frames_dir.c_str(), ec.message().c_str());
        return 1;
      }
      state_ = make_state(model_);
      const long frames = static_cast<long>(std::floor(opt_.seconds * opt_.fps + 1e-9)) + 1;
      for (long i = 0; i < frames; ++i) {
        const std::string done = std::to_string(i) + " of " + std::to_string(frames) + " frames written (each whole)";
        if (!advance_to(static_cast<double>(i) / opt_.fps, done) || stop_asked()) {
          if (!stop_asked()) return 1;
          return interrupted_offscreen(done.c_str());
        }
        char name[32];
        std::snprintf(name, sizeof name, "frame_%05ld.png", i);
        if (!render_to_png((std::filesystem::path(opt_.frames_dir) / name).string())) return 1;
      }
    }
    return 0;
  }

  // --- interactive -----------------------------------------------------------------------
  int run_interactive() {
    interactive_ = true;
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

    // The look-ahead (--lookahead): a ring of states the picture plays while the simulation
    // runs ahead of it (view/playback.hpp).
    if (opt_.lookahead > 0.0) {
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

    // A first picture before the clock starts: a GL may compile the shaders at their first
    // draw (llvmpipe does), time the simulation would otherwise owe from t = 0.
    render();
    glFinish();
    auto last = Clock::now();
    const auto run_start = last;
    auto last_frame = last;
    long frames = 0;
    auto window_start = last;
    double window_shown_start = shown_time(), window_step_time = 0.0, window_dropped = 0.0;
    std::uint64_t window_steps = 0;
    // For the closing line: wall time while running (not paused, not pre-rolling) and the
    // picture's time advanced (R sets t back; pauses do not count).
    double run_wall = 0.0, shown_advanced = 0.0, previous_shown = shown_time();
    update_title(view::StepRates{});
    const double dt = model_.options.dt;
    const auto at_end = [&] { return opt_.seconds >= 0.0 && state_.t >= opt_.seconds - 0.5 * dt; };
    // Whether the ring has room for what the next step leaves: a state every snap_every_ model
    // steps, and the last one of a timed run (judged early, never late: keeps_state()).
    const auto room = [&] {
      return !ring_->full() || !view::keeps_state(state_.steps + 1, snap_every_, state_.t, dt, opt_.seconds);
    };
    // Steps timed together: the cost estimate, the counts and the failure handling.
    const auto steps_for = [&](auto more) {
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
      window_steps += static_cast<std::uint64_t>(done);
      window_step_time += spent;
      total_steps_ += static_cast<std::uint64_t>(done);
      total_step_time_ += spent;
    };
    while (!glfwWindowShouldClose(window_)) {
      glfwPollEvents();
      if (stop_asked()) {
        interrupted_ = true;
        break;
      }
      // Into the look-ahead when running freely; out of it (the picture's state taken back,
      // in the key and mouse handlers) to pause, single-step or drag.
      if (playback_ && !in_playback_ && !paused_ && !dragging_ && !non_finite_) {
        ring_->clear();
        ring_->push(state_);
        playback_->restart(state_.t, preroll_next_);  // the first start and every R pre-roll
        preroll_next_ = false;
        in_playback_ = true;
        update_title();  // ("buffering")
      }
      const auto now = Clock::now();
      const double elapsed = std::chrono::duration<double>(now - last).count();
      last = now;
      bool draw = true;
      if (in_playback_) {
        const bool was_prerolling = playback_->prerolling();
        playback_->advance(elapsed, ring_->back().t, !at_end() && !non_finite_ && failure_.empty());
        if (!paused_ && !was_prerolling) run_wall += elapsed;
        if (was_prerolling != playback_->prerolling()) update_title();
        ring_->show(playback_->shown(), 0.5 * dt);
        // a timed run closes once the picture shows its last state; a failure ahead is met
        // once the picture shows the last finite one
        if (at_end() && ring_->size() == 1) glfwSetWindowShouldClose(window_, GLFW_TRUE);
        if (!failure_.empty() && !non_finite_ && ring_->size() == 1 && playback_->shown() >= ring_->back().t)
          fail_now();
        const bool stepping = !paused_ && !non_finite_ && failure_.empty() && !at_end();
        const auto act = playback_->next(std::chrono::duration<double>(now - last_frame).count(), ring_->back().t,
                                         state_.t, stepping && room(), frame_cost_);
        draw = act.kind == view::Playback::Action::Draw || glfwWindowShouldClose(window_);
        if (!draw) {
          const auto due = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(act.seconds));
          if (act.kind == view::Playback::Action::Step) {
            // steps until the next frame is due (at most 50 ms, for the events), the look-ahead
            // is full, or the ring has no room for the next state
            const auto until = std::min(due, now + std::chrono::milliseconds(50));
            steps_for([&](long) {
              return failure_.empty() && !at_end() && playback_->wants_steps(state_.t) && room() &&
                     Clock::now() < until;
            });
          } else {
            glfwWaitEventsTimeout(std::max(act.seconds, 1e-3));
          }
        }
      } else {
        if (!paused_) run_wall += elapsed;
        long n = 0;
        if (!paused_) {
          n = clock_.steps_due(elapsed, step_cost_);
        } else {
          clock_.reset();
          n = pending_steps_;  // N presses, each one step of dt, even several within one frame
        }
        // paused with nothing to step: frames at most 60 per second (it drew as fast as it could);
        // a requested screenshot is drawn at once
        if (paused_ && pending_steps_ == 0 && !dragging_ && !screenshot_request_) {
          const double since = std::chrono::duration<double>(now - last_frame).count();
          if (since < view::Playback::kMinFrameInterval) {
            glfwWaitEventsTimeout(view::Playback::kMinFrameInterval - since);
            continue;
          }
        }
        pending_steps_ = 0;
        if (opt_.seconds >= 0.0) {  // a timed run: stop exactly at the requested time
          const long left = static_cast<long>(std::llround((opt_.seconds - state_.t) / dt));
          n = std::min(n, std::max(left, 0L));
          if (left <= 0) glfwSetWindowShouldClose(window_, GLFW_TRUE);
        }
        if (n > 0) steps_for([&](long done) { return done < n; });
      }
      const double shown = shown_time();  // (R sets it back: no advance)
      shown_advanced += std::max(shown - previous_shown, 0.0);
      previous_shown = shown;
      if (draw) {
        const auto t0 = Clock::now();
        if (!non_finite_) gpu_.upload_state(scene_, model_, in_playback_ ? ring_->front() : state_,
                                            show_springs_ || dragging_);
        render();
        gpu_.target.blit_to_window();
        if (screenshot_request_) {
          screenshot_request_ = false;
          save_numbered_screenshot();
          replay_deferred();
        }
        glfwSwapBuffers(window_);
        // A software renderer drawing on the cores the simulation's threads all use: let it
        // finish the frame before the next steps. Left to overlap them, its threads stalled the
        // steps' barriers (skirt_hires, two threads on two cores, llvmpipe: 0.385-0.401 ->
        // 0.367-0.370 ms per step). With a core to spare the overlap pays (one thread: 0.54x
        // real time with it, 0.48-0.52x without).
        if (finish_frames()) glFinish();
        last_frame = t0;  // intervals run from a frame's start (Playback::next)
        const double cost = std::chrono::duration<double>(Clock::now() - t0).count();
        frame_cost_ = frame_cost_ > 0.0 ? 0.8 * frame_cost_ + 0.2 * cost : cost;
        ++frames;
      }

      const double wall = std::chrono::duration<double>(Clock::now() - window_start).count();
      if (stats_reset_) {  // R: the rates start again from the reset state
        stats_reset_ = false;
        window_start = Clock::now();
        window_shown_start = shown_time();
        previous_shown = window_shown_start;
        window_steps = 0;
        window_step_time = 0.0;
      } else if (wall >= 0.5) {
        const double dropped_now = dropped();
        behind_ = dropped_now > window_dropped || clock_.behind();
        window_dropped = dropped_now;
        update_title(view::step_rates(of_dt_, window_steps, window_step_time, shown_time() - window_shown_start, wall));
        window_start = Clock::now();
        window_shown_start = shown_time();
        window_steps = 0;
        window_step_time = 0.0;
      }
    }
    const double wall = std::chrono::duration<double>(Clock::now() - run_start).count();
    // The picture's state: the one the user saw last (the simulation may have gone ahead).
    const State& seen = in_playback_ && !non_finite_ ? ring_->front() : state_;
    // Steps of the user's dt (substeps x the model's dt), as the headless summary counts them;
    // a failed run counts those before the failing one, as its report does.
    const std::uint64_t steps_done =
        non_finite_ ? of_dt_.completed_before_failure(state_.steps) : of_dt_.completed(seen.steps);
    // The real-time factor over the time it ran: pauses, pre-rolls and resets do not count.
    const std::string of_sub =
        opt_.substeps > 1 ? " of " + std::to_string(opt_.substeps) + " substeps each" : std::string();
    const view::StepRates rates = view::step_rates(of_dt_, total_steps_, total_step_time_, shown_advanced, run_wall);
    // Whether it kept up: a clock that never dropped time lags the wall clock only by what a
    // frame owes (the first picture, the last frame), which a ratio over a short run shows.
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
    if (frames > 0)
      std::snprintf(per_frame, sizeof per_frame, ", %.1f ms each besides the steps",
                    1e3 * std::max(wall - total_step_time_, 0.0) / static_cast<double>(frames));
    std::printf("clothsim: viewer closed at t = %.2f s after %llu steps%s%s (%.3f ms/step, %.2fx real "
                "time over %.2f s running, %s; %ld frames in %.2f s%s%s)%s\n",
                non_finite_ ? state_.t : seen.t, static_cast<unsigned long long>(steps_done), of_sub.c_str(), ahead,
                rates.ms_per_step, rates.realtime, run_wall, pace, frames, wall, per_frame, thread_note,
                non_finite_ ? " (state non-finite)" : "");
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

  // The failure the simulation met (failure_), said and shown: paused on the last finite
  // picture; a timed run has nobody to press R: it ends, and the exit code says it failed.
  void fail_now() {
    non_finite_ = true;
    paused_ = true;
    std::fprintf(stderr, "clothsim: %s; paused, R resets (try a smaller --dt)\n", failure_.c_str());
    if (opt_.seconds >= 0.0) glfwSetWindowShouldClose(window_, GLFW_TRUE);
    update_title();
  }

  // The time of the state on screen.
  double shown_time() const { return in_playback_ ? ring_->front().t : state_.t; }
  double dropped() const { return clock_.dropped() + (playback_ ? playback_->dropped() : 0.0); }

  // Out of the look-ahead: the state on screen becomes the simulation's (a pause, a single
  // step or a drag starts from what the user sees); what was computed ahead is dropped.
  void take_back_shown() {
    if (!in_playback_) return;
    if (playback_->prerolling()) preroll_next_ = true;  // (paused before it moved: the resume pre-rolls in full)
    failure_.clear();  // (met again when it steps there)
    if (!non_finite_) state_ = ring_->front();
    ring_->clear();
    in_playback_ = false;
    clock_.reset();
  }
  // Keys redraw the title with the last measured rates (they are measured every 0.5 s).
  void update_title() { update_title(last_rates_); }

  void update_title(const view::StepRates& rates) {
    last_rates_ = rates;
    const char* status = non_finite_ ? " | NON-FINITE STATE: paused (R resets)"
                         : paused_   ? " | paused"
                         : in_playback_ && playback_->prerolling() ? " | buffering"
                         : behind_ ? " | slower than real time"
                                           : "";
    // --threads auto on a model that splits: the count it steps with now
    const std::string threads_now =
        chooser_ && chooser_->cores() > 1 ? " | " + std::to_string(threads()) + (threads() == 1 ? " thread" : " threads") + " (auto)"
                                          : std::string();
    const std::string stats = view::stats_text(model_.scene_name, gpu_.target.width, gpu_.target.height, shown_time(),
                                               rates, status + threads_now);
    const std::string keys = "Space pause  N step  R reset  W wire  S springs  P shot  H text  Esc quit";
    glfwSetWindowTitle(window_, (stats + " | " + keys).c_str());
    overlay_ = stats + "\n" + keys +
               "\nleft drag: pull the cloth (elsewhere: orbit)  right: orbit  middle/Shift: pan  wheel: zoom";
  }

  void save_numbered_screenshot() {
    for (int i = 0; i < 10000; ++i) {
      char name[32];
      std::snprintf(name, sizeof name, "clothsim_%04d.png", i);
      if (std::filesystem::exists(name)) continue;
      const std::string err =
          view::write_png(name, gpu_.target.width, gpu_.target.height, gpu_.target.read_rgb());
      if (err.empty()) std::printf("clothsim: wrote %s\n", name);
      else std::fprintf(stderr, "clothsim: %s\n", err.c_str());
      return;
    }
  }

  // An input event as GLFW gives it: key (key, action), button (button, action, mods),
  // cursor (x, y) or scroll (y).
  struct Input {
    enum Kind { Key, Button, Cursor, Scroll } kind;
    int code, action, mods;
    double x, y;
  };

  // P saves the picture as of its press: the input after it waits until the screenshot is
  // taken (a Q right after P still gets its picture; a drag released after P is in it).
  void input(const Input& e) {
    if (screenshot_request_ || !deferred_.empty()) deferred_.push_back(e);
    else apply(e);
  }

  void apply(const Input& e) {
    switch (e.kind) {
      case Input::Key: on_key(e.code, e.action); break;
      case Input::Button: on_button(e.code, e.action, e.mods); break;
      case Input::Cursor: on_cursor(e.x, e.y); break;
      case Input::Scroll: camera_.zoom(e.y); break;
    }
  }

  // After a screenshot: the input that waited for it, in order, up to the next P.
  void replay_deferred() {
    while (!deferred_.empty() && !screenshot_request_) {
      const Input e = deferred_.front();
      deferred_.pop_front();
      apply(e);
    }
  }

  void on_key(int key, int action) {
    switch (key) {
      case GLFW_KEY_ESCAPE:
      case GLFW_KEY_Q: glfwSetWindowShouldClose(window_, GLFW_TRUE); break;
      case GLFW_KEY_SPACE:
        if (action == GLFW_PRESS && !non_finite_) {
          if (!paused_) take_back_shown();  // paused where the picture is
          paused_ = !paused_;
        }
        break;
      case GLFW_KEY_N:
      case GLFW_KEY_PERIOD:
        if (!non_finite_) {
          take_back_shown();
          paused_ = true;
          // One step of the user's dt, all its substeps: the state stays on a whole step, as
          // every count the viewer shows is of whole steps of dt.
          pending_steps_ += std::max(opt_.substeps, 1);
        }
        break;
      case GLFW_KEY_R:
        if (in_playback_) ring_->clear();  // what was computed ahead is of the old run
        in_playback_ = false;
        preroll_next_ = true;
        failure_.clear();
        state_ = make_state(model_);
        stats_reset_ = true;
        dragging_ = false;
        non_finite_ = false;
        gpu_.upload_state(scene_, model_, state_, true);
        break;
      case GLFW_KEY_W:
        if (action == GLFW_PRESS) wireframe_ = !wireframe_;
        break;
      case GLFW_KEY_S:
        if (action == GLFW_PRESS) show_springs_ = !show_springs_;
        break;
      case GLFW_KEY_P:
        if (action == GLFW_PRESS) screenshot_request_ = true;
        break;
      case GLFW_KEY_H:
        if (action == GLFW_PRESS) show_overlay_ = !show_overlay_;
        break;
      default: break;
    }
    update_title();
  }

  view::Ray cursor_ray() const {
    int ww = 0, wh = 0;
    glfwGetWindowSize(window_, &ww, &wh);
    return camera_.ray(cursor_x_, cursor_y_, ww, wh);
  }

  void on_button(int button, int action, int mods) {
    if (action == GLFW_RELEASE) {
      mode_ = Mouse::None;
      if (dragging_) {
        dragging_ = false;
        state_.drag = Drag{};
      }
      return;
    }
    if (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT)) mode_ = Mouse::Pan;
    else if (button == GLFW_MOUSE_BUTTON_MIDDLE) mode_ = Mouse::Pan;
    else if (button == GLFW_MOUSE_BUTTON_RIGHT) mode_ = Mouse::Orbit;
    else if (button == GLFW_MOUSE_BUTTON_LEFT) {
      const view::Ray ray = cursor_ray();
      // (on the state on screen; a grab takes it back from the look-ahead and pulls from there)
      const view::Pick pick =
          view::pick_mass(scene_, model_, in_playback_ ? ring_->front() : state_, ray, 0.02 * camera_.distance);
      if (pick.mass >= 0 && !non_finite_) {
        take_back_shown();
        dragging_ = true;
        mode_ = Mouse::Drag;
        drag_depth_ = (ray.origin + pick.t * ray.dir - camera_.eye()).dot(camera_.forward());
        state_.drag.mass = pick.mass;
        state_.drag.k = model_.options.k_struct;  // as stiff as one cloth spring: stable at dt
        state_.drag.reach = drag_reach_;          // a far target pulls like one two springs away
        update_drag_target();
      } else {
        mode_ = Mouse::Orbit;
      }
    }
  }

  void update_drag_target() {
    if (!dragging_) return;
    Eigen::Vector3d target;
    if (view::point_at_depth(cursor_ray(), camera_.eye(), camera_.forward(), drag_depth_, target))
      state_.drag.target = target;
  }

  void on_cursor(double x, double y) {
    const double dx = x - cursor_x_, dy = y - cursor_y_;
    cursor_x_ = x;
    cursor_y_ = y;
    int fh = 0;
    glfwGetWindowSize(window_, nullptr, &fh);
    switch (mode_) {
      case Mouse::Orbit: camera_.orbit(dx, dy); break;
      case Mouse::Pan: camera_.pan(dx, dy, fh); break;
      case Mouse::Drag: update_drag_target(); break;
      case Mouse::None: break;
    }
  }

  // One step, with the thread count --threads auto chooses (else the one set).
  StepStatus timed_step() {
    return chooser_ ? chosen_step(*chooser_, model_, state_, ws_) : step(model_, state_, ws_);
  }

  // glFinish() after each frame (see the main loop): a software renderer while the steps'
  // threads take every core.
  bool finish_frames() const {
    return software_ && threads() > 1 && threads() >= core_count();
  }

  void render() {
    view::RenderFlags flags;
    flags.wireframe = wireframe_;
    flags.springs = show_springs_;
    flags.flat_cloth = opt_.flat_cloth;
    flags.hide_cloth = opt_.hide_cloth;
    if (interactive_ && show_overlay_) flags.overlay = overlay_;
    flags.drag_mass = dragging_ ? state_.drag.mass : -1;
    flags.drag_target = state_.drag.target;
    const double aspect = static_cast<double>(gpu_.target.width) / std::max(gpu_.target.height, 1);
    gpu_.draw(scene_, model_, camera_.projection(aspect) * camera_.view(), camera_.eye(), flags);
  }

  enum class Mouse { None, Orbit, Pan, Drag };

  const b2o::Scene& scene_;
  const Model& model_;
  ViewerOptions opt_;
  State state_;
  Workspace ws_;
  view::StepClock clock_;  ///< in steps of the model's dt (substeps)
  view::StepsOfDt of_dt_;  ///< what every text counts: steps of the user's dt
  view::OrbitCamera camera_;
  view::GlScene gpu_;
  GLFWwindow* window_ = nullptr;
  double step_cost_ = 0.0;
  // --- the look-ahead (--lookahead; view/playback.hpp) ---
  static constexpr std::size_t kRingBytes = std::size_t{128} << 20;  ///< the ring's memory at most
  std::optional<view::StateRing> ring_;   ///< the states ahead of the picture (front: on screen)
  std::optional<view::Playback> playback_;
  std::uint64_t snap_every_ = 1;          ///< model steps between the ring's states
  bool in_playback_ = false;              ///< the picture plays the ring (else it shows state_)
  bool preroll_next_ = true;              ///< the next start pre-rolls (the first, and after R)
  bool behind_ = false;                   ///< time was dropped in the last half second
  std::string failure_;                   ///< the simulation went non-finite (said when shown)
  double frame_cost_ = 0.0;               ///< s per frame, smoothed
  std::uint64_t total_steps_ = 0;         ///< model steps taken in the window, and their time
  double total_step_time_ = 0.0;
  bool software_ = false;  ///< the GL draws on the CPU
  std::optional<ThreadChooser> chooser_;  ///< --threads auto
  double drag_reach_ = std::numeric_limits<double>::infinity();
  bool stats_reset_ = false;  ///< R was pressed: the title's rates start again
  bool paused_ = false, non_finite_ = false, interrupted_ = false;
  static constexpr int kInterrupted = 130;  ///< as a shell reports Ctrl-C
  long pending_steps_ = 0;
  bool wireframe_ = false, show_springs_ = false, screenshot_request_ = false;
  bool dragging_ = false;
  bool interactive_ = false, show_overlay_ = true;
  std::deque<Input> deferred_;  ///< input after a P whose screenshot is not taken yet
  std::string overlay_;
  view::StepRates last_rates_;
  double drag_depth_ = 0.0;
  Mouse mode_ = Mouse::None;
  double cursor_x_ = 0.0, cursor_y_ = 0.0;
};

std::string check_options(const ViewerOptions& o) {
  // 8192 keeps a 4x multisampled target under ~2 GB; GL may allow less (checked at resize).
  if (o.width < 16 || o.width > 8192 || o.height < 16 || o.height > 8192)
    return "window size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
           " is outside 16..8192";
  if (!o.frames_dir.empty() && (o.fps < 1 || o.fps > 1000))
    return "--fps " + std::to_string(o.fps) + " is outside 1..1000";
  if (!o.frames_dir.empty() && !(o.seconds >= 0.0))
    return "--frames needs --seconds T (how much simulated time to record)";
  if (!std::isfinite(o.seconds) || o.seconds > 1e6) return "--seconds must be a finite time";
  // The output paths before the window opens and the simulation runs (the writes check again).
  if (!o.screenshot.empty())
    if (std::string why = io::check_output_file(o.screenshot); !why.empty()) return "--screenshot: " + why;
  if (!o.frames_dir.empty())
    if (std::string why = io::check_output_dir(o.frames_dir); !why.empty()) return "--frames: " + why;
  if (!(o.max_work_per_frame > 0.0)) return "max_work_per_frame must be positive";
  return {};
}

}  // namespace

int run_viewer(const b2o::Scene& scene, const Model& model, const ViewerOptions& given) {
  ViewerOptions options = given;
  // Test modes and start toggles can also be set from outside, so tests and docs can use the
  // real program: CLOTHSIM_VIEWER_TEST=flat-cloth,hide-cloth,springs,wireframe (any subset).
  if (const char* test = std::getenv("CLOTHSIM_VIEWER_TEST")) {
    std::string list = test;
    for (std::size_t start = 0; start <= list.size();) {
      const std::size_t comma = std::min(list.find(',', start), list.size());
      const std::string mode = list.substr(start, comma - start);
      if (mode == "flat-cloth") options.flat_cloth = true;
      else if (mode == "hide-cloth") options.hide_cloth = true;
      else if (mode == "springs") options.show_springs = true;
      else if (mode == "wireframe") options.wireframe = true;
      else if (!mode.empty()) {
        std::fprintf(stderr, "clothsim: CLOTHSIM_VIEWER_TEST: '%s' is not one of flat-cloth, hide-cloth, "
                     "springs, wireframe\n", mode.c_str());
        return 1;
      }
      start = comma + 1;
    }
  }
  if (std::string err = check_options(options); !err.empty()) {
    std::fprintf(stderr, "clothsim: %s\n", err.c_str());
    return 1;
  }
  if (std::string err = view::check_model_matches_scene(scene, model); !err.empty()) {
    std::fprintf(stderr, "clothsim: scene '%s': %s\n", scene.name ? scene.name : "?", err.c_str());
    return 1;
  }
  const bool offscreen = !options.screenshot.empty() || !options.frames_dir.empty();
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit()) {
    std::fprintf(stderr, "clothsim: cannot start GLFW: %s%s\n", g_glfw_error.c_str(),
                 no_display_hint().c_str());
    return 1;
  }
  GlfwSession session;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, offscreen ? GLFW_FALSE : GLFW_TRUE);
  session.window = glfwCreateWindow(offscreen ? 64 : options.width, offscreen ? 64 : options.height,
                                    "clothsim", nullptr, nullptr);
  if (!session.window) {
    std::fprintf(stderr, "clothsim: cannot open an OpenGL 3.3 core window: %s%s\n",
                 g_glfw_error.c_str(), no_display_hint().c_str());
    return 1;
  }
  glfwMakeContextCurrent(session.window);
  glewExperimental = GL_TRUE;  // core profiles need it for GLEW to load everything
  if (const GLenum e = glewInit(); e != GLEW_OK) {
    std::fprintf(stderr, "clothsim: cannot load OpenGL with GLEW: %s\n",
                 reinterpret_cast<const char*>(glewGetErrorString(e)));
    return 1;
  }
  while (glGetError() != GL_NO_ERROR) {}  // glewInit's harmless INVALID_ENUM on core profiles
  glfwSwapInterval(options.vsync && !offscreen ? 1 : 0);
  try {
    Viewer viewer(scene, model, options);
    return viewer.run(session.window);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "clothsim: %s\n", e.what());
    return 1;
  }
}

}  // namespace clothsim
