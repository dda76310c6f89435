// The command line: every option of the table (options.hpp) as a flag, the run's own flags,
// the 2016 program's aliases, and --help with the defaults next to the scene's baked values.
#include "run_config.hpp"

#include <clothsim/scene.hpp>

#include <blender2ogl/scene_types.h>

#ifdef CLOTHSIM_HAVE_VIEWER
#include <clothsim/viewer.hpp>
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#ifndef CLOTHSIM_VERSION
#define CLOTHSIM_VERSION "0.0.0"
#endif

namespace clothsim::app {

namespace {

// The 2016 program's single-dash options (the table's seed aliases), rewritten to ours.
std::vector<std::string> rewrite_seed_aliases(int argc, char** argv) {
  std::vector<std::string> out;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    for (const OptionInfo& o : option_table()) {
      if (o.seed_alias.empty()) continue;
      std::string from(1, '-');  // (built in steps: g++ 12 warns falsely on "-" + std::string)
      from += o.seed_alias;
      if (a == from) a = o.flag();
      else if (a.rfind(from + "=", 0) == 0) a = o.flag() + a.substr(from.size());
    }
    out.push_back(a);
  }
  return out;
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

// The help line of a table option: "Step size h, s (seed: -step)".
std::string option_help(const OptionInfo& o) {
  std::string h(o.help);
  if (!o.unit.empty()) h += ", " + std::string(o.unit);
  if (o.is_choice) {
    h += ": ";
    for (std::size_t i = 0; i < o.choices.size(); ++i) h += (i ? ", " : "") + std::string(o.choices[i]);
  }
  if (!o.seed_alias.empty()) h += " (seed: -" + std::string(o.seed_alias) + ")";
  return h;
}

// The table's defaults next to the scene's baked values, for --help's footer.
std::string defaults_footer(const b2o::Scene& scene, const BakedParams& baked) {
  const Options defaults{};
  Options runs = baked.options;  // what the scene runs with (its material's values filled in)
  try {
    runs = resolve_options(baked.options, baked.seed_given);
  } catch (const ModelMismatch&) {  // (said when it runs)
  }
  const OptionGroup unused = is_seed(runs) ? OptionGroup::Material : OptionGroup::Seed;
  std::ostringstream foot;
  foot << "Options of the table: built-in default, and where scene '" << scene.name << "' runs with another value, "
       << "the scene's (material " << find_option("material")->text(runs) << "; the "
       << (unused == OptionGroup::Seed ? "seed model's" : "materials'") << " options are not used):\n";
  for (const OptionInfo& o : option_table()) {
    const std::string d = o.text(defaults), s = o.text(runs), flag = o.flag();
    foot << "  " << flag << std::string(flag.size() < 18 ? 18 - flag.size() : 1, ' ') << d;
    if (o.group == unused) foot << " (not used)";
    else if (s != d) foot << " (scene '" << scene.name << "': " << s << ')';
    foot << '\n';
  }
  foot << "  --gravity G   sets the gravity to (0, -G, 0) m/s^2\n"
          "The command line overrides the scene. Exit codes: 0 ok, 1 the run failed (non-finite state, I/O), "
          "2 bad input.\n";
#ifdef CLOTHSIM_HAVE_VIEWER
  foot << '\n' << viewer_help_text();
#endif
  return foot.str();
}

// A number option: spaces around it are dropped and a non-number is refused at parse time.
CLI::Validator a_number() {
  return CLI::Validator(
      [](std::string& text) {
        double v = 0.0;
        const std::string why = parse_number(text, v);
        if (why.empty()) text = number_text(v);
        return why;
      },
      "");
}

// The options whose flags the parse registers, and what was written for each.
struct Flags {
  std::vector<std::string> table_values;  // one per table row
  std::vector<CLI::Option*> table;
  CLI::Option *seconds = nullptr, *steps = nullptr, *gravity = nullptr, *threads = nullptr, *export_every = nullptr;
  std::string steps_text, export_every_text = "10", threads_text = "auto", substeps_text = "auto";
  double seconds_value = 20.0, gravity_value = 0.0;
  std::vector<CLI::Option*> viewer;
  CLI::Option *fps = nullptr, *lookahead = nullptr;
};

void add_run_flags(CLI::App& app, RunConfig& c, Flags& f) {
  app.add_flag("--headless", c.headless, "Run without a window");
  f.seconds = app.add_option("--seconds", f.seconds_value,
                             "Simulated seconds to run (default 20 headless; the viewer runs until closed)")
                  ->transform(a_number())
                  ->type_name("NUMBER");
  // Counts are read as text and parsed below: CLI11 wraps -3 to 2^64-3 and saturates overflow.
  f.steps = app.add_option("--steps", f.steps_text, "Number of steps to run instead of --seconds (1..1000000000)");
  f.steps->excludes(f.seconds);
  app.add_option("--report", c.report, "Write a JSON report of the run to this file");
  app.add_option("--export-obj", c.export_dir, "Write the cloth meshes as OBJ files into this directory");
  f.export_every = app.add_option("--export-every", f.export_every_text,
                                  "With --export-obj: every K steps of --dt (substeps not counted; default 10)");
  app.add_flag("--quiet", c.quiet, "No progress bar and no summary");
  app.add_flag("--check-crossings", c.check_crossings,
               "Count the cloth's self-crossings (edges through its own triangles) every 0.05 s of simulated "
               "time: the report's max_self_crossings and max_self_crossings_t (the count at the end, "
               "self_crossings, is always there)");
  app.add_option("--threads", f.threads_text,
                 "Threads for the force loops: auto (default: measures one thread and all cores while it runs and "
                 "keeps the faster), N (1..1024) or 0 (all cores), as asked even when another program keeps a core "
                 "busy (then 2 threads can be 50x slower than 1); the same results for any count");
  app.add_option("--substeps", f.substeps_text,
                 "auto: substep to stay at or below the safe step, 0.9 x the stability limit dt_stable (default); "
                 "off: refuse a dt above the safe step (exactly when auto would substep); N: N substeps per step, "
                 "as asked (a warning above the safe step)");
}

void add_viewer_flags(CLI::App& app, RunConfig& c, Flags& f) {
  f.viewer = {
      app.add_option("--screenshot", c.screenshot, "Viewer: render at --seconds, write this PNG and exit"),
      app.add_option("--frames", c.frames, "Viewer: write a PNG sequence into this directory up to --seconds"),
      f.fps = app.add_option("--fps", c.fps, "Viewer: frames per simulated second for --frames (default 30)")
                  ->check(CLI::Range(1, 1000)),
      app.add_option("--width", c.width, "Viewer: window width (default 1280)")->check(CLI::Range(16, 8192)),
      app.add_option("--height", c.height, "Viewer: window height (default 720)")->check(CLI::Range(16, 8192)),
      app.add_flag("--no-vsync", c.no_vsync, "Viewer: do not wait for vertical sync"),
      app.add_flag("--paused", c.paused, "Viewer: start paused"),
      f.lookahead = app.add_option("--lookahead", c.lookahead,
                     "Viewer: simulated seconds the window may compute ahead of the picture, which plays them at the "
                     "wall clock's pace, so heavy seconds borrow from cheap ones (default 3; half of it is computed "
                     "before the picture starts, at most 2 s of waiting; 0: off, each state shown as it is computed)")
          ->transform(a_number())
          ->type_name("NUMBER")
          ->check([](const std::string& v) -> std::string {
            const double x = std::stod(v);
            if (x == 0.0 || (x >= 0.25 && x <= 60.0)) return {};
            return "0 (off) or 0.25 to 60 s, got " + v + " (a shorter look-ahead cannot keep up)";
          }),
  };
}

// The table's flags and --gravity.
void add_option_flags(CLI::App& app, Flags& f) {
  const auto table = option_table();
  f.table_values.resize(table.size());
  for (std::size_t i = 0; i < table.size(); ++i)
    f.table.push_back(app.add_option(table[i].flag(), f.table_values[i], option_help(table[i]))
                          ->type_name(table[i].is_choice ? "NAME" : "NUMBER"));
  f.gravity = app.add_option("--gravity", f.gravity_value, "Gravity G, m/s^2, pointing down -Y: (0, -G, 0)")
                  ->transform(a_number())
                  ->type_name("NUMBER");
  for (CLI::Option* o : f.table)
    if (o->get_name().rfind("--gravity-", 0) == 0) f.gravity->excludes(o);
}

std::string resolve_model(RunConfig& c, const BakedParams& baked, const std::string& baked_note);

// The scene's baked values with the user's on top; empty, or the error.
std::string apply_options(RunConfig& c, const Flags& f, const b2o::Scene& scene, const BakedParams& baked) {
  const auto table = option_table();
  for (std::size_t i = 0; i < table.size(); ++i)
    if (f.table[i]->count()) {
      if (const std::string why = table[i].set(c.options, f.table_values[i]); !why.empty())
        return table[i].flag() + " " + why;
      c.options_given.emplace_back(table[i].name);
    }
  if (f.gravity->count()) {
    if (!std::isfinite(f.gravity_value)) return "--gravity must be a finite number (got " + fmt(f.gravity_value) + ")";
    const Options& s = c.scene_options;
    if (!c.quiet && (s.gravity_x != 0.0 || s.gravity_z != 0.0))
      std::cerr << "clothsim: note: --gravity " << fmt(f.gravity_value) << " replaces the scene's gravity ("
                << fmt(s.gravity_x) << ", " << fmt(s.gravity_y) << ", " << fmt(s.gravity_z) << ") by (0, "
                << fmt(-f.gravity_value) << ", 0)\n";
    c.options.gravity_x = 0.0;
    c.options.gravity_y = -f.gravity_value;
    c.options.gravity_z = 0.0;
  }
  // A value the scene bakes and the command line does not replace.
  const std::string baked_note = ", baked into scene '" + std::string(scene.name) +
                                 "' (its PARAMS in generated/CMakeLists.txt); give the option on the command line to "
                                 "override it";
  for (const BakedParams::Refused& r : baked.refused) {
    const OptionInfo* o = find_option(r.key);
    const bool replaced = f.table[static_cast<std::size_t>(o - table.data())]->count() > 0 ||
                          (f.gravity->count() > 0 && r.key.rfind("gravity_", 0) == 0);
    if (!replaced) return r.key + " " + r.why + baked_note;
  }
  if (std::string why = validate_options(c.options); !why.empty()) return why;
  return resolve_model(c, baked, baked_note);
}

// The material and integrator decided (resolve_options()): an option of the seed model, baked
// or given, selects it; a material given here, or an option of the seed model given here (the
// 2016 program's flags on a scene baked with a material), sets the scene's options of the
// other model back to their defaults. Empty, or the error naming the option that belongs to
// the other model.
std::string resolve_model(RunConfig& c, const BakedParams& baked, const std::string& baked_note) {
  bool seed_on_line = false;
  for (const std::string& name : c.options_given) seed_on_line |= find_option(name)->group == OptionGroup::Seed;
  bool seed_given = baked.seed_given || seed_on_line;
  const bool chosen = c.given("material") && c.options.material != Material::Auto;
  if (chosen || (seed_on_line && !c.given("material"))) {
    if (!chosen) c.options.material = Material::Seed;
    const OptionGroup other = c.options.material == Material::Seed ? OptionGroup::Material : OptionGroup::Seed;
    const Options defaults{};
    for (const OptionInfo& o : option_table())
      if (o.group == other && !c.given(o.name)) o.set(c.options, o.text(defaults));
    seed_given = c.options.material == Material::Seed;
  }
  try {
    c.options = resolve_options(c.options, seed_given);
  } catch (const ModelMismatch& e) {
    return c.given(e.option) ? std::string(find_option(e.option)->flag()) + std::string(e.what()).substr(e.option.size())
                             : e.what() + baked_note;
  }
  return {};
}

// The run's own counts and choices; empty, or the error.
std::string read_run_flags(RunConfig& c, const Flags& f) {
  if (f.threads_text != "auto") {
    std::uint64_t count = 0;
    if (!parse_count("--threads", f.threads_text, 0, 1024, count).empty())
      return "--threads must be auto or a whole number 0..1024 (0: all cores; got '" + f.threads_text + "')";
    c.auto_threads = false;
    c.threads = static_cast<int>(count);
  }
  try {
    c.substeps = parse_substeps(f.substeps_text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  if (f.seconds->count()) {
    if (!(std::isfinite(f.seconds_value) && f.seconds_value >= 0.0))
      return "--seconds must be a finite number >= 0 (got " + fmt(f.seconds_value) + ")";
    c.seconds = f.seconds_value;
  }
  if (f.steps->count()) {
    std::uint64_t n = 0;
    if (std::string why = parse_count("--steps", f.steps_text, 1, kMaxSteps, n); !why.empty()) return why;
    c.steps = n;
  }
  c.export_every_given = f.export_every->count() > 0;
  return parse_count("--export-every", f.export_every_text, 1, std::numeric_limits<std::uint64_t>::max(),
                     c.export_every);
}

}  // namespace

Parsed parse_command_line(int argc, char** argv, const b2o::Scene& scene) {
  RunConfig c;
  const BakedParams baked = read_scene_params(scene);
  c.scene_options = c.options = baked.options;
  c.unknown_params = baked.unknown;

  CLI::App app{std::string("clothsim: mass-spring cloth simulation of the baked scene '") + scene.name +
               "': a cloth material (cotton unless the scene or --material says otherwise) stepped by XPBD, "
               "or the 2016 program's per-vertex model (--material seed) by symplectic Euler"};
  // (the usage line names the program as it was started)
  app.name(argc > 0 && argv[0] ? std::filesystem::path(argv[0]).filename().string() : std::string("clothsim"));
  app.set_version_flag("--version", std::string("clothsim ") + CLOTHSIM_VERSION + " (scene " + scene.name + ")");
  Flags f;
  add_run_flags(app, c, f);
  add_option_flags(app, f);
  add_viewer_flags(app, c, f);
  app.footer(defaults_footer(scene, baked));

  std::vector<std::string> args = rewrite_seed_aliases(argc, argv);
  std::reverse(args.begin(), args.end());  // CLI11 parses a reversed vector
  try {
    app.parse(args);
  } catch (const CLI::CallForHelp& e) {
    return {std::nullopt, app.exit(e)};
  } catch (const CLI::CallForVersion& e) {
    return {std::nullopt, app.exit(e)};
  } catch (const CLI::ParseError& e) {
    return {std::nullopt, bad_input(e.what())};
  }
  for (CLI::Option* o : f.viewer)
    if (o->count()) c.viewer_options_given.push_back(o->get_name());
  c.lookahead_given = f.lookahead->count() > 0;
  c.fps_given = f.fps->count() > 0;
  // Pictures come from the viewer: with --headless there is none.
#ifndef CLOTHSIM_HAVE_VIEWER
  if (!c.screenshot.empty() || !c.frames.empty())
    return {std::nullopt, bad_input("--screenshot/--frames need the viewer, and this clothsim was built without it")};
#endif
  if (c.headless && (!c.screenshot.empty() || !c.frames.empty()))
    return {std::nullopt, bad_input(std::string(!c.screenshot.empty() ? "--screenshot" : "--frames") +
                                    " renders with the viewer, which --headless turns off: drop --headless "
                                    "(with no display, run it under xvfb-run -a)")};
  if (std::string why = apply_options(c, f, scene, baked); !why.empty()) return {std::nullopt, bad_input(why)};
  if (std::string why = read_run_flags(c, f); !why.empty()) return {std::nullopt, bad_input(why)};
  return {std::move(c), kExitOk};
}

}  // namespace clothsim::app
