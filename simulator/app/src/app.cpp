#include "app.hpp"

#include <clothsim/closed_mesh.hpp>
#include <clothsim/integrators.hpp>
#include <clothsim/output_file.hpp>
#include <clothsim/scene.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>
#include <clothsim/thread_choice.hpp>

#include <blender2ogl/scene_types.h>

#ifdef CLOTHSIM_HAVE_VIEWER
#include <clothsim/viewer.hpp>
#endif

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <optional>
#include <csignal>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#ifndef CLOTHSIM_VERSION
#define CLOTHSIM_VERSION "0.0.0"
#endif

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

constexpr int kExitFailed = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitInterrupted = 130;  // 128 + SIGINT, as a shell reports Ctrl-C

// Ctrl-C (SIGINT) or SIGTERM during a headless run: the run stops after the step in progress,
// and the summary and the report say where ("interrupted": true).
volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int) { g_interrupted = 1; }

// While alive: SIGINT and SIGTERM set g_interrupted instead of ending the process. Made before
// the model is built, so that a signal during start-up also ends in a report (after 0 steps).
struct CatchInterrupt : io::SignalHandlers {
  CatchInterrupt() : io::SignalHandlers(SIGINT, SIGTERM, on_interrupt) {}
};

// The most steps of h (substeps included) one run may take: 1e9 steps are ~1 h of the smallest
// scene and days of the skirt; beyond it a typo (--dt 1e-30) would run for ever.
constexpr std::uint64_t kMaxSteps = 1'000'000'000;

int bad_input(const std::string& msg) {
  std::cerr << "clothsim: error: " << msg << "\n";
  return kExitBadInput;
}

// The 2016 program's single-dash options, rewritten to ours before CLI11 sees them.
std::vector<std::string> rewrite_seed_aliases(int argc, char** argv) {
  static const std::pair<const char*, const char*> aliases[] = {
      {"-step", "--dt"}, {"-mass", "--mass"}, {"-stiff", "--k-struct"}, {"-wstiff", "--k-bend"}, {"-damp", "--damping"}};
  std::vector<std::string> out;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    for (const auto& [from, to] : aliases) {
      const std::string f = from;
      if (a == f) a = to;
      else if (a.rfind(f + "=", 0) == 0) a = std::string(to) + a.substr(f.size());
    }
    out.push_back(a);
  }
  return out;
}

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A fraction as a percentage with one decimal: "97.3 %".
std::string fmt_percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * fraction);
  return text;
}

// The steps of dt that cover `seconds`: seconds / dt when that is a whole number (up to
// rounding: 20 s / 0.0004 s is 50000, not 50001), else rounded up, so that a run lasts at
// least the time asked (--seconds 0.5 at --dt 1.5 is one step, not none). 0 s is 0 steps.
double steps_covering(double seconds, double dt) {
  // (seconds / dt is rounded once, by ~1e-16 of itself: 1e-12 of it is far beyond that and far
  // below half a step for any count a run may take, 1e9)
  const double r = seconds / dt, nearest = std::round(r);
  if (std::abs(r - nearest) <= 1e-12 * std::max(1.0, r)) return seconds > 0.0 ? std::max(nearest, 1.0) : nearest;
  return std::ceil(r);
}

// A step count: whole numbers in full, beyond 1e15 as 1e+30.
std::string fmt_count(double n) {
  return n < 1e15 ? std::to_string(static_cast<std::uint64_t>(n)) : fmt(n);
}

// A count in decimal digits, lo..hi, into `out`; else a one-line reason naming the option.
// (CLI11 reads 99999999999999999999 as 2^64-1 and 010 as octal.)
std::string parse_count(const std::string& option, const std::string& text, std::uint64_t lo, std::uint64_t hi,
                        std::uint64_t& out) {
  const std::string shown = text.size() > 40 ? text.substr(0, 40) + "..." : text;
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, out);
  const bool digits = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits || ptr != end || (ec != std::errc{} && ec != std::errc::result_out_of_range))
    return option + " must be a whole number " + range + " (got '" + shown + "')";
  if (out < lo && ec == std::errc{}) return option + " must be >= " + std::to_string(lo) + " (got " + shown + ")";
  if (ec == std::errc::result_out_of_range || out > hi) return option + " must be " + range + " (got " + shown + ")";
  return {};
}

json options_json(const Options& o) {
  return json{{"dt", o.dt},         {"mass", o.mass},
              {"k_struct", o.k_struct}, {"k_bend", o.k_bend},
              {"damping", o.damping},   {"gravity", {o.gravity.x(), o.gravity.y(), o.gravity.z()}},
              {"epsilon", o.epsilon},   {"k_rep", o.k_rep},
              {"integrator", to_string(o.integrator)}};
}

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
  if (f.parent_path() != fs::path(io::output_identity(dir)) ||
      !generated_name(f.filename().string(), prefix, digits, suffix))
    return {};
  return std::string(file_option) + " '" + file + "' is one of the files " + std::string(dir_option) +
         " writes (" + prefix + std::string(digits, 'N') + suffix + "): one would replace the other; name another file";
}

