// clothsim_wp: the work-precision report (docs/work-precision.md) for the baked scenes it is
// built with.
//   clothsim_wp --out docs/wp                      full study (minutes)
//   clothsim_wp --fast --out build/wp-smoke        a short smoke run (ctest)
//   clothsim_wp --fine --out docs/wp               the fine, stiff case (skirt_hires in cotton)
#include <clothsim/integrators.hpp>
#include <clothsim/scene.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>
#include <clothsim/workprecision.hpp>
#include <clothsim/wp_fine.hpp>

#include <CLI/CLI.hpp>

#ifndef CLOTHSIM_WP_VERSION
#define CLOTHSIM_WP_VERSION "0.0.0"
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#ifdef CLOTHSIM_WP_HAVE_SKIRT
#include "skirt.h"
#endif
#ifdef CLOTHSIM_WP_HAVE_HANGING
#include "hanging.h"
#endif
#ifdef CLOTHSIM_WP_HAVE_SKIRT_HIRES
#include "skirt_hires.h"
#endif

namespace {

struct SceneEntry {
  const char* name;
  const b2o::Scene* scene;
  double horizon;  // s, full study
  /// The study's own options (KEY=VALUE, as PARAMS) in place of the scene's baked ones, or none.
  std::vector<const char*> params = {};
};

// The options a scene's study runs with: its own params, else the scene's baked ones.
clothsim::Options study_options(const SceneEntry& e) {
  if (e.params.empty()) return clothsim::scene_options(*e.scene);
  clothsim::Options o;
  for (const std::string_view entry : e.params) {
    const auto eq = entry.find('=');
    clothsim::find_option(entry.substr(0, eq))->set(o, entry.substr(eq + 1));
  }
  return clothsim::resolve_options(o, clothsim::seed_options_set(o));
}

std::vector<SceneEntry> baked_scenes() {
  std::vector<SceneEntry> s;
#ifdef CLOTHSIM_WP_HAVE_HANGING
  // hanging: the cloth swings from its pins; no contact, smooth: the clean case.
  s.push_back({"hanging", &b2o::gen::hanging::scene, 1.0});
#endif
#ifdef CLOTHSIM_WP_HAVE_SKIRT
  // skirt, in the seed's per-vertex model (its weight per mass at real gravity, a smooth
  // penalty, no friction): a rigid free fall (no spring force) until it meets the sphere at
  // ~0.6 s; 1 s holds the first 0.25 s of contact (wrapping) but not the slide-off, where ever
  // more band entries and exits make the error curves ragged.
  s.push_back({"skirt", &b2o::gen::skirt::scene, 1.0, {"material=seed", "mass=0.0102", "damping=0.03", "dt=0.002"}});
#endif
  return s;
}

double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// CPU seconds per symplectic Euler step from t = 1 s on (the skirt is on the sphere by then,
// so the contact path runs): min of 5 runs of 200 steps.
double seconds_per_step(const clothsim::Model& m) {
  clothsim::State start = clothsim::make_state(m);
  clothsim::Workspace ws = clothsim::make_workspace(m);
  while (start.t < 1.0) clothsim::step(m, start, ws);
  double best = 1e300;
  for (int r = 0; r < 6; ++r) {
    clothsim::State s = start;
    const double t0 = cpu_now();
    for (int i = 0; i < 200; ++i) clothsim::step(m, s, ws);
    if (r > 0) best = std::min(best, (cpu_now() - t0) / 200.0);
  }
  return best;
}

clothsim::Model without_bend_springs(const clothsim::Model& m) {
  clothsim::Model out = m;
  out.spring_a.clear();
  out.spring_b.clear();
  out.spring_kind.clear();
  std::vector<float> rest;
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (m.spring_kind[s] == 0) {
      out.spring_a.push_back(m.spring_a[s]);
      out.spring_b.push_back(m.spring_b[s]);
      out.spring_kind.push_back(0);
      rest.push_back(m.rest_length0[static_cast<Eigen::Index>(s)]);
    }
  out.rest_length0 = Eigen::Map<Eigen::VectorXf>(rest.data(), static_cast<Eigen::Index>(rest.size()));
  out.cloths.clear();  // the ranges no longer hold; nothing below needs them
  return out;
}

// "Model only what a scene needs": the cost of each modelled part, measured.
void model_cost(const SceneEntry& e, double stiffness_scale) {
  clothsim::Options options = study_options(e);
  options.k_struct *= stiffness_scale;
  options.k_bend *= stiffness_scale;
  const clothsim::Model full = clothsim::build_model(*e.scene, options);
  clothsim::Model no_bend = without_bend_springs(full);
  clothsim::Model no_coll = full;
  no_coll.colliders = nullptr;
  std::cout << "== " << e.name << ": " << full.mass_count() << " masses, " << full.spring_count()
            << " springs (" << no_bend.spring_count() << " structural)\n";
  std::cout << std::left << std::setw(26) << "variant" << std::setw(16) << "us per step" << std::setw(16)
            << "omega_max" << "dt_stable (symplectic Euler)\n";
  for (const auto& [name, m] : {std::pair<const char*, const clothsim::Model*>{"full", &full},
                                {"no bend springs", &no_bend},
                                {"no colliders", &no_coll}}) {
    const auto r = clothsim::analyse_stability(*m);
    std::cout << std::setw(26) << name << std::setw(16) << std::setprecision(4) << 1e6 * seconds_per_step(*m)
              << std::setw(16) << r.omega_max << r.dt_stable_symplectic << " s\n";
  }
}


// The command line, as parsed.
struct Cli {
  std::string out_dir = "work-precision";
  std::vector<std::string> scenes, methods;
  bool fast = false, cost = false, fine = false;
  double horizon = 0.0, stiffness_scale = 1.0;
  int levels = 0, repeats = -1, ref_refine = 0;
  bool scale_given = false;
};

// A finite number > 0 (CLI11's PositiveNumber lets nan through, and prints its range as 0 to
// a 309-digit number).
CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) || !(v > 0.0))
          return "must be a finite number > 0 (got '" + text + "')";
        return {};
      },
      "NUMBER > 0");
}

