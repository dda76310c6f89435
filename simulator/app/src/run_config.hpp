// One run of the clothsim program as the command line asks for it, and the stages that turn it
// into a run: parse -> check -> build and plan -> run (headless or in the viewer) -> report.
#pragma once

#include <clothsim/sim.hpp>
#include <clothsim/stability.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace b2o { struct Scene; }

namespace clothsim::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInterrupted = 130;  // 128 + SIGINT, as a shell reports Ctrl-C

/// The most steps of h (substeps included) one run may take: 1e9 steps are ~1 h of the smallest
/// scene and days of the skirt; beyond it a typo (--dt 1e-30) would run for ever.
inline constexpr std::uint64_t kMaxSteps = 1'000'000'000;

/// Everything the command line decided. `given` says which options the user wrote.
struct RunConfig {
  Options options;                 ///< the scene's baked values with the command line's on top
  Options scene_options;           ///< the scene's baked values alone (for --help and notes)
  std::vector<std::string> unknown_params;  ///< baked keys that are no option
  bool headless = false, quiet = false;
  // length: --steps N, or --seconds T (default 20 headless; a window runs until closed)
  std::optional<std::uint64_t> steps;
  std::optional<double> seconds;
  double default_seconds = 20.0;
  // threads and the stability guard
  bool auto_threads = true;
  int threads = 1;                 ///< when not auto: the count asked (0: all cores)
  SubstepPolicy substeps;
  // outputs of a headless run
  std::string report, export_dir;
  std::uint64_t export_every = 10;
  bool export_every_given = false;
  bool check_crossings = false;    ///< count the cloth's self-crossings every kCrossingsEvery s
  // the viewer
  std::string screenshot, frames;
  int fps = 30, width = 1280, height = 720;
  bool no_vsync = false, paused = false;
  double lookahead = 3.0;
  std::vector<std::string> viewer_options_given;  ///< the viewer-only flags the user wrote
  bool lookahead_given = false, fps_given = false;

  std::vector<std::string> options_given;  ///< the table options the user wrote (names)

  bool timed() const { return steps.has_value() || seconds.has_value(); }
  bool given(std::string_view name) const {
    for (const std::string& n : options_given)
      if (n == name) return true;
    return false;
  }
  /// The steps of dt the run takes: --steps, or the whole steps covering --seconds (or the
  /// default time, headless); 0 for a window that runs until closed.
  double step_count() const;
};

/// What the command line asked, or an exit code (help, version, or bad input, already said).
struct Parsed {
  std::optional<RunConfig> config;
  int exit_code = kExitOk;
};
Parsed parse_command_line(int argc, char** argv, const b2o::Scene& scene);

/// The checks between options, and of output paths, before anything runs; empty, or the error
/// (bad input, exit 2).
std::string check_config(const RunConfig& config, const b2o::Scene& scene);

/// The steps of dt that cover `seconds`: seconds / dt when that is a whole number (up to
/// rounding), else rounded up, so that a run lasts at least the time asked; 0 s is 0 steps.
double steps_covering(double seconds, double dt);

/// A number as the messages show it (6 significant digits).
std::string fmt(double v);

/// Writes "clothsim: error: <msg>" and returns kExitBadInput.
int bad_input(const std::string& msg);

}  // namespace clothsim::app
