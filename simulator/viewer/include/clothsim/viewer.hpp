// The OpenGL view (GLFW + GLEW, GL 3.3 core). It draws a Model + State and calls step();
// it contains no physics of its own.
#pragma once

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
  double seconds = -1.0;        ///< simulated seconds for screenshot/frames; < 0: run until closed
};

/// Opens the window (hidden for screenshot/frames) and runs until it is closed or the
/// screenshot/frames are written. Returns a process exit code (0 on success); prints errors.
int run_viewer(const b2o::Scene& scene, const Model& model, const ViewerOptions& options);

}  // namespace clothsim