std::string known_scenes() {
  std::string known;
  for (const auto& e : baked_scenes()) known += (known.empty() ? "" : ", ") + std::string(e.name);
  return known;
}

// Parses the command line into `c`: -1 to go on, else the exit code (--help, bad input: 2).
int parse(int argc, char** argv, Cli& c) {
  CLI::App app{"clothsim_wp: work-precision report (every integrator, halved dt, against a reference)"};
  app.set_version_flag("--version", CLOTHSIM_WP_VERSION);
  app.add_option("--out", c.out_dir, "directory for <scene>.csv and <scene>.svg")->capture_default_str();
  app.add_option("--scene", c.scenes, "scene(s) to study: " + known_scenes() + " (default: all of them)");
  app.add_option("--integrators", c.methods, "integrators (default: all): " + clothsim::integrator_names())
      ->delimiter(',');
  app.add_flag("--fast", c.fast, "smoke run: short horizon, 3 levels, 1 repeat");
  auto* o_scale = app.add_option("--stiffness-scale", c.stiffness_scale,
                                 "multiply every spring's stiffness (stiffer cloth)")
                      ->check(finite_positive());
  app.add_flag("--model-cost", c.cost, "instead: time per step and dt_stable with and without bend springs / colliders");
  app.add_flag("--fine", c.fine, "instead: the fine, stiff case (skirt_hires in cotton, from just before contact; "
                                 "with --fast a short smoke run); writes <out>/skirt_hires.csv");
  app.add_option("--horizon", c.horizon, "simulated seconds per run (default per scene; rounded to whole steps of the "
                                         "largest dt)")
      ->check(finite_positive());
  app.add_option("--levels", c.levels, "number of halved dt per method (default 8)")->check(CLI::Range(2, 16));
  app.add_option("--repeats", c.repeats, "timed runs after the warm-up (default 3)")->check(CLI::Range(1, 20));
  app.add_option("--ref-refine", c.ref_refine, "reference step = smallest dt / this (default 8)")
      ->check(CLI::Range(2, 64));
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {  // bad input: exit 2, like clothsim (CLI11's own codes vary)
    std::cerr << "clothsim_wp: error: " << e.what() << "\n";
    return 2;
  }
  c.scale_given = o_scale->count() > 0;
  // a table on the terminal, or a study of its own: the sweep's options do nothing there
  const std::vector<const char*> sweep_only = {"--horizon", "--levels", "--repeats", "--ref-refine", "--scene",
                                               "--stiffness-scale"};
  if (c.cost)
    for (const char* name : {"--out", "--integrators", "--horizon", "--levels", "--repeats", "--ref-refine", "--fast",
                             "--fine"})
      if (app.count(name) > 0) {
        std::cerr << "clothsim_wp: error: " << name << " is for the study, not for --model-cost\n";
        return 2;
      }
  if (c.fine)
    for (const char* name : sweep_only)
      if (app.count(name) > 0) {
        std::cerr << "clothsim_wp: error: " << name << " is for the sweep over baked scenes, not for --fine\n";
        return 2;
      }
  return -1;
}

