// The stages after the command line: build and plan, run, report.
#pragma once

#include "run_config.hpp"

#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <csignal>
#include <optional>
#include <cstdint>
#include <string>
#include <vector>

namespace b2o { struct Scene; }

namespace clothsim::app {

/// Set by SIGINT/SIGTERM while a run is on (io::SignalHandlers).
extern volatile std::sig_atomic_t g_interrupted;

/// What the run is built on: the Model as built, and what the stability guard decided.
struct Plan {
  Model model;
  StabilityReport stability;
  SubstepPlan substeps;          ///< h = dt / substeps
  TunnellingReport tunnel;
  std::vector<std::string> warnings;  ///< printed at start, listed in the report
};

/// Builds the model and plans the run; prints the stability line and the warnings. Returns
/// -1 to go on, else the exit code (the error already said).
int prepare(const RunConfig& config, const b2o::Scene& scene, Plan& plan);

/// s of simulated time between the frames --check-crossings counts (the first state at or
/// after each multiple, t = 0 included).
inline constexpr double kCrossingsEvery = 0.05;

/// What a headless run did.
struct RunResult {
  State state;
  bool finite = true, interrupted = false;
  std::uint64_t total = 0;        ///< steps of dt asked
  std::uint64_t done = 0;         ///< steps of dt completed (each of plan.substeps substeps)
  std::uint64_t timed = 0;        ///< steps of dt timed (the failed one included)
  std::uint64_t failed_step = 0;  ///< the step of dt (1-based) in which the state became non-finite
  double t_done = 0.0;            ///< s simulated after the last completed step
  double max_strain = 0.0;        ///< the largest structural strain after any step of dt
  // --check-crossings: the most self-crossings of a counted frame, and the first frame's time
  std::size_t max_self_crossings = 0;
  double max_self_crossings_t = 0.0;
  double ms_per_step = 0.0, cpu_ms_per_step = 0.0;  ///< per step of dt, its substeps included
  std::optional<SelfContactCounts> self_counts;  ///< the self-contact stage's work (nullopt: off)
  // threads: auto (steps with one and with `cores` threads), or the fixed count
  bool auto_threads = false;
  int cores = 1, threads = 1;
  std::uint64_t steps_one = 0, steps_many = 0, trials = 0, trials_won_by_many = 0;
};

/// Steps the plan's model headless; writes the OBJ frames of --export-obj. Returns -1 to go
/// on, else the exit code of an I/O failure (said).
int run_headless(const RunConfig& config, const b2o::Scene& scene, const Plan& plan, RunResult& result);

/// The JSON report, the closing summary and the explanation of a failure; returns the exit
/// code. A kinetic energy that overflows joins the plan's warnings.
int report_run(const RunConfig& config, Plan& plan, RunResult& result);

/// One OBJ file <dir>/<scene>_<step>.obj by the output rule; `step` counts steps of `dt`.
/// Returns empty or the error.
std::string export_obj(const std::string& dir, const b2o::Scene& scene, const Model& model, const State& s,
                       std::uint64_t step, double dt);

}  // namespace clothsim::app
