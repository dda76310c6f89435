// The checks between options and of output paths, made before anything runs: a run that
// would fail at its end for a bad path, or an option that would do nothing, is bad input at once.
#include "run_config.hpp"

#include <clothsim/output_file.hpp>
#include <clothsim/scene.hpp>

#include <blender2ogl/scene_types.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace clothsim::app {

namespace {

namespace fs = std::filesystem;

// Whether `name` is prefix + at least `digits` digits + suffix: a file a run writes into a
// folder (<scene>_<step>.obj, frame_<n>.png).
bool generated_name(const std::string& name, const std::string& prefix, std::size_t digits, const std::string& suffix) {
  if (name.size() < prefix.size() + digits + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const std::string mid = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  return std::all_of(mid.begin(), mid.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A file output that names one of the files a folder output writes (a report as
// exp/dice_000000.obj): the run would replace one with the other. Empty, or why.
std::string file_among_generated(std::string_view file_option, const std::string& file, std::string_view dir_option,
                                 const std::string& dir, const std::string& prefix, std::size_t digits,
                                 const std::string& suffix) {
  if (file.empty() || dir.empty()) return {};
  const fs::path f = io::output_identity(file);
  if (f.parent_path() != fs::path(io::output_identity(dir)) || !generated_name(f.filename().string(), prefix, digits, suffix))
    return {};
  return std::string(file_option) + " '" + file + "' is one of the files " + std::string(dir_option) + " writes (" +
         prefix + std::string(digits, 'N') + suffix + "): one would replace the other; name another file";
}

// Options that only make sense with others.
std::string check_combinations(const RunConfig& c) {
  if (c.export_every_given && c.export_dir.empty()) return "--export-every needs --export-obj DIR (the OBJ files it paces)";
  if (c.headless && !c.viewer_options_given.empty())
    return c.viewer_options_given.front() + " is a viewer option, and --headless opens no viewer (drop one of them)";
  if (c.fps_given && c.frames.empty()) return "--fps needs --frames DIR (the frames it paces)";
  if (c.lookahead_given && (!c.screenshot.empty() || !c.frames.empty()))
    return "--lookahead paces the window; --screenshot and --frames step straight to their times (drop one)";
  if (!c.frames.empty() && !c.timed()) return "--frames needs --seconds T (how much simulated time to record)";
  if (!c.screenshot.empty()) {  // (a name without an extension, such as /dev/null, is written into)
    std::string ext = fs::path(c.screenshot).extension().string();
    for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (!ext.empty() && ext != ".png") return "--screenshot writes a PNG: name it *.png (got " + c.screenshot + ")";
  }
#ifdef CLOTHSIM_HAVE_VIEWER
  if (!c.headless && (!c.report.empty() || !c.export_dir.empty()))
    return "--report and --export-obj belong to headless runs: add --headless";
  if (!c.headless && c.check_crossings) return "--check-crossings belongs to headless runs: add --headless";
#endif
  return {};
}

// Output paths: a directory named as the report, a file where a folder should be, two outputs
// at one path.
std::string check_outputs(const RunConfig& c, const b2o::Scene& scene) {
  if (!c.report.empty())
    if (const std::string why = io::check_output_file(c.report); !why.empty()) return "--report: " + why;
  if (const std::string why = io::same_output(
          {{"--report", c.report}, {"--export-obj", c.export_dir}, {"--screenshot", c.screenshot}, {"--frames", c.frames}});
      !why.empty())
    return why;
  for (const auto& [option, file] :
       {std::pair<std::string_view, std::string>{"--report", c.report}, {"--screenshot", c.screenshot}}) {
    if (const std::string why = file_among_generated(option, file, "--export-obj", c.export_dir,
                                                     std::string(scene.name) + "_", 6, ".obj");
        !why.empty())
      return why;
    if (const std::string why = file_among_generated(option, file, "--frames", c.frames, "frame_", 5, ".png");
        !why.empty())
      return why;
  }
  if (!c.export_dir.empty())
    if (const std::string why = io::check_output_dir(c.export_dir); !why.empty()) return "--export-obj: " + why;
  if (!c.screenshot.empty())
    if (const std::string why = io::check_output_file(c.screenshot); !why.empty()) return "--screenshot: " + why;
  if (!c.frames.empty())
    if (const std::string why = io::check_output_dir(c.frames); !why.empty()) return "--frames: " + why;
  return {};
}

// Friction, given or baked, on a scene without colliders: it would act on nothing.
std::string check_friction(const RunConfig& c, const b2o::Scene& scene) {
  if (has_colliders(scene)) return {};
  const std::string none = "scene '" + std::string(scene.name) + "' has no colliders (every object is cloth): friction acts on nothing";
  for (const char* key : {"friction", "static_friction"})
    if (c.given(key)) return std::string(find_option(key)->flag()) + ": " + none;
  if (const std::string key = read_scene_params(scene).friction_key; !key.empty())
    return "PARAMS " + key + " baked, but " + none;
  return {};
}

}  // namespace

std::string check_config(const RunConfig& c, const b2o::Scene& scene) {
  if (std::string why = check_combinations(c); !why.empty()) return why;
  if (std::string why = check_friction(c, scene); !why.empty()) return why;
  if (std::string why = check_outputs(c, scene); !why.empty()) return why;
  if (!c.quiet)
    for (const auto& k : c.unknown_params)
      std::cerr << "clothsim: note: scene '" << scene.name << "' bakes param '" << k << "', which is no simulator option\n";
  return {};
}

double RunConfig::step_count() const {
  if (steps) return static_cast<double>(*steps);
  if (seconds) return steps_covering(*seconds, options.dt);
  return headless ? steps_covering(default_seconds, options.dt) : 0.0;
}

double steps_covering(double seconds, double dt) {
  // (seconds / dt is rounded once, by ~1e-16 of itself: 1e-12 of it is far beyond that and far
  // below half a step for any count a run may take, 1e9)
  const double r = seconds / dt, nearest = std::round(r);
  if (std::abs(r - nearest) <= 1e-12 * std::max(1.0, r)) return seconds > 0.0 ? std::max(nearest, 1.0) : nearest;
  return std::ceil(r);
}

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

int bad_input(const std::string& msg) {
  std::cerr << "clothsim: error: " << msg << "\n";
  return kExitBadInput;
}

}  // namespace clothsim::app