// --integrators into `out`: -1 to go on, 2 for an unknown name or one given twice.
int parse_methods(const std::vector<std::string>& names, std::vector<clothsim::Integrator>& out) {
  for (const std::string& name : names) {
    const auto m = clothsim::parse_integrator(name);
    if (!m) {
      std::cerr << "clothsim_wp: error: --integrators: unknown integrator '" << name << "' (known: "
                << clothsim::integrator_names() << ")\n";
      return 2;
    }
    // (given twice, its points would merge and its fitted order would be nonsense)
    if (std::find(out.begin(), out.end(), *m) != out.end()) {
      std::cerr << "clothsim_wp: error: --integrators: '" << name << "' given twice\n";
      return 2;
    }
    out.push_back(*m);
  }
  return -1;
}

// --scene into `todo` (all of them when none is named): -1 to go on, else 2.
int select_scenes(const std::vector<std::string>& scenes, std::vector<SceneEntry>& todo) {
  const auto all = baked_scenes();
  if (all.empty()) {
    std::cerr << "clothsim_wp: error: built without any of the scenes skirt, hanging\n";
    return 2;
  }
  for (const std::string& name : scenes) {
    bool found = false;
    for (const auto& e : todo)
      if (name == e.name) {
        std::cerr << "clothsim_wp: error: --scene: '" << name << "' given twice\n";
        return 2;
      }
    for (const auto& e : all)
      if (name == e.name) todo.push_back(e), found = true;
    if (!found) {
      std::cerr << "clothsim_wp: error: --scene: '" << name << "' is not one of this tool's scenes ("
                << known_scenes() << ")\n";
      return 2;
    }
  }
  if (todo.empty()) todo = all;
  return -1;
}

std::string label_of(const SceneEntry& e, double stiffness_scale) {
  if (stiffness_scale == 1.0) return e.name;
  std::ostringstream o;
  o << e.name << "_k" << stiffness_scale;
  return o.str();
}

// The sweep over the baked scenes: 0, 1 (a failed run or write), 2 (a scaled stiffness overflows).
int run_studies(const Cli& c, const clothsim::wp::Settings& settings, const std::vector<SceneEntry>& todo) {
  int status = 0;
  for (const auto& e : todo) {
    clothsim::wp::Settings s = settings;
    s.horizon = c.horizon > 0.0 ? c.horizon : (c.fast ? 0.05 : e.horizon);
    clothsim::Options options = study_options(e);
    const std::string label = label_of(e, c.stiffness_scale);
    if (c.stiffness_scale != 1.0) {  // both kinds, before the build: nothing keeps the old values
      options.k_struct *= c.stiffness_scale;
      options.k_bend *= c.stiffness_scale;
      if (!std::isfinite(options.k_struct) || !std::isfinite(options.k_bend)) {
        std::cerr << "clothsim_wp: error: --stiffness-scale " << c.stiffness_scale
                  << ": the scaled stiffness overflows\n";
        return 2;
      }
    }
    const clothsim::Model model = clothsim::build_model(*e.scene, options);
    const auto result = clothsim::wp::run(model, label, s, std::cerr);
    if (c.horizon > 0.0 && std::abs(result.horizon - c.horizon) > 1e-9 * c.horizon)
      std::cerr << "clothsim_wp: note: --horizon " << c.horizon << " s taken as " << result.horizon
                << " s (whole steps of the largest dt, at least one)\n";
    clothsim::wp::write_outputs(result, c.out_dir);
    clothsim::wp::print_summary(result, std::cout);
    std::cout << "wrote " << c.out_dir << "/" << label << ".csv and .svg\n" << std::flush;
    // a point flagged finite must carry a finite error (never a NaN passed on silently)
    for (const auto& p : result.points)
      if (p.finite && !std::isfinite(p.error)) status = 1;
  }
  return status;
}

