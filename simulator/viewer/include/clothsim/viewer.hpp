// The OpenGL view (GLFW + GLEW, GL 3.3 core). It draws a Model + State and calls step();
// it contains no physics of its own.
#pragma once

#include <csignal>
#include <string>

namespace b2o { struct Scene; }

namespace clothsim {
struct Model;

struct ViewerOptions {
  int width = 1280, height = 720;
  bool vsync = true;
  bool paused = false;          ///< start paused
  std::string screenshot;       ///< non-empty: render at `seconds`, write this PNG, exit
  std::string frames_dir;       ///< non-empty: write a PNG sequence at `fps` up to `seconds`
  int fps = 30;
  double seconds = -1.0;        ///< simulated seconds for screenshot/frames; in the window: close at
                                ///< this simulated time (real-time pace); < 0: run until closed
  // --- test modes, start toggles and how the window runs ---
  bool flat_cloth = false;      ///< test mode: cloth drawn unlit in kFlatClothRgb, no texture
  bool hide_cloth = false;      ///< test mode: draw the colliders only
  bool show_springs = false;    ///< start with springs shown (key S toggles)
  bool wireframe = false;       ///< start in wireframe (key W toggles)
  /// s of simulated time the window may compute ahead of the picture (0: none, the picture
  /// shows each state as it is computed). Heavy seconds then borrow from cheap ones; the first
  /// start and every R pre-roll half of it (the picture waits, at most 2 s of wall time).
  /// A pause, a single step or a grab takes back the state on screen.
  double lookahead = 3.0;
  double max_work_per_frame = 0.1;  ///< s of stepping per frame at most; beyond it run slower than real time
  /// Each step of the model's dt is taken in this many steps of dt / substeps (the stability
  /// guard): every count and rate the viewer shows (title, overlay, stderr, closing line) is
  /// of steps of dt, as the headless run's, and N takes one such step.
  int substeps = 1;
  /// --threads auto: step with one thread or all cores, whichever a ThreadChooser measures
  /// faster (thread_choice.hpp); false: `threads` threads.
  bool auto_threads = false;
  int threads = 1;
  /// Set (non-zero) by the caller's SIGINT/SIGTERM handler: the viewer stops at the next frame
  /// or step, says so, and run_viewer() returns 130. Null: the signals end the process.
  const volatile std::sig_atomic_t* interrupted = nullptr;
};

/// The flat cloth colour of ViewerOptions::flat_cloth (8-bit RGB), for tests that look for it.
inline constexpr unsigned char kFlatClothRgb[3] = {255, 0, 255};

/// The viewer's keys and mouse buttons, one per line, for the app's --help.
const char* viewer_help_text();

/// Opens the window (hidden for screenshot/frames) and runs until it is closed or the
/// screenshot/frames are written. Returns a process exit code (0 on success); prints errors.
int run_viewer(const b2o::Scene& scene, const Model& model, const ViewerOptions& options);

}  // namespace clothsim