// One OBJ file <dir>/<scene>_<step>.obj by the output rule (clothsim/output_file.hpp);
// `step` counts the user's steps of `dt` (not substeps). Returns empty or the error.
std::string export_obj(const fs::path& dir, const b2o::Scene& scene, const Model& model, const State& s,
                       std::uint64_t step, double dt) {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%06llu.obj", model.scene_name.c_str(),
                static_cast<unsigned long long>(step));
  std::ostringstream out;
  out << "# clothsim " << CLOTHSIM_VERSION << ", t = " << s.t << " s, step " << step << " of dt " << dt << " s\n";
  // Positions exactly (17 digits read back the same double). A baked cloth is written as its
  // object's render mesh: its vertices in the scene's order (each at its mass), its texture
  // coordinates and triangles, so the frames map onto the model and keep its UV seams.
  out.precision(std::numeric_limits<double>::max_digits10);
  std::size_t base = 1;  // OBJ indices are 1-based and file-global
  for (const ClothRange& r : model.cloths) {
    const b2o::Cloth* cloth = r.scene_cloth >= 0 ? &scene.cloths[r.scene_cloth] : nullptr;
    if (cloth == nullptr) {  // a cloth made in code: its masses and no faces
      out << "o cloth\n";
      for (std::uint32_t i = 0; i < r.mass_count; ++i) {
        const auto c = s.x.col(r.first_mass + i);
        out << "v " << c.x() << ' ' << c.y() << ' ' << c.z() << "\n";
      }
      base += r.mass_count;
      continue;
    }
    const b2o::Object& obj = scene.objects[cloth->object];
    out << "o " << obj.name << "\n";
    std::vector<std::uint32_t> mass_of(obj.vertex_count, std::numeric_limits<std::uint32_t>::max());
    for (std::uint32_t m = 0; m < cloth->mass_count; ++m)
      for (std::uint32_t k = cloth->mass_vertex_offsets[m]; k < cloth->mass_vertex_offsets[m + 1]; ++k)
        if (const std::uint32_t v = cloth->mass_vertices[k] - obj.first_vertex; v < obj.vertex_count) mass_of[v] = m;
    for (std::uint32_t v = 0; v < obj.vertex_count; ++v) {
      if (mass_of[v] < cloth->mass_count) {
        const auto c = s.x.col(r.first_mass + mass_of[v]);
        out << "v " << c.x() << ' ' << c.y() << ' ' << c.z() << "\n";
      } else {  // a render vertex of no mass: where the model has it
        const float* c = scene.positions + 3 * (std::size_t{obj.first_vertex} + v);
        out << "v " << double(c[0]) << ' ' << double(c[1]) << ' ' << double(c[2]) << "\n";
      }
    }
    for (std::uint32_t v = 0; v < obj.vertex_count; ++v) {
      const float* t = scene.texcoords + 2 * (std::size_t{obj.first_vertex} + v);
      out << "vt " << double(t[0]) << ' ' << double(t[1]) << "\n";
    }
    for (std::uint32_t i = obj.first_index; i + 2 < obj.first_index + obj.index_count; i += 3) {
      out << 'f';
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::size_t idx = base + (scene.indices[i + k] - obj.first_vertex);
        out << ' ' << idx << '/' << idx;
      }
      out << '\n';
    }
    base += obj.vertex_count;
  }
  return io::write_output_file((dir / name).string(), out.str());
}

// Progress of a headless run. On a terminal: a bar with simulated time, wall time so far, and
// the time left at the pace of the last few percent (a step costs more once the cloth is in
// contact). Otherwise (a log, CI): one line every 30 s of wall time, so a long run is not silent.
class Progress {
 public:
  Progress(std::uint64_t total, bool on, bool terminal)
      : total_(total), on_(on && total >= 200), terminal_(terminal) {}
  void update(std::uint64_t done, double t) {
    if (!on_) return;
    const int pct = static_cast<int>(100 * done / total_);
    if (pct == last_) return;
    last_ = pct;
    const double now = std::chrono::duration<double>(Clock::now() - start_).count();
    at_[pct % kRecent] = now;
    const int back = std::min(pct, kRecent - 1);  // percent points with a time
    const double left = back > 0 ? (now - at_[(pct - back) % kRecent]) / back * (100 - pct) : 0.0;
    if (!terminal_) {
      if (now < next_line_ || pct >= 100) return;
      next_line_ = now + kLineEvery;
      std::fprintf(stderr, "clothsim: %d %% (t = %.2f s), wall %.0f s, left ~%.0f s\n", pct, t, now, left);
      return;
    }
    const int bar = pct * 30 / 100;
    std::fprintf(stderr, "\r[%.*s%*s] %3d%%  t = %.2f s  wall %.0f s", bar, "##############################",
                 30 - bar, "", pct, t, now);
    if (pct > 0 && pct < 100) std::fprintf(stderr, "  left ~%.0f s ", left);
    else std::fprintf(stderr, "%14s", "");
    std::fflush(stderr);
  }
  void finish() {
    if (on_ && terminal_ && last_ >= 0) std::fprintf(stderr, "\n");
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr int kRecent = 6;            // the pace of the last 5 percent points
  static constexpr double kLineEvery = 30.0;   // s of wall time between lines without a terminal
  std::uint64_t total_;
  bool on_, terminal_;
  int last_ = -1;
  Clock::time_point start_ = Clock::now();
  double at_[kRecent] = {};
  double next_line_ = kLineEvery;
};

}  // namespace

