// Work-precision study (docs/work-precision.md): every integrator over a sweep of halved dt
// against a far more accurate reference; error = RMS vertex position error at fixed times /
// cloth size, work = minimum CPU time of several runs after a warm-up. Writes a CSV and an SVG
// plot.
#pragma once

#include <clothsim/sim.hpp>

#include <iosfwd>
#include <string>
#include <vector>

namespace clothsim::wp {

struct Settings {
  double horizon = 1.0;         ///< s, simulated time of every run
  int samples = 4;              ///< error sampled at horizon * j / samples, j = 1..samples
  int levels = 8;               ///< dt_top / 2^k, k = 0..levels-1
  double top_factor = 4.0;      ///< explicit methods: dt_top = top_factor * symplectic Euler's dt_stable
  double implicit_top_factor = 64.0;  ///< implicit methods start higher (no stability limit)
  int repeats = 3;              ///< timed runs after the warm-up (1 when a run takes > 2 s)
  int ref_refine = 8;           ///< h_ref = smallest dt / ref_refine (RK4)
  std::vector<Integrator> methods;  ///< empty: all
};

struct Point {
  Integrator method{};
  double dt = 0.0, error = 0.0, seconds = 0.0;
  long steps = 0;
  bool finite = true;
  bool resolved = true;  ///< shown: 10x the reference check <= error <= 1 (the cloth's size)
};

struct MethodSummary {
  Integrator method{};
  double order = 0.0;        ///< mean log2(e_i / e_{i+1}) over resolved consecutive points; NaN if < 2
  double time_1pc = 0.0;     ///< s to reach 1 % error (log-log interpolation); NaN: not reached
  double time_01pc = 0.0;    ///< s to reach 0.1 % error
  double time_1e4 = 0.0;     ///< s to reach 1e-4 (0.01 %)
  bool bound_1pc = false, bound_01pc = false, bound_1e4 = false;  ///< below at the largest dt: an upper bound
};

struct Result {
  std::string scene;
  double size = 0.0;             ///< m, bounding-box diagonal of the cloth at rest
  double horizon = 0.0;          ///< s, as run (rounded to whole largest steps)
  double dt_stable = 0.0;        ///< s, symplectic Euler's limit (guard)
  double h_ref = 0.0;            ///< s
  double ref_check = 0.0;        ///< relative RMS difference of h_ref vs h_ref / 2
  double first_contact = -1.0;   ///< s, first contact in the reference run; -1: none
  double smallest_error = 0.0;   ///< smallest resolved error shown
  std::vector<Point> points;
  std::vector<MethodSummary> summary;
  double se_limit_dt = 0.0;      ///< s, the largest dt <= 0.95 dt_stable on the sample grid
  double se_limit_seconds = 0.0; ///< symplectic Euler at se_limit_dt: CPU time
  double se_limit_error = 0.0;
  double speedup_1pc = 0.0;      ///< se_limit_seconds / best time_1pc (NaN if none)
  Integrator best_1pc{};
  double speedup_1e4 = 0.0;      ///< symplectic Euler's time_1e4 / the best other method's
  Integrator best_1e4{};
};

/// m, the bounding-box diagonal of the model's rest positions (the error's scale).
double cloth_size(const Model& model);

/// The CPU time (Point::seconds) at which a curve reaches `target` error for good (this and
/// every smaller dt below it), interpolating log-log between the points (sorted by dt
/// descending). NaN if never reached; `bound` when already below at the largest dt (an upper
/// bound).
double time_to(const std::vector<const Point*>& points, double target, bool& bound);

/// Runs the study on one Model; progress lines go to `progress`.
Result run(const Model& model, const std::string& scene, const Settings& settings, std::ostream& progress);

/// Before the study: empty, or why <dir>/<scene>.csv or .svg cannot be written (a directory in
/// their place, `dir` not a directory, ...), one line naming the path.
std::string check_outputs(const std::string& dir, const std::string& scene);

/// Writes <dir>/<scene>.csv and <dir>/<scene>.svg by the output rule of clothsim/output_file.hpp
/// (a regular file through a temporary file + rename, a device in place, a directory refused).
/// Throws std::runtime_error naming the file on failure.
void write_outputs(const Result& result, const std::string& dir);

/// The human-readable summary (orders, time to 1 % / 0.1 %, reference check, target).
void print_summary(const Result& result, std::ostream& out);

}  // namespace clothsim::wp
