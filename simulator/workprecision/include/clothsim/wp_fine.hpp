// The fine, stiff case of the work-precision study (docs/work-precision.md, "Fine, stiff case"):
// a real material on a fine mesh with contact, where symplectic Euler's stable step is tiny.
// Every run starts from one state saved just before first contact (the fall is run once, by
// the default method at its planned step) and covers a short measured interval. Each step h is
// a whole fraction of the model's frame step (options.dt), taken as the app takes it: h =
// dt / substeps, the strain limit once per frame. Per run: CPU time per simulated second, the
// error against a reference (RMS position error at the sample times / cloth size) and the
// largest structural strain at the end of any frame.
#pragma once

#include <clothsim/sim.hpp>
#include <clothsim/workprecision.hpp>

#include <iosfwd>
#include <string>
#include <vector>

namespace clothsim::wp {

struct FineSettings {
  double lead = 0.02;        ///< s, the measured interval starts this long before first contact
  int frames = 8;            ///< measured interval, in frames (options.dt each)
  int samples = 4;           ///< error sampled at the end of every frames / samples frames
  /// h = factor x the method's planned step: explicit methods x symplectic Euler's (the guard's
  /// substeps of the frame), implicit Euler and fast mass-spring x XPBD's, XPBD x its own
  std::vector<double> explicit_factors{2.0, 1.0, 0.5};
  std::vector<double> implicit_factors{4.0, 2.0, 1.0};
  std::vector<double> xpbd_factors{4.0, 2.0, 1.0, 0.5, 0.25, 0.125, 0.0625};
  double ref_factor = 1.0;   ///< reference: RK4 at this x symplectic Euler's planned step, checked at half
  double strain_cap = 0.10;  ///< "equal maximum strain"
  double error_target = 0.01;
  std::vector<Integrator> methods;  ///< empty: all
};

struct FinePoint {
  Integrator method{};
  int substeps = 1;           ///< per frame
  double h = 0.0;             ///< s
  bool planned = false;       ///< the method's planned step (factor 1)
  bool finite = true;
  double error = 0.0;         ///< NaN when not finite
  double cpu_per_second = 0.0;  ///< CPU s per simulated s
  double max_strain = 0.0;    ///< at the end of every frame
  long steps = 0;
};

struct FineRow {
  Integrator method{};
  double strain_h = 0.0;      ///< largest h with a finite run at or below strain_cap (NaN: none)
  double strain_cpu = 0.0;    ///< its CPU s per simulated s
  double strain_error = 0.0;  ///< its error
  double target_cpu = 0.0;    ///< CPU s per simulated s to error_target (NaN: not reached)
  bool target_bound = false;  ///< already below at the largest h: an upper bound
  double run_h = 0.0;         ///< the cheapest run at or below error_target: its h (NaN: none)
  double run_cpu = 0.0;       ///< its CPU s per simulated s
};

struct FineResult {
  std::string scene;
  std::size_t masses = 0;
  double size = 0.0;          ///< m, rest bounding-box diagonal
  double frame = 0.0;         ///< s, options.dt
  double first_contact = 0.0; ///< s, in the fall run
  double start = 0.0;         ///< s, the measured interval's start
  double interval = 0.0;      ///< s
  double dt_stable = 0.0;     ///< s, symplectic Euler's guard limit
  double h_se = 0.0, h_xpbd = 0.0;  ///< s, the planned steps
  double h_ref = 0.0, ref_check = 0.0;
  double ref_contacts = 0.0;  ///< most points in contact in the reference run
  std::vector<FinePoint> points;
  std::vector<FineRow> rows;
  double se_cpu = 0.0;        ///< symplectic Euler's CPU per s at its planned step
  double speedup = 0.0;       ///< se_cpu / XPBD's to error_target (interpolated)
  double speedup_run = 0.0;   ///< se_cpu / XPBD's cheapest run at or below error_target
};

/// Runs the fine study on `model` (its integrator: the default method that runs the fall).
FineResult run_fine(const Model& model, const std::string& scene, const FineSettings& settings,
                    std::ostream& progress);

/// The table: per method, CPU per simulated second at equal strain and at the error target.
void print_fine_summary(const FineResult& result, const FineSettings& settings, std::ostream& out);

/// <dir>/<scene>.csv: one row per run (method, substeps, h, planned, finite, error,
/// cpu_per_second, max_strain, steps), by the output rule of write_outputs.
void write_fine_csv(const FineResult& result, const std::string& dir);

}  // namespace clothsim::wp
