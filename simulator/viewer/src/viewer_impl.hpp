// The viewer on one scene: its state and its loops. viewer.cpp opens the window and runs the
// offscreen pictures, interactive.cpp the interactive window, input.cpp its keys and mouse.
// Everything the viewer computes without GL lives in camera/pacing/cloth_mesh/playback.
#pragma once

#include <clothsim/sim.hpp>
#include <clothsim/step.hpp>
#include <clothsim/thread_choice.hpp>
#include <clothsim/view/camera.hpp>
#include <clothsim/view/pacing.hpp>
#include <clothsim/view/playback.hpp>
#include <clothsim/viewer.hpp>

#include "gl_scene.hpp"

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>

struct GLFWwindow;
namespace b2o { struct Scene; }

namespace clothsim {

class Viewer {
 public:
  Viewer(const b2o::Scene& scene, const Model& model, const ViewerOptions& opt);
  // Draws into `window` (hidden for --screenshot and --frames) until done; an exit code.
  int run(GLFWwindow* window);

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr int kInterrupted = 130;  ///< as a shell reports Ctrl-C

  // --- offscreen: --screenshot / --frames (viewer.cpp) ---
  bool stop_asked() const { return opt_.interrupted != nullptr && *opt_.interrupted != 0; }
  bool advance_to(double t, const std::string& written);
  bool render_to_png(const std::string& path);
  int interrupted_offscreen(const char* what) const;
  int run_offscreen();
  StepStatus timed_step();
  void render();

  // --- the interactive window (interactive.cpp) ---
  int run_interactive();
  void install_callbacks();
  void plan_lookahead();
  void enter_playback();
  bool play(Clock::time_point now, double elapsed);
  bool step_in_real_time(Clock::time_point now, double elapsed);
  template <class More> void step_while(More more);
  void draw_frame();
  void update_rates();
  int end_of_run();
  std::string pace_text() const;
  void fail_now();
  void take_back_shown();
  void update_title() { update_title(last_rates_); }
  void update_title(const view::StepRates& rates);
  void save_numbered_screenshot();
  bool finish_frames() const;
  // A timed run has reached its time.
  /// s, one model step: the user's dt over the substeps.
  double h() const { return model_.options.dt / ws_.substeps; }
  bool at_end() const { return opt_.seconds >= 0.0 && state_.t >= opt_.seconds - 0.5 * h(); }
  bool room() const;
  // The time of the state on screen.
  double shown_time() const { return in_playback_ ? ring_->front().t : state_.t; }
  double dropped() const { return clock_.dropped() + (playback_ ? playback_->dropped() : 0.0); }

  // --- keys and mouse (input.cpp) ---
  // An input event as GLFW gives it: key (key, action), button (button, action, mods),
  // cursor (x, y) or scroll (y).
  struct Input {
    enum Kind { Key, Button, Cursor, Scroll } kind;
    int code, action, mods;
    double x, y;
  };
  void input(const Input& e);
  void apply(const Input& e);
  void replay_deferred();
  void on_key(int key, int action);
  view::Ray cursor_ray() const;
  void on_button(int button, int action, int mods);
  void update_drag_target();
  void on_cursor(double x, double y);

  enum class Mouse { None, Orbit, Pan, Drag };

  // The interactive loop's clocks and counts: the frame's, the title's (every 0.5 s) and the
  // closing line's.
  struct LoopClock {
    Clock::time_point last, run_start, last_frame, window_start;
    long frames = 0;
    double window_shown_start = 0.0, window_step_time = 0.0, window_dropped = 0.0;
    std::uint64_t window_steps = 0;
    // wall time while running (not paused, not pre-rolling) and the picture's time advanced
    // (R sets t back; pauses do not count)
    double run_wall = 0.0, shown_advanced = 0.0, previous_shown = 0.0;
  };

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
  LoopClock loop_;
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

}  // namespace clothsim
