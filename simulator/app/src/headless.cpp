// The headless run: steps of dt (each of the plan's substeps) as fast as they go, timed, with
// the OBJ frames and a progress bar; stops at a non-finite state or on Ctrl-C.
#include "progress.hpp"
#include "run.hpp"

#include <clothsim/self_crossings.hpp>
#include <clothsim/thread_choice.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <optional>

namespace clothsim::app {

namespace {

// The note for a time that is no whole number of steps of dt.
void note_rounded_time(const RunConfig& c, std::uint64_t total) {
  const double seconds = c.seconds.value_or(c.default_seconds), dt = c.options.dt;
  if (c.steps || c.quiet) return;
  const double covered = static_cast<double>(total) * dt;
  if (covered == seconds || std::abs(covered - seconds) <= 1e-12 * seconds) return;
  std::cerr << "clothsim: note: " << (c.seconds ? "--seconds " + fmt(seconds) : "the default " + fmt(seconds) + " s")
            << " is not a whole number of steps of " << (c.given("dt") ? "--dt " : "dt ") << fmt(dt) << ": " << total
            << " step" << (total == 1 ? "" : "s") << " (" << fmt(covered) << " s)\n";
}

// The folder of --export-obj, made; empty, or the error.
std::string make_export_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!ec && std::filesystem::is_directory(dir)) return {};
  return "--export-obj: cannot create directory '" + dir + "'" + (ec ? ": " + ec.message() : std::string());
}

// --check-crossings: counts the frames every kCrossingsEvery s of simulated time and keeps the
// most (the first frame with it).
struct CrossingsWatch {
  bool on = false;
  std::int64_t last_frame = -1;
  void look(const Model& model, RunResult& r) {
    const auto frame = static_cast<std::int64_t>(std::floor(r.state.t / kCrossingsEvery + 1e-9));
    if (!on || frame <= last_frame) return;
    last_frame = frame;
    const std::size_t n = count_self_crossings(model, r.state.x).crossings;
    if (n > r.max_self_crossings || frame == 0) {
      r.max_self_crossings = n;
      r.max_self_crossings_t = r.state.t;
    }
  }
};

}  // namespace

int run_headless(const RunConfig& c, const b2o::Scene& scene, const Plan& p, RunResult& r) {
  r.total = static_cast<std::uint64_t>(c.step_count());
  note_rounded_time(c, r.total);
  const bool exporting = !c.export_dir.empty();
  if (exporting)
    if (std::string err = make_export_dir(c.export_dir); !err.empty()) {
      std::cerr << "clothsim: error: " << err << "\n";
      return kExitFailed;
    }
  const Model& model = p.model;
  r.state = make_state(model);
  Workspace ws = make_workspace(model);
  ws.substeps = p.substeps.substeps;
  std::optional<ThreadChooser> chooser;  // a model too small to split steps on one thread: nothing to measure
  if (c.auto_threads) chooser.emplace(step_splits(model) ? core_count() : 1);
  else ws.threads = resolve_threads(c.threads);
  Progress progress(r.total, !c.quiet, ::isatty(STDERR_FILENO) != 0);
  r.t_done = r.state.t;
  if (exporting)
    if (const std::string err = export_obj(c.export_dir, scene, model, r.state, 0, c.options.dt); !err.empty()) {
      std::cerr << "clothsim: error: --export-obj: " << err << "\n";
      return kExitFailed;
    }
  CrossingsWatch crossings{c.check_crossings};
  crossings.look(model, r);
  std::chrono::steady_clock::duration step_time{};
  const std::clock_t cpu0 = std::clock();  // CPU time: robust to other processes on the machine
  for (std::uint64_t i = 0; i < r.total; ++i) {
    if (g_interrupted) {
      r.interrupted = true;
      break;
    }
    const auto t0 = std::chrono::steady_clock::now();
    StepStatus st;
    for (int k = 0; k < ws.substeps && st.finite; ++k)  // with auto threads each step is timed for the chooser
      st = chooser ? chosen_step(*chooser, model, r.state, ws) : step(model, r.state, ws);
    step_time += std::chrono::steady_clock::now() - t0;
    ++r.timed;
    if (!st.finite) {
      r.finite = false;
      r.failed_step = i + 1;
      break;
    }
    r.done = i + 1;
    r.t_done = r.state.t;
    r.max_strain = std::max(r.max_strain, max_strain(model, r.state.x));
    crossings.look(model, r);
    if (exporting && r.done % c.export_every == 0)
      if (const std::string err = export_obj(c.export_dir, scene, model, r.state, r.done, c.options.dt); !err.empty()) {
        progress.finish();
        std::cerr << "clothsim: error: --export-obj: " << err << "\n";
        return kExitFailed;
      }
    progress.update(i + 1, r.state.t);
  }
  progress.finish();
  const double cpu_ms = 1000.0 * static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  const auto per_step = [&r](double ms) { return r.timed ? ms / static_cast<double>(r.timed) : 0.0; };
  r.ms_per_step = per_step(std::chrono::duration<double, std::milli>(step_time).count());
  r.cpu_ms_per_step = per_step(cpu_ms);  // includes --export-obj and --check-crossings
  r.self_counts = self_contact_counts(ws);
  r.auto_threads = chooser.has_value();
  if (chooser) {
    r.cores = chooser->cores();
    r.steps_one = chooser->steps_one();
    r.steps_many = chooser->steps_many();
    r.trials = chooser->trials();
    r.trials_won_by_many = chooser->trials_won_by_many();
  } else {
    r.threads = ws.threads;
  }
  return -1;
}

}  // namespace clothsim::app