// --fine: the fine, stiff case, skirt_hires with the default options (cotton, xpbd), without
// self-contact (the study compares the integrators).
int run_fine_case(const Cli& c, const std::vector<clothsim::Integrator>& methods) {
#ifdef CLOTHSIM_WP_HAVE_SKIRT_HIRES
  const std::string label = "skirt_hires";
  if (const std::string why = clothsim::wp::check_outputs(c.out_dir, label); !why.empty()) {
    std::cerr << "clothsim_wp: error: --out: " << why << "\n";
    return 2;
  }
  clothsim::wp::FineSettings s;
  s.methods = methods;
  if (c.fast) {  // one frame, the planned steps only (xpbd also at a quarter of it)
    s.frames = 1;
    s.samples = 1;
    s.explicit_factors = {1.0};
    s.implicit_factors = {4.0};
    s.xpbd_factors = {1.0, 0.25};
  }
  clothsim::Options options;
  options.self_collision = clothsim::Switch::Off;  // (the study measures the integrators)
  const clothsim::Model model = clothsim::build_model(b2o::gen::skirt_hires::scene, options);
  const auto result = clothsim::wp::run_fine(model, label, s, std::cerr);
  clothsim::wp::write_fine_csv(result, c.out_dir);
  clothsim::wp::print_fine_summary(result, s, std::cout);
  std::cout << "wrote " << c.out_dir << "/" << label << ".csv\n" << std::flush;
  return 0;
#else
  (void)methods;
  std::cerr << "clothsim_wp: error: --fine: built without the scene skirt_hires\n";
  return 2;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  Cli c;
  if (const int code = parse(argc, argv, c); code >= 0) return code;
  clothsim::wp::Settings settings;
  if (c.fast) {
    settings.levels = 3;
    settings.repeats = 1;
    settings.ref_refine = 4;
  }
  if (c.levels > 0) settings.levels = c.levels;
  if (c.repeats > 0) settings.repeats = c.repeats;
  if (c.ref_refine > 0) settings.ref_refine = c.ref_refine;
  if (const int code = parse_methods(c.methods, settings.methods); code >= 0) return code;
  try {
    if (c.fine) return run_fine_case(c, settings.methods);
  } catch (const std::exception& ex) {
    std::cerr << "clothsim_wp: error: " << ex.what() << "\n";
    return 1;
  }
  std::vector<SceneEntry> todo;
  if (const int code = select_scenes(c.scenes, todo); code >= 0) return code;
  if (c.cost) {
    for (const auto& e : todo) model_cost(e, c.scale_given ? c.stiffness_scale : 1.0);
    return 0;
  }
  // The outputs <out>/<label>.csv/.svg, checked before the study (minutes): a bad path is bad input.
  for (const auto& e : todo)
    if (const std::string why = clothsim::wp::check_outputs(c.out_dir, label_of(e, c.stiffness_scale)); !why.empty()) {
      std::cerr << "clothsim_wp: error: --out: " << why << "\n";
      return 2;
    }
  try {
    return run_studies(c, settings, todo);
  } catch (const std::exception& ex) {
    std::cerr << "clothsim_wp: error: " << ex.what() << "\n";
    return 1;
  }
}
