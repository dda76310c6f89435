// The clothsim program: parse -> check -> build and plan -> run (in the viewer, or headless)
// -> report, around one RunConfig.
#include "app.hpp"
#include "run.hpp"

#include <clothsim/output_file.hpp>

#include <blender2ogl/scene_types.h>

#ifdef CLOTHSIM_HAVE_VIEWER
#include <clothsim/viewer.hpp>
#endif

#include <signal.h>

#include <iostream>
#include <optional>

namespace clothsim {

namespace app {

volatile std::sig_atomic_t g_interrupted = 0;

namespace {

extern "C" void on_interrupt(int) { g_interrupted = 1; }

// While alive: SIGINT and SIGTERM set g_interrupted instead of ending the process, so that a
// run stops after the step in progress and still writes its report (exit 130). Made before the
// model is built: a signal during start-up also ends in a report (after 0 steps).
struct CatchInterrupt : io::SignalHandlers {
  CatchInterrupt() : io::SignalHandlers(SIGINT, SIGTERM, on_interrupt) {}
};

#ifdef CLOTHSIM_HAVE_VIEWER
int run_window(const RunConfig& c, const b2o::Scene& scene, const Plan& p) {
  ViewerOptions vo;
  vo.width = c.width;
  vo.height = c.height;
  vo.vsync = !c.no_vsync;
  vo.paused = c.paused;
  vo.lookahead = c.lookahead;
  vo.screenshot = c.screenshot;
  vo.frames_dir = c.frames;
  vo.fps = c.fps;
  vo.substeps = p.substeps.substeps;
  vo.auto_threads = c.auto_threads;
  vo.threads = c.auto_threads ? 1 : resolve_threads(c.threads);
  vo.interrupted = &g_interrupted;
  if (g_interrupted) {  // during the start-up (a large model's stability check): no window
    std::cerr << "clothsim: interrupted before the window opened\n";
    return kExitInterrupted;
  }
  // the time of the whole steps that cover --seconds, as a headless run takes (the viewer
  // rounds its own count to the nearest step)
  if (c.timed()) vo.seconds = c.step_count() * c.options.dt;
  return run_viewer(scene, p.model, vo);
}
#endif

}  // namespace
}  // namespace app

int run_app(int argc, char** argv, const b2o::Scene& scene) {
  using namespace app;
  Parsed parsed = parse_command_line(argc, argv, scene);
  if (!parsed.config) return parsed.exit_code;
  const RunConfig& c = *parsed.config;
  if (const std::string why = check_config(c, scene); !why.empty()) return bad_input(why);

  std::optional<CatchInterrupt> catch_interrupt;
  catch_interrupt.emplace();
  Plan plan;
  if (const int code = prepare(c, scene, plan); code >= 0) return code;
#ifdef CLOTHSIM_HAVE_VIEWER
  if (!c.headless) return run_window(c, scene, plan);
#endif
  RunResult result;
  if (const int code = run_headless(c, scene, plan, result); code >= 0) return code;
  catch_interrupt.reset();  // the report is written with the usual signals
  return report_run(c, plan, result);
}

}  // namespace clothsim
