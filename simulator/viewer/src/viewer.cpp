// Opens the viewer's window and GL context (run_viewer) and makes the offscreen pictures
// (--screenshot, --frames); the interactive window is interactive.cpp's.
#include <clothsim/viewer.hpp>

#include <blender2ogl/scene_types.h>
#include <clothsim/output_file.hpp>
#include <clothsim/view/cloth_mesh.hpp>

#include "png_io.hpp"
#include "viewer_impl.hpp"

#include <GL/glew.h>
#include <GLFW/glfw3.h>

#include <algorithm>
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

// The viewer's step memory: its substeps and, without --threads auto, its thread count.
Workspace viewer_workspace(const Model& model, const ViewerOptions& opt) {
  Workspace ws = make_workspace(model);
  ws.substeps = std::max(opt.substeps, 1);
  ws.threads = opt.auto_threads ? 1 : std::max(opt.threads, 1);
  return ws;
}

}  // namespace

// The state at t = 0, the options' start toggles and the drag's reach.
Viewer::Viewer(const b2o::Scene& scene, const Model& model, const ViewerOptions& opt)
    : scene_(scene), model_(model), opt_(opt), state_(make_state(model)),
      ws_(viewer_workspace(model, opt)), clock_(model.options.dt / std::max(opt.substeps, 1), opt.max_work_per_frame),
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

// Sets up the GL side and the camera for the window's size, then runs the loop the options ask for.
int Viewer::run(GLFWwindow* window) {
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

// `written`: what the output holds if it stops here (said when the state blows up).
bool Viewer::advance_to(double t, const std::string& written) {
  const double dt = h();
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

// The state's picture into a PNG file; false (said) when it cannot be written.
bool Viewer::render_to_png(const std::string& path) {
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

// Says where Ctrl-C stopped an offscreen run; returns its exit code.
int Viewer::interrupted_offscreen(const char* what) const {
  std::fprintf(stderr, "clothsim: interrupted at t = %.3f s; %s\n", state_.t, what);
  return kInterrupted;
}

// --screenshot: one picture at --seconds; --frames: one every 1/fps s up to --seconds.
int Viewer::run_offscreen() {
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

// One step, with the thread count --threads auto chooses (else the one set).
StepStatus Viewer::timed_step() {
  return chooser_ ? chosen_step(*chooser_, model_, state_, ws_) : step(model_, state_, ws_);
}

// A frame of the state on the GPU, as the flags and the camera say.
void Viewer::render() {
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

namespace {

std::string g_glfw_error;  // the last GLFW error, for the one-line message

void on_glfw_error(int code, const char* what) {
  g_glfw_error = std::string(what ? what : "unknown") + " (GLFW error " + std::to_string(code) + ")";
}

// GLFW and its window, ended on every way out of run_viewer().
struct GlfwSession {
  GLFWwindow* window = nullptr;
  ~GlfwSession() {
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
  }
};

// What to do when there is no display to open.
std::string no_display_hint() {
  const char* d = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  if ((!d || !*d) && (!w || !*w)) return "; no DISPLAY is set: run it under `xvfb-run -a`";
  return "";
}

// Empty when the options can be run, else a one-line reason.
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

// The test modes from the environment, the checks, then the window and GL context for a Viewer.
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
