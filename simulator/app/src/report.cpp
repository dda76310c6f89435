// The end of a headless run: what it says on stderr when it failed, the JSON report
// (docs/scenes.md, "The report") and the closing summary.
#include "run.hpp"

#include <clothsim/output_file.hpp>
#include <clothsim/scene.hpp>
#include <clothsim/self_crossings.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>

#ifndef CLOTHSIM_VERSION
#define CLOTHSIM_VERSION "0.0.0"
#endif

namespace clothsim::app {

namespace {

using json = nlohmann::json;

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// What the end state looks like.
struct Outcome {
  Eigen::Vector3d lo, hi;   ///< the cloth's box (NaN for a failed run or no cloth)
  Eigen::Vector3d centre;   ///< its centre of mass
  double kinetic = 0.0;     ///< J
  bool ke_overflow = false; ///< finite, but the kinetic energy overflows a double
  double reach = 0.0;       ///< m, how far behind a surface the search sees (2 eps)
  bool past_eps = false;    ///< a mass was seen past eps (it may be deeper, or through)
  std::optional<std::size_t> self_crossings;  ///< at the end (none for a failed run)
};

Outcome outcome(const RunConfig& c, const Plan& p, const RunResult& r) {
  Outcome o;
  o.lo = o.hi = o.centre = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  if (p.model.mass_count() > 0 && r.finite) {  // (a failed run's state is no box: null)
    o.lo = r.state.x.rowwise().minCoeff();
    o.hi = r.state.x.rowwise().maxCoeff();
    o.centre = r.state.x * p.model.mass / p.model.mass.sum();
  }
  o.kinetic = kinetic_energy(p.model, r.state);
  // A finite state whose kinetic energy overflows (--mass 1e306, --gravity 1e200) is out of a
  // double's range: a failure like a non-finite state.
  o.ke_overflow = r.finite && !r.interrupted && !std::isfinite(o.kinetic);
  // The collision search reaches 2 eps behind a surface: a mass deeper than that is not seen,
  // so max_penetration is at most 2 eps and is no depth. Past eps the contact lets go.
  o.reach = 2.0 * c.options.epsilon;
  o.past_eps = r.state.max_penetration > c.options.epsilon;
  if (r.finite) o.self_crossings = count_self_crossings(p.model, r.state.x).crossings;
  return o;
}

// Why the state became non-finite, on stderr.
void explain_failure(const Plan& p, const RunResult& r) {
  const double omega = gershgorin_omega_max(p.model);
  const double gershgorin = omega > 0 ? 2.0 / omega : std::numeric_limits<double>::infinity();
  std::cerr << "clothsim: error: the state became non-finite at step " << r.failed_step << " (t = " << r.state.t
            << " s). Likely cause: ";
  const std::string h = "the step h = " + fmt(p.substeps.h) + " s" +
                        (p.substeps.substeps > 1 ? " (dt / " + std::to_string(p.substeps.substeps) + " substeps)"
                                                 : std::string());
  // (dt_stable: the guard's limit for this integrator, from omega_max by Lanczos; the
  // Gershgorin bound 2/omega_max is lower, and a step between the two is stable)
  if (!(p.substeps.h <= p.stability.dt_stable))
    std::cerr << h << " is above the stability limit dt_stable = " << p.stability.dt_stable
              << " s (the Gershgorin estimate 2/omega_max is " << gershgorin
              << " s; lower --dt, let --substeps auto substep, or soften --k-struct/--k-rep)\n";
  else
    std::cerr << "a force too large for double precision: " << h << " is within the stability limit dt_stable = "
              << p.stability.dt_stable << " s, so look at the sizes of the options (--gravity, --k-struct, "
              << "--k-bend, --k-rep, --mass)\n";
}

json options_json(const Options& o) {
  json j = json::object();
  for (const OptionInfo& info : option_table())
    j[std::string(info.name)] = info.is_choice ? json(info.text(o)) : json(info.value(o));
  return j;
}

json threads_json(const Model& model, const RunResult& r) {
  // threads: what was asked; thread_steps: model steps taken with each count
  json by_count = json::object();
  if (r.auto_threads) {
    by_count["1"] = r.steps_one;
    if (r.cores > 1) by_count[std::to_string(r.cores)] = r.steps_many;
  } else {
    // a model too small to split steps on one thread whatever was asked
    by_count[std::to_string(step_splits(model) ? r.threads : 1)] = r.state.steps;
  }
  return by_count;
}

json report_json(const RunConfig& c, const Plan& p, const RunResult& r, const Outcome& o) {
  const Model& m = p.model;
  const double omega = gershgorin_omega_max(m);
  json j;
  j["scene"] = m.scene_name;
  j["version"] = CLOTHSIM_VERSION;
  j["masses"] = m.mass_count();
  j["springs"] = m.spring_count();
  j["bend_springs"] = std::count(m.spring_kind.begin(), m.spring_kind.end(), std::uint8_t{1});
  j["pinned_masses"] = std::count(m.pinned.begin(), m.pinned.end(), std::uint8_t{1});
  j["collider_triangles"] = collider_triangle_count(m);
  j["dt"] = c.options.dt;
  j["steps"] = r.done;                       // steps of dt completed
  j["substeps"] = p.substeps.substeps;       // per step of dt
  j["substep_dt"] = p.substeps.h;            // dt / substeps
  j["dt_stable"] = number(p.stability.dt_stable);  // the guard's limit for this integrator
  j["omega_max"] = number(p.stability.omega_max);
  j["integrator"] = to_string(c.options.integrator);
  j["tunnelling_warning"] = p.tunnel.warn;
  j["warnings"] = p.warnings;
  j["seconds_simulated"] = r.t_done;         // (a failed run: up to the last step that completed)
  j["ms_per_step"] = r.ms_per_step;
  j["cpu_ms_per_step"] = r.cpu_ms_per_step;  // includes --export-obj
  j["finite"] = r.finite;
  if (!r.finite) j["failed_step"] = r.failed_step;
  j["interrupted"] = r.interrupted;          // stopped by Ctrl-C or SIGTERM after `steps` steps
  j["cloth_min"] = {number(o.lo.x()), number(o.lo.y()), number(o.lo.z())};
  j["cloth_max"] = {number(o.hi.x()), number(o.hi.y()), number(o.hi.z())};
  j["cloth_centre"] = {number(o.centre.x()), number(o.centre.y()), number(o.centre.z())};  // of mass
  j["max_penetration"] = number(r.state.max_penetration);  // behind a surface, within the search's reach
  j["max_penetration_reach"] = o.reach;                    // 2 eps: deeper is not seen
  j["max_penetration_past_eps"] = o.past_eps;              // true: masses may be deeper or through
  j["kinetic_energy"] = number(o.kinetic);
  j["max_strain"] = number(r.max_strain);  // the largest structural strain after any step of dt
  j["self_crossings"] = o.self_crossings ? json(*o.self_crossings) : json(nullptr);  // at the end
  if (c.check_crossings) {  // the most of the frames every kCrossingsEvery s, and when
    j["max_self_crossings"] = r.max_self_crossings;
    j["max_self_crossings_t"] = r.max_self_crossings_t;
  }
  // the self-contact stage's detections and candidate-list builds over the run (null: off)
  j["self_detections"] = r.self_counts ? json(r.self_counts->detections) : json(nullptr);
  j["self_list_builds"] = r.self_counts ? json(r.self_counts->list_builds) : json(nullptr);
  j["self_pin_overruns"] = r.self_counts ? json(r.self_counts->pin_overruns) : json(nullptr);
  j["self_split_steps"] = r.self_counts ? json(r.self_counts->split_steps) : json(nullptr);
  j["stable_dt_estimate"] = number(omega > 0 ? 2.0 / omega : std::numeric_limits<double>::infinity());
  j["options"] = options_json(c.options);
  j["threads"] = r.auto_threads ? json("auto") : json(r.threads);
  j["thread_steps"] = threads_json(m, r);
  return j;
}

void print_summary(const RunConfig& c, const Plan& p, const RunResult& r, const Outcome& o) {
  std::cout << p.model.scene_name << ": " << r.done << " steps of " << c.options.dt << " s";
  if (p.substeps.substeps > 1) std::cout << " (" << p.substeps.substeps << " substeps of " << p.substeps.h << " s each)";
  std::cout << ", " << r.state.t << " s simulated, " << r.ms_per_step << " ms/step, max penetration "
            << r.state.max_penetration << " m"
            << (o.past_eps ? " (behind a surface, as far as the search reaches: 2 eps = " + fmt(o.reach) +
                                 " m; past eps the contact lets go, masses may be deeper or through)"
                           : std::string())
            << ", kinetic energy " << o.kinetic << " J, cloth y " << o.lo.y() << " .. " << o.hi.y()
            << ", max strain " << fmt(100.0 * r.max_strain) << " %";
  if (c.check_crossings)
    std::cout << ", self-crossings " << o.self_crossings.value_or(0) << " (most " << r.max_self_crossings
              << " at t = " << fmt(r.max_self_crossings_t) << " s)";
  std::cout << "\n";
  if (r.auto_threads && r.cores > 1 && r.steps_one + r.steps_many > 0) {
    const double share = static_cast<double>(r.steps_many) / static_cast<double>(r.steps_one + r.steps_many);
    char pct[32];
    std::snprintf(pct, sizeof pct, "%.1f %%", 100.0 * share);
    std::cout << "threads auto: " << r.cores << " threads for " << pct << " of the steps (" << r.trials_won_by_many
              << " of " << r.trials << " trials won by " << r.cores << " threads)\n";
  }
}

}  // namespace

int report_run(const RunConfig& c, Plan& p, RunResult& r) {
  if (r.interrupted)
    std::cerr << "clothsim: interrupted after " << r.done << " of " << r.total << " steps (t = " << r.state.t << " s)"
              << (!c.report.empty() ? "; the report says so" : "") << "\n";
  const Outcome o = outcome(c, p, r);
  if (o.ke_overflow) {
    const std::string why = "error: the kinetic energy overflows a double at t = " + fmt(r.state.t) +
                            " s: the masses and speeds are out of range; look at the sizes of the options "
                            "(--mass, --gravity, --k-struct, --k-rep)";
    std::cerr << "clothsim: " << why << "\n";
    p.warnings.push_back(why);
  }
  if (r.self_counts && r.self_counts->pin_overruns > 0) {
    const std::string why = "warning: a turning pin came nearer to the cloth than its move over one step (" +
                            std::to_string(r.self_counts->pin_overruns) + " pairs over the detections, the first at t = " +
                            fmt(r.self_counts->first_pin_overrun_t) +
                            " s): self-contact cannot keep those places from crossing; a smaller step (more --substeps) "
                            "or slower pins keep them apart";
    std::cerr << "clothsim: " << why << "\n";
    p.warnings.push_back(why);
  }
  if (!r.finite) explain_failure(p, r);
  if (!c.report.empty())
    if (const std::string err = io::write_output_file(c.report, report_json(c, p, r, o).dump(2) + "\n"); !err.empty()) {
      std::cerr << "clothsim: error: --report: " << err << "\n";
      return kExitFailed;
    }
  if (!r.finite || o.ke_overflow) return kExitFailed;
  if (r.interrupted) return kExitInterrupted;
  if (!c.quiet) print_summary(c, p, r, o);
  return kExitOk;
}

}  // namespace clothsim::app
