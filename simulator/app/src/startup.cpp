// Build and plan: the Model from the scene and the options, the stability guard's substeps,
// the run's length, and every start-up warning (docs/stability.md).
#include "run.hpp"

#include <clothsim/closed_mesh.hpp>
#include <clothsim/integrators.hpp>
#include <clothsim/scene.hpp>
#include <clothsim/self_crossings.hpp>

#include <blender2ogl/scene_types.h>

#include <cmath>
#include <iostream>
#include <limits>

namespace clothsim::app {

namespace {

// A run longer than kMaxSteps steps of h; empty, or why.
std::string too_long(const RunConfig& c, const SubstepPlan& plan) {
  const double n = c.step_count(), total_h = n * plan.substeps;
  if (total_h <= static_cast<double>(kMaxSteps)) return {};
  const auto count = [](double v) { return v < 1e15 ? std::to_string(static_cast<std::uint64_t>(v)) : fmt(v); };
  std::string why;
  if (c.steps)  // within kMaxSteps itself: too many only with substeps
    why = "--steps " + std::to_string(*c.steps) + " of " + std::to_string(plan.substeps) + " substeps each is " +
          count(total_h) + " steps of " + fmt(plan.h) + " s";
  else {
    why = "--seconds " + fmt(c.seconds.value_or(c.default_seconds)) + " at --dt " + fmt(c.options.dt) + " is " +
          count(n) + " steps";
    if (plan.substeps > 1)
      why += " of " + std::to_string(plan.substeps) + " substeps each (" + count(total_h) + " steps of " +
             fmt(plan.h) + " s)";
  }
  return why + "; one run takes at most " + std::to_string(kMaxSteps) +
         (c.steps ? " (fewer --steps)" : plan.substeps > 1 ? " (lower --seconds)" : " (raise --dt or lower --seconds)");
}

// The position-based methods take velocities from position differences, (x1 - x0) / h: when a
// step's motion under gravity, g h^2, is near the rounding of the positions, the velocities are
// mostly rounding (fast-mass-spring 41 % off, XPBD 13 %, at dt 1e-8 over 1000 steps). Warned
// below a relative error of 1e-3 per step.
std::string rounding_warning(const Model& model, double h) {
  const Integrator method = model.options.integrator;
  if ((method != Integrator::FastMassSpring && method != Integrator::XPBD) || model.mass_count() == 0) return {};
  const double g = gravity(model.options).norm(), reach = model.x0.cwiseAbs().maxCoeff();
  const double ulp = std::numeric_limits<double>::epsilon() * std::max(reach, 1e-300);
  if (!(g > 0.0) || !std::isfinite(reach) || h * h * g >= 1e3 * ulp) return {};
  return "warning: " + std::string(to_string(method)) +
         " takes velocities from position differences, and a step of " + fmt(h) + " s moves a mass by about g h^2 = " +
         fmt(g * h * h) + " m, near the rounding of positions up to " + fmt(reach) +
         " m: the velocities will be mostly rounding; use a step of at least " + fmt(std::sqrt(1e3 * ulp / g)) +
         " s, or another integrator";
}

// A cloth that starts passing through itself, or touching itself (an edge on a triangle it is
// not part of): self-contact keeps what it is given, and holds such places where they are.
std::string crossing_warning(const Model& model) {
  if (model.options.self_collision != Switch::On) return {};
  const CrossingCount c = count_self_crossings(model, model.x0);
  if (c.crossings == 0 && c.touches == 0) return {};
  const std::string crossings = std::to_string(c.crossings) + " self-crossings (" +
                                std::to_string(c.triangle_pairs) + " triangle pairs)";
  const std::string touches = std::to_string(c.touches) + " places where an edge touches a triangle";
  const std::string what = c.touches == 0 ? crossings : c.crossings == 0 ? touches : crossings + " and " + touches;
  return "warning: the cloth starts with " + what +
         ": self-contact makes no new crossing but cannot undo these, and the layers stay caught where "
         "they meet; fix the model in Blender (clothsim_crossings counts them in an OBJ)";
}

// Every start-up warning: a step above the safe one, no cloth, tunnelling, colliders whose
// faces point inwards, masses that start inside a collider's band, position rounding, a
// cloth that starts through itself.
std::vector<std::string> startup_warnings(const Plan& p, const b2o::Scene& scene) {
  std::vector<std::string> w;
  if (p.substeps.message.rfind("warning: ", 0) == 0) w.push_back(p.substeps.message);
  if (p.model.mass_count() == 0)
    w.push_back(std::string("warning: scene '") + (scene.name ? scene.name : "?") +
                "' has no cloth: nothing moves (name the cloth objects in blender2ogl_add_scene's CLOTH, or "
                "blender2ogl -a)");
  if (p.tunnel.warn) w.push_back(p.tunnel.message);
  for (std::string& s : collider_warnings(p.model)) w.push_back(std::move(s));
  if (std::string s = rounding_warning(p.model, p.substeps.h); !s.empty()) w.push_back(std::move(s));
  if (std::string s = crossing_warning(p.model); !s.empty()) w.push_back(std::move(s));
  return w;
}

}  // namespace

int prepare(const RunConfig& c, const b2o::Scene& scene, Plan& p) {
  try {
    p.model = build_model(scene, c.options);
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << "\n";
    return kExitFailed;
  }
  // The stability guard: omega_max (springs by Lanczos + contact), the limit of this
  // integrator, substeps or refusal, and the tunnelling check.
  if (!c.quiet && p.model.mass_count() >= 50000)  // Lanczos: ~3 s at 90k masses, ~45 s at 500k
    std::cerr << "clothsim: stability: estimating omega_max of " << p.model.mass_count()
              << " masses (Lanczos; seconds per 100k masses)...\n";
  p.stability = analyse_stability(p.model);
  p.substeps = plan_substeps(c.options.dt, p.stability.dt_stable, c.substeps);
  if (!p.substeps.ok)
    return bad_input("--dt " + fmt(c.options.dt) + ": " +
                     (p.stability.dt_stable > 0.0 ? p.substeps.message
                                                  : never_stable_reason(p.stability, c.options.integrator)));
  if (std::string why = too_long(c, p.substeps); !why.empty()) return bad_input(why);
  p.tunnel = check_tunnelling(p.model, p.substeps.h);
  if (!c.quiet) {
    std::cerr << "clothsim: " << describe(p.stability, c.options.integrator) << "\n";
    // a note (a warning is listed with the others below, also under --quiet)
    if (!p.substeps.message.empty() && p.substeps.message.rfind("warning: ", 0) != 0)
      std::cerr << "clothsim: note: " << p.substeps.message << "\n";
  }
  p.warnings = startup_warnings(p, scene);
  for (const std::string& w : p.warnings) std::cerr << "clothsim: " << w << "\n";
  return -1;
}

}  // namespace clothsim::app