int run_app(int argc, char** argv, const b2o::Scene& scene) {
  const Options defaults{};
  std::vector<std::string> unknown_params;
  const Options scene_opts = scene_options(scene, defaults, &unknown_params);

  CLI::App app{std::string("clothsim: mass-spring cloth simulation of the baked scene '") + scene.name +
               "' (symplectic Euler, report eqs. 1-7; penalty contacts, eq. 12)"};
  // (the usage line names the program as it was started)
  app.name(argc > 0 && argv[0] ? std::filesystem::path(argv[0]).filename().string() : std::string("clothsim"));
  app.set_version_flag("--version", std::string("clothsim ") + CLOTHSIM_VERSION + " (scene " + scene.name + ")");

  bool headless = false, quiet = false, no_vsync = false, paused = false;
  double seconds = 20.0, dt = 0, mass = 0, k_struct = 0, k_bend = 0, damping = 0, gravity = 0, epsilon = 0, k_rep = 0;
  std::uint64_t steps = 0, export_every = 10;
  std::string steps_text, export_every_text = "10";
  std::string report, export_dir, screenshot, frames;
  int fps = 30, width = 1280, height = 720;

  // A number option given an empty value ("--gravity ''": CLI11 read it as 0, gravity off) or
  // a hexadecimal one (--dt 0x10 was 16 s).
  const CLI::Validator a_number(
      [](std::string& text) {
        if (text.find_first_not_of(" \t") == std::string::npos) return std::string("needs a number, got an empty value");
        // (spaces around the number, as a shell variable may leave them: both ends alike)
        text.erase(0, text.find_first_not_of(" \t"));
        text.erase(text.find_last_not_of(" \t") + 1);
        if (text.find_first_of("xX") != std::string::npos) return "takes a decimal number, got '" + text + "'";
        return std::string();
      },
      "");
  app.add_flag("--headless", headless, "Run without a window" );
  auto* o_seconds = app.add_option("--seconds", seconds, "Simulated seconds to run (default 20 headless; the viewer runs until closed)")->transform(a_number);
  // Counts are read as text and parsed below: CLI11 wraps -3 to 2^64-3 and saturates overflow.
  auto* o_steps = app.add_option("--steps", steps_text, "Number of steps to run instead of --seconds (1..1000000000)");
  o_steps->excludes(o_seconds);
  auto* o_dt = app.add_option("--dt", dt, "Step size h, s (seed: -step)")->transform(a_number);
  auto* o_mass = app.add_option("--mass", mass, "Mass per point, kg (seed: -mass)")->transform(a_number);
  auto* o_ks = app.add_option("--k-struct", k_struct, "Structural spring stiffness, N/m (seed: -stiff)")->transform(a_number);
  auto* o_kb = app.add_option("--k-bend", k_bend, "Bend spring stiffness, N/m (seed: -wstiff)")->transform(a_number);
  auto* o_damp = app.add_option("--damping", damping, "Damping gamma of eq. 6, N s/m (seed: -damp)")->transform(a_number);
  auto* o_g = app.add_option("--gravity", gravity, "Gravity, m/s^2, pointing down -Y")->transform(a_number);
  auto* o_eps = app.add_option("--epsilon", epsilon, "Collision band epsilon of eq. 12, m")->transform(a_number);
  auto* o_krep = app.add_option("--k-rep", k_rep, "Penalty stiffness k_rep of eq. 12, N/m")->transform(a_number);
  auto* o_report = app.add_option("--report", report, "Write a JSON report of the run to this file");
  auto* o_export = app.add_option("--export-obj", export_dir, "Write the cloth meshes as OBJ files into this directory");
  auto* o_export_every = app.add_option("--export-every", export_every_text,
                 "With --export-obj: every K steps of --dt (substeps not counted; default 10)");
  app.add_flag("--quiet", quiet, "No progress bar and no summary");
  // issue 6: results are bit-identical for every count, so auto may switch while it runs
  std::string threads_text = "auto";
  app.add_option("--threads", threads_text,
                 "Threads for the force loops: auto (default: measures one thread and all cores while it "
                 "runs and keeps the faster), N (1..1024) or 0 (all cores), as asked even when another program keeps a core busy (then 2 threads can be 50x slower than 1); the same results for any count");
  // issue 5: integrator and stability guard (integrators.hpp, stability.hpp, docs/stability.md)
  std::string integrator_name = to_string(Integrator::SymplecticEuler), substeps_text = "auto";
  app.add_option("--integrator", integrator_name,
                 "Time integrator: " + integrator_names() + " (default: the seed's symplectic-euler)");
  app.add_option("--substeps", substeps_text,
                 "auto: substep to stay at or below the safe step, 0.9 x the stability limit dt_stable "
                 "(default); off: refuse a dt above the safe step (exactly when auto would substep); "
                 "N: N substeps per step, as asked (a warning above the safe step)");
  auto* o_screenshot = app.add_option("--screenshot", screenshot, "Viewer: render at --seconds, write this PNG and exit");
  auto* o_frames = app.add_option("--frames", frames, "Viewer: write a PNG sequence into this directory up to --seconds");
  // The viewer's own limits (check_options), checked here so that they are bad input (exit 2).
  auto* o_fps = app.add_option("--fps", fps, "Viewer: frames per simulated second for --frames (default 30)")
                    ->check(CLI::Range(1, 1000));
  auto* o_width = app.add_option("--width", width, "Viewer: window width (default 1280)")->check(CLI::Range(16, 8192));
  auto* o_height =
      app.add_option("--height", height, "Viewer: window height (default 720)")->check(CLI::Range(16, 8192));
  auto* o_no_vsync = app.add_flag("--no-vsync", no_vsync, "Viewer: do not wait for vertical sync");
  auto* o_paused = app.add_flag("--paused", paused, "Viewer: start paused");
  double lookahead = 3.0;
  auto* o_lookahead =
      app.add_option("--lookahead", lookahead,
                     "Viewer: simulated seconds the window may compute ahead of the picture, which plays "
                     "them at the wall clock's pace, so heavy seconds borrow from cheap ones (default 3; "
                     "half of it is computed before the picture starts, at most 2 s of waiting; 0: "
                     "off, each state shown as it is computed)")
          ->transform(a_number)
          ->check([](const std::string& v) -> std::string {
            // (a_number has read it; nan and inf are no numbers here)
            errno = 0;
            const double x = std::strtod(v.c_str(), nullptr);
            if ((x == 0.0 && errno != ERANGE) || (x >= 0.25 && x <= 60.0)) return {};  // (1e-400 is no 0)
            return "0 (off) or 0.25 to 60 s, got " + v + " (a shorter look-ahead cannot keep up)";
          });

  // --help lists the built-in defaults next to this scene's baked values.
  std::ostringstream foot;
  const std::string scene_label = std::string("(scene '") + scene.name + "': ";
  auto row = [&foot, &scene_label](const char* name, double d, double s) {
    foot << "  " << name << std::string(12 - std::string(name).size(), ' ') << fmt(d);
    if (d != s) foot << ' ' << scene_label << fmt(s) << ')';
    foot << '\n';
  };
  foot << "Physical options: built-in default, and where this scene bakes another value, the scene's:\n";
  row("--dt", defaults.dt, scene_opts.dt);
  row("--mass", defaults.mass, scene_opts.mass);
  row("--k-struct", defaults.k_struct, scene_opts.k_struct);
  row("--k-bend", defaults.k_bend, scene_opts.k_bend);
  row("--damping", defaults.damping, scene_opts.damping);
  if (scene_opts.gravity.x() != 0.0 || scene_opts.gravity.z() != 0.0)  // a vector: shown whole
    foot << "  --gravity   " << fmt(-defaults.gravity.y()) << ' ' << scene_label << "the vector (" << fmt(scene_opts.gravity.x())
         << ", " << fmt(scene_opts.gravity.y()) << ", " << fmt(scene_opts.gravity.z()) << ") m/s^2; --gravity G sets (0, -G, 0))\n";
  else
    row("--gravity", -defaults.gravity.y(), -scene_opts.gravity.y());
  row("--epsilon", defaults.epsilon, scene_opts.epsilon);
  row("--k-rep", defaults.k_rep, scene_opts.k_rep);
  foot << "The command line overrides the scene. Exit codes: 0 ok, 1 the run failed "
          "(non-finite state, I/O), 2 bad input.\n";
#ifdef CLOTHSIM_HAVE_VIEWER
  foot << '\n' << viewer_help_text();
#endif
  app.footer(foot.str());

  std::vector<std::string> args = rewrite_seed_aliases(argc, argv);
  std::reverse(args.begin(), args.end());  // CLI11 parses a reversed vector
  try {
    app.parse(args);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return bad_input(e.what());
  }

  // Pictures come from the viewer: with --headless there is none, and no picture was written.
#ifndef CLOTHSIM_HAVE_VIEWER
  if (o_screenshot->count() || o_frames->count())
    return bad_input("--screenshot/--frames need the viewer, and this clothsim was built without it");
#endif
  if (headless && (o_screenshot->count() || o_frames->count()))
    return bad_input(std::string(o_screenshot->count() ? "--screenshot" : "--frames") +
                     " renders with the viewer, which --headless turns off: drop --headless "
                     "(with no display, run it under xvfb-run -a)");

  Options opts = scene_opts;
  if (o_dt->count()) opts.dt = dt;
  if (o_mass->count()) opts.mass = mass;
  if (o_ks->count()) opts.k_struct = k_struct;
  if (o_kb->count()) opts.k_bend = k_bend;
  if (o_damp->count()) opts.damping = damping;
  if (o_g->count()) {
    if (!quiet && (scene_opts.gravity.x() != 0.0 || scene_opts.gravity.z() != 0.0))
      std::cerr << "clothsim: note: --gravity " << fmt(gravity) << " replaces the scene's gravity (" << fmt(scene_opts.gravity.x())
                << ", " << fmt(scene_opts.gravity.y()) << ", " << fmt(scene_opts.gravity.z()) << ") by (0, " << fmt(-gravity)
                << ", 0)\n";
    opts.gravity = Eigen::Vector3d(0.0, -gravity, 0.0);
  }
  if (o_eps->count()) opts.epsilon = epsilon;
  if (o_krep->count()) opts.k_rep = k_rep;
  if (const auto method = parse_integrator(integrator_name)) opts.integrator = *method;
  else return bad_input("--integrator: unknown '" + integrator_name + "' (known: " + integrator_names() + ")");
  SubstepPolicy substep_policy;
  try {
    substep_policy = parse_substeps(substeps_text);
  } catch (const std::invalid_argument& e) {
    return bad_input(e.what());
  }
  if (const std::string why = validate_options(opts); !why.empty()) {
    // A value the scene bakes (PARAMS in generated/CMakeLists.txt), not one the user gave: say
    // so. It is the scene's when the same check fails with the user's values set to the
    // built-in defaults (which pass).
    Options baked = opts;
    if (o_dt->count()) baked.dt = defaults.dt;
    if (o_mass->count()) baked.mass = defaults.mass;
    if (o_ks->count()) baked.k_struct = defaults.k_struct;
    if (o_kb->count()) baked.k_bend = defaults.k_bend;
    if (o_damp->count()) baked.damping = defaults.damping;
    if (o_g->count()) baked.gravity = defaults.gravity;
    if (o_eps->count()) baked.epsilon = defaults.epsilon;
    if (o_krep->count()) baked.k_rep = defaults.k_rep;
    if (validate_options(baked) == why)
      return bad_input(why + ", baked into scene '" + scene.name +
                       "' (its PARAMS in generated/CMakeLists.txt); give the option on the command line to override it");
    return bad_input(why);
  }
  // --threads: auto, or a fixed count (0: all cores)
  std::optional<ThreadChooser> chooser;
  if (threads_text == "auto") {
    chooser.emplace(core_count());  // made again for the model below
  } else {
    std::uint64_t count = 0;
    if (!parse_count("--threads", threads_text, 0, 1024, count).empty())
      return bad_input("--threads must be auto or a whole number 0..1024 (0: all cores; got '" + threads_text + "')");
    set_threads(static_cast<int>(count));
  }
  if (o_seconds->count() && !(std::isfinite(seconds) && seconds >= 0.0))
    return bad_input("--seconds must be a finite number >= 0 (got " + fmt(seconds) + ")");
  if (o_steps->count())
    if (const std::string why = parse_count("--steps", steps_text, 1, kMaxSteps, steps); !why.empty())
      return bad_input(why);
  if (const std::string why = parse_count("--export-every", export_every_text, 1,
                                          std::numeric_limits<std::uint64_t>::max(), export_every);
      !why.empty())
    return bad_input(why);
  // Output paths before the (possibly long) run: a directory named as the report, or a file
  // where the OBJ directory should be, is bad input found at once.
  if (o_export_every->count() && !o_export->count())
    return bad_input("--export-every needs --export-obj DIR (the OBJ files it paces)");
  // The viewer's options do nothing without it: said, not ignored.
  if (headless)
    for (const CLI::Option* o : {o_screenshot, o_frames, o_fps, o_width, o_height, o_no_vsync, o_paused, o_lookahead})
      if (o->count())
        return bad_input(o->get_name() + " is a viewer option, and --headless opens no viewer (drop one of them)");
  if (o_fps->count() && !o_frames->count()) return bad_input("--fps needs --frames DIR (the frames it paces)");
  if (o_lookahead->count() && (o_screenshot->count() || o_frames->count()))
    return bad_input("--lookahead paces the window; --screenshot and --frames step straight to their times (drop one)");
  if (o_frames->count() && !o_seconds->count() && !o_steps->count())
    return bad_input("--frames needs --seconds T (how much simulated time to record)");
  if (o_screenshot->count()) {  // (a name without an extension, such as /dev/null, is written into)
    std::string ext = std::filesystem::path(screenshot).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (!ext.empty() && ext != ".png")
      return bad_input("--screenshot writes a PNG: name it *.png (got " + screenshot + ")");
  }
  if (o_report->count())
    if (const std::string why = io::check_output_file(report); !why.empty()) return bad_input("--report: " + why);
  // Two outputs at one path: the first written would be lost to the second, or stop it.
  if (const std::string why = io::same_output(
          {{"--report", o_report->count() ? report : ""}, {"--export-obj", o_export->count() ? export_dir : ""},
           {"--screenshot", o_screenshot->count() ? screenshot : ""}, {"--frames", o_frames->count() ? frames : ""}});
      !why.empty())
    return bad_input(why);
  for (const auto& [option, file] : {std::pair<std::string_view, std::string>{"--report", o_report->count() ? report : ""},
                                     {"--screenshot", o_screenshot->count() ? screenshot : ""}}) {
    if (const std::string why = file_among_generated(option, file, "--export-obj", o_export->count() ? export_dir : "",
                                                     std::string(scene.name) + "_", 6, ".obj");
        !why.empty())
      return bad_input(why);
    if (const std::string why =
            file_among_generated(option, file, "--frames", o_frames->count() ? frames : "", "frame_", 5, ".png");
        !why.empty())
      return bad_input(why);
  }
  if (o_export->count())
    if (const std::string why = io::check_output_dir(export_dir); !why.empty())
      return bad_input("--export-obj: " + why);
  if (o_screenshot->count())
    if (const std::string why = io::check_output_file(screenshot); !why.empty())
      return bad_input("--screenshot: " + why);
  if (o_frames->count())
    if (const std::string why = io::check_output_dir(frames); !why.empty()) return bad_input("--frames: " + why);
  if (!quiet)
    for (const auto& k : unknown_params)
      std::cerr << "clothsim: note: scene '" << scene.name << "' bakes param '" << k << "', which is no simulator option\n";

#ifdef CLOTHSIM_HAVE_VIEWER
  if (!headless && (o_report->count() || o_export->count()))
    return bad_input("--report and --export-obj belong to headless runs: add --headless");
#endif

  // Ctrl-C or SIGTERM: the run stops after the step in progress, says so, writes what it
  // writes (a headless report; the viewer's whole PNGs) and exits 130.
  std::optional<CatchInterrupt> catch_interrupt;
  catch_interrupt.emplace();
  Model model;
  try {
    model = build_model(scene, opts);
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << "\n";
    return kExitFailed;
  }

  // The stability guard: omega_max (springs by Lanczos + contact), the limit of this
  // integrator, substeps or refusal, and the tunnelling check (docs/stability.md).
  if (!quiet && model.mass_count() >= 50000)  // Lanczos: ~3 s at 90k masses, ~45 s at 500k
    std::cerr << "clothsim: stability: estimating omega_max of " << model.mass_count()
              << " masses (Lanczos; seconds per 100k masses)...\n";
  const StabilityReport stab = analyse_stability(model);
  const SubstepPlan plan = plan_substeps(opts.dt, stab.dt_stable, substep_policy);
  if (!plan.ok)
    return bad_input("--dt " + fmt(opts.dt) + ": " +
                     (stab.dt_stable > 0.0 ? plan.message : never_stable_reason(stab, opts.integrator)));
  model.options.dt = plan.h;
  if (chooser) {  // a model too small to split steps on one thread: nothing to measure
    chooser.emplace(step_splits(model) ? core_count() : 1);
    set_threads(chooser->threads());
  }

  // The run's length before it starts: headless, --screenshot and --frames step as fast as they
  // can, and a window with --seconds or --steps closes at that time; a window without either
  // runs until the user closes it (n = 0).
  {
    const double n = o_steps->count()                     ? static_cast<double>(steps)
                     : (headless || o_seconds->count()) ? steps_covering(seconds, opts.dt)
                                                        : 0.0;
    const double total_h = n * plan.substeps;
    if (!(total_h <= static_cast<double>(kMaxSteps))) {
      std::string why;
      if (o_steps->count())  // within kMaxSteps itself: too many only with substeps
        why = "--steps " + steps_text + " of " + std::to_string(plan.substeps) + " substeps each is " +
              fmt_count(total_h) + " steps of " + fmt(plan.h) + " s";
      else {
        why = "--seconds " + fmt(seconds) + " at --dt " + fmt(opts.dt) + " is " + fmt_count(n) + " steps";
        if (plan.substeps > 1)
          why += " of " + std::to_string(plan.substeps) + " substeps each (" + fmt_count(total_h) + " steps of " +
                 fmt(plan.h) + " s)";
      }
      why += "; one run takes at most " + std::to_string(kMaxSteps) +
             (o_steps->count()       ? " (fewer --steps)"
              : plan.substeps > 1    ? " (lower --seconds)"
                                     : " (raise --dt or lower --seconds)");
      return bad_input(why);
    }
  }

  const TunnellingReport tunnel = check_tunnelling(model, plan.h);
  if (!quiet) {
    std::cerr << "clothsim: " << describe(stab, opts.integrator) << "\n";
    // a note (a warning is listed with the others below, also under --quiet)
    if (!plan.message.empty() && plan.message.rfind("warning: ", 0) != 0)
      std::cerr << "clothsim: note: " << plan.message << "\n";
  }
  // Every start-up warning, printed (also with --quiet) and listed in the report: tunnelling,
  // a closed collider whose faces point inwards, cloth masses that start inside a collider.
  std::vector<std::string> warnings;
  if (plan.message.rfind("warning: ", 0) == 0) warnings.push_back(plan.message);  // a step above the safe one
  if (model.mass_count() == 0)
    warnings.push_back(std::string("warning: scene '") + (scene.name ? scene.name : "?") +
                       "' has no cloth: nothing moves (name the cloth objects in blender2ogl_add_scene's CLOTH, "
                       "or blender2ogl -a)");
  if (tunnel.warn) warnings.push_back(tunnel.message);
  for (std::string& w : collider_warnings(model)) warnings.push_back(std::move(w));
  // The position-based methods take velocities from position differences, (x1 - x0) / h: when
  // a step's motion under gravity, g h^2, is near the rounding of the positions, the velocities
  // are mostly rounding (a probe: fast-mass-spring 41 % off, XPBD 13 %, at dt 1e-8 over 1000
  // steps; at 1e-15 XPBD lost gravity). Warned below a relative error of 1e-3 per step.
  if ((opts.integrator == Integrator::FastMassSpring || opts.integrator == Integrator::XPBD) && model.mass_count() > 0) {
    const double g = opts.gravity.norm(), reach = model.x0.cwiseAbs().maxCoeff();
    const double ulp = std::numeric_limits<double>::epsilon() * std::max(reach, 1e-300);
    if (g > 0.0 && std::isfinite(reach) && plan.h * plan.h * g < 1e3 * ulp)
      warnings.push_back("warning: " + std::string(to_string(opts.integrator)) + " takes velocities from position "
                         "differences, and a step of " + fmt(plan.h) + " s moves a mass by about g h^2 = " +
                         fmt(g * plan.h * plan.h) + " m, near the rounding of positions up to " + fmt(reach) +
                         " m: the velocities will be mostly rounding; use a step of at least " +
                         fmt(std::sqrt(1e3 * ulp / g)) + " s, or another integrator");
  }
  for (const std::string& w : warnings) std::cerr << "clothsim: " << w << "\n";


#ifdef CLOTHSIM_HAVE_VIEWER
  if (!headless) {
    ViewerOptions vo;
    vo.width = width;
    vo.height = height;
    vo.vsync = !no_vsync;
    vo.paused = paused;
    vo.lookahead = lookahead;
    vo.screenshot = screenshot;
    vo.frames_dir = frames;
    vo.fps = fps;
    vo.substeps = plan.substeps;
    vo.auto_threads = chooser.has_value();
    vo.interrupted = &g_interrupted;
    if (g_interrupted) {  // during the start-up (a large model's stability check): no window
      std::cerr << "clothsim: interrupted before the window opened\n";
      return kExitInterrupted;
    }
    // the time of the whole steps that cover --seconds, as a headless run takes (the viewer
    // rounds its own count to the nearest step)
    if (o_seconds->count()) vo.seconds = steps_covering(seconds, opts.dt) * opts.dt;
    else if (o_steps->count()) vo.seconds = static_cast<double>(steps) * opts.dt;
    return run_viewer(scene, model, vo);
  }
#endif
  (void)no_vsync;
  (void)paused;
  (void)lookahead;

  const std::uint64_t total =
      o_steps->count() ? steps : static_cast<std::uint64_t>(steps_covering(seconds, opts.dt));
  if (!o_steps->count() && !quiet && static_cast<double>(total) * opts.dt != seconds &&
      std::abs(static_cast<double>(total) * opts.dt - seconds) > 1e-12 * seconds)
    std::cerr << "clothsim: note: " << (o_seconds->count() ? "--seconds " + fmt(seconds) : "the default " + fmt(seconds) + " s")
              << " is not a whole number of steps of " << (o_dt->count() ? "--dt " : "dt ") << fmt(opts.dt) << ": "
              << total << " step" << (total == 1 ? "" : "s") << " (" << fmt(static_cast<double>(total) * opts.dt) << " s)\n";

  const fs::path export_path = export_dir;
  if (o_export->count()) {
    std::error_code ec;
    fs::create_directories(export_path, ec);
    if (ec || !fs::is_directory(export_path)) {
      std::cerr << "clothsim: error: --export-obj: cannot create directory '" << export_dir << "'"
                << (ec ? ": " + ec.message() : std::string()) << "\n";
      return kExitFailed;
    }
  }

  State state = make_state(model);
  Workspace ws = make_workspace(model);
  Progress progress(total, !quiet, ::isatty(STDERR_FILENO) != 0);
  const double omega = gershgorin_omega_max(model);
  const double stable_dt = omega > 0 ? 2.0 / omega : std::numeric_limits<double>::infinity();
  bool finite = true;
  std::chrono::steady_clock::duration step_time{};
  std::uint64_t failed_step = 0;  // the step of dt (1-based) in which the state became non-finite
  std::uint64_t done = 0;         // steps of dt completed (each of plan.substeps substeps)
  std::uint64_t timed = 0;        // steps of dt timed (the failed one included)
  double t_done = state.t;        // simulated time after the last completed step
  if (o_export->count())
    if (const std::string err = export_obj(export_path, scene, model, state, 0, opts.dt); !err.empty()) {
      std::cerr << "clothsim: error: --export-obj: " << err << "\n";
      return kExitFailed;
    }
  const std::clock_t cpu0 = std::clock();  // CPU time: robust to other processes on the machine
  bool interrupted = false;
  for (std::uint64_t i = 0; i < total; ++i) {
    if (g_interrupted) {
      interrupted = true;
      break;
    }
    const auto t0 = std::chrono::steady_clock::now();
    StepStatus st;
    if (chooser) {  // each step timed: the chooser compares one thread with all cores
      for (int k = 0; k < plan.substeps && st.finite; ++k) st = chosen_step(*chooser, model, state, ws);
    } else {
      for (int k = 0; k < plan.substeps && st.finite; ++k) st = step(model, state, ws);
    }
    step_time += std::chrono::steady_clock::now() - t0;
    ++timed;
    if (!st.finite) {
      finite = false;
      failed_step = i + 1;
      break;
    }
    done = i + 1;
    t_done = state.t;
    if (o_export->count() && done % export_every == 0)
      if (const std::string err = export_obj(export_path, scene, model, state, done, opts.dt); !err.empty()) {
        progress.finish();
        std::cerr << "clothsim: error: --export-obj: " << err << "\n";
        return kExitFailed;
      }
    progress.update(i + 1, state.t);
  }
  progress.finish();
  catch_interrupt.reset();  // the report is written with the usual signals
  const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  if (interrupted)
    std::cerr << "clothsim: interrupted after " << done << " of " << total << " steps (t = " << state.t
              << " s)" << (o_report->count() ? "; the report says so" : "") << "\n";

  // per step of dt, all its substeps included
  const double ms_per_step =
      timed ? std::chrono::duration<double, std::milli>(step_time).count() / static_cast<double>(timed) : 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()), hi = lo;
  if (model.mass_count() > 0 && finite) {  // (a failed run's state is no box: null)
    lo = state.x.rowwise().minCoeff();
    hi = state.x.rowwise().maxCoeff();
  }
  const double ke = kinetic_energy(model, state);
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  // A finite state whose kinetic energy overflows (--mass 1e306, --gravity 1e200): the run
  // is out of a double's range, a failure like a non-finite state (it ended with exit 0, the
  // summary saying "inf J" and the report null).
  const bool ke_overflow = finite && !interrupted && !std::isfinite(ke);
  if (ke_overflow) {
    const std::string why = "error: the kinetic energy overflows a double at t = " + fmt(state.t) +
                            " s: the masses and speeds are out of range; look at the sizes of the options "
                            "(--mass, --gravity, --k-struct, --k-rep)";
    std::cerr << "clothsim: " << why << "\n";
    warnings.push_back(why);
  }

  // The collision search reaches 2 eps behind a surface: a mass deeper than that is not seen,
  // so max_penetration is at most 2 eps and is no depth. Past eps the contact lets go (no
  // force): a mass seen there may have gone deeper, or through.
  const double reach = 2.0 * opts.epsilon;
  const bool past_eps = state.max_penetration > opts.epsilon;

  if (!finite) {
    std::cerr << "clothsim: error: the state became non-finite at step " << failed_step << " (t = " << state.t
              << " s). Likely cause: ";
    const std::string h = "the step h = " + fmt(plan.h) + " s" +
                          (plan.substeps > 1 ? " (dt / " + std::to_string(plan.substeps) + " substeps)" : std::string());
    // (dt_stable: the guard's limit for this integrator, from omega_max by Lanczos; the
    // Gershgorin bound 2/omega_max is lower, and a step between the two is stable)
    if (!(plan.h <= stab.dt_stable))
      std::cerr << h << " is above the stability limit dt_stable = " << stab.dt_stable
                << " s (the Gershgorin estimate 2/omega_max is " << stable_dt
                << " s; lower --dt, let --substeps auto substep, or soften --k-struct/--k-rep)\n";
    else
      std::cerr << "a force too large for double precision: " << h << " is within the stability limit dt_stable = "
                << stab.dt_stable << " s, so look at the sizes of the options (--gravity, --k-struct, --k-bend, "
                << "--k-rep, --mass)\n";
  }

  if (o_report->count()) {
    json r;
    r["scene"] = model.scene_name;
    r["version"] = CLOTHSIM_VERSION;
    r["masses"] = model.mass_count();
    r["springs"] = model.spring_count();
    r["bend_springs"] = std::count(model.spring_kind.begin(), model.spring_kind.end(), std::uint8_t{1});
    r["pinned_masses"] = std::count(model.pinned.begin(), model.pinned.end(), std::uint8_t{1});  // (a helper's pins land)
    r["collider_triangles"] = collider_triangle_count(model);
    r["dt"] = opts.dt;
    r["steps"] = done;  // steps of dt completed
    r["substeps"] = plan.substeps;  // per step of dt
    r["substep_dt"] = plan.h;       // dt / substeps
    r["dt_stable"] = num(stab.dt_stable);  // the guard's limit for this integrator
    r["omega_max"] = num(stab.omega_max);
    r["integrator"] = to_string(opts.integrator);
    r["tunnelling_warning"] = tunnel.warn;
    r["warnings"] = warnings;
    r["seconds_simulated"] = t_done;  // (a failed run: up to the last step that completed)
    r["ms_per_step"] = ms_per_step;
    r["cpu_ms_per_step"] = timed ? cpu_ms / static_cast<double>(timed) : 0.0;  // includes --export-obj
    r["finite"] = finite;
    if (!finite) r["failed_step"] = failed_step;
    r["interrupted"] = interrupted;  // stopped by Ctrl-C or SIGTERM after `steps` steps
    r["cloth_min"] = {num(lo.x()), num(lo.y()), num(lo.z())};
    r["cloth_max"] = {num(hi.x()), num(hi.y()), num(hi.z())};
    r["max_penetration"] = num(state.max_penetration);  // behind a surface, within the search's reach
    r["max_penetration_reach"] = reach;                  // 2 eps: deeper is not seen
    r["max_penetration_past_eps"] = past_eps;            // true: masses may be deeper or through
    r["kinetic_energy"] = num(ke);
    r["stable_dt_estimate"] = num(stable_dt);
    r["options"] = options_json(opts);
    // threads: what was asked; thread_steps: model steps taken with each count
    if (chooser) {
      r["threads"] = "auto";
      json by_count = json::object();
      by_count["1"] = chooser->steps_one();
      if (chooser->cores() > 1) by_count[std::to_string(chooser->cores())] = chooser->steps_many();
      r["thread_steps"] = by_count;
    } else {
      r["threads"] = threads();
      // a model too small to split steps on one thread whatever was asked
      const int used = step_splits(model) ? threads() : 1;
      r["thread_steps"] = json::object({{std::to_string(used), state.steps}});
    }
    if (const std::string err = io::write_output_file(report, r.dump(2) + "\n"); !err.empty()) {
      std::cerr << "clothsim: error: --report: " << err << "\n";
      return kExitFailed;
    }
  }
  if (!finite || ke_overflow) return kExitFailed;
  if (interrupted) return kExitInterrupted;
  if (!quiet) {
    std::cout << model.scene_name << ": " << done << " steps of " << opts.dt << " s";
    if (plan.substeps > 1) std::cout << " (" << plan.substeps << " substeps of " << plan.h << " s each)";
    std::cout << ", " << state.t << " s simulated, "
              << ms_per_step << " ms/step, max penetration " << state.max_penetration << " m"
              << (past_eps ? " (behind a surface, as far as the search reaches: 2 eps = " + fmt(reach) +
                                 " m; past eps the contact lets go, masses may be deeper or through)"
                           : std::string())
              << ", kinetic energy " << ke << " J, cloth y " << lo.y() << " .. " << hi.y() << "\n";
    if (chooser && chooser->cores() > 1 && chooser->steps_one() + chooser->steps_many() > 0)
      std::cout << "threads auto: " << chooser->cores() << " threads for "
                << fmt_percent(chooser->share_many())
                << " of the steps (" << chooser->trials_won_by_many() << " of " << chooser->trials()
                << " trials won by " << chooser->cores() << " threads)\n";
  }
  return 0;
}

}  // namespace clothsim
