// The fine, stiff case of the work-precision study; see wp_fine.hpp and docs/work-precision.md.
#include <clothsim/integrators.hpp>
#include <clothsim/output_file.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>
#include <clothsim/wp_fine.hpp>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <deque>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace clothsim::wp {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFallLimit = 10.0;  ///< s of fall without contact: the scene has none to study
constexpr double kRepeatBelow = 1.0;  ///< s: a run this cheap is timed once more (the least counts)

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string fmt(double v, int prec = 3) {
  if (std::isnan(v)) return "-";
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

int planned_substeps(const Model& m, double dt_stable) {
  return plan_substeps(m.options.dt, dt_stable, SubstepPolicy{}).substeps;
}

struct Start {
  State state;
  double first_contact = 0.0;
};

// The fall, run once by the model's own method at its planned substeps: the state at the last
// frame boundary at least `lead` before the first step with a point in a collider band.
Start fall_to_contact(const Model& model, double lead) {
  Workspace ws = make_workspace(model);
  ws.substeps = planned_substeps(model, analyse_stability(model).dt_stable);
  State s = make_state(model);
  std::deque<State> frames{s};  // the recent frame boundaries
  const auto keep = static_cast<std::size_t>(std::ceil(lead / model.options.dt)) + 2;
  for (;;) {
    for (int q = 0; q < ws.substeps; ++q) {
      if (!step(model, s, ws).finite) throw std::runtime_error("the fall to first contact is not finite");
      if (ws.last_contacts > 0) {
        Start out;
        out.first_contact = s.t;
        out.state = frames.front();
        for (const State& f : frames)
          if (f.t <= s.t - lead + 1e-12) out.state = f;
        out.state.steps = 0;
        out.state.max_penetration = 0.0;
        return out;
      }
    }
    frames.push_back(s);
    if (frames.size() > keep) frames.pop_front();
    if (s.t > kFallLimit) throw std::runtime_error("no contact within 10 s of fall");
  }
}

struct Run {
  std::vector<Eigen::Matrix3Xd> x;  ///< positions at the sample frames
  bool finite = true;
  long steps = 0;
  double seconds = 0.0;             ///< CPU time of the steps alone
  double max_strain = 0.0;
  std::uint32_t contacts = 0;       ///< most points in a collider band at once
};

// One run of `method` at `substeps` per frame over the measured interval.
Run simulate(const Model& base, Integrator method, int substeps, const State& start, const FineSettings& s) {
  Model m = base;
  m.options.integrator = method;
  Workspace ws = make_workspace(m);
  ws.substeps = substeps;
  if (method != Integrator::SymplecticEuler) ws.integrator_scratch = make_integrator_scratch(m);
  State st = start;
  const int per_sample = s.frames / s.samples;
  Run r;
  for (int f = 0; f < s.frames && r.finite; ++f) {
    const double t0 = cpu_seconds();
    for (int q = 0; q < substeps && r.finite; ++q) {
      ++r.steps;
      r.finite = step(m, st, ws).finite;
      r.contacts = std::max(r.contacts, ws.last_contacts);
    }
    r.seconds += cpu_seconds() - t0;
    if (r.finite) r.max_strain = std::max(r.max_strain, max_strain(m, st.x));
    if ((f + 1) % per_sample == 0) r.x.push_back(st.x);
  }
  return r;
}

double relative_rms(const Run& a, const Run& b, double size) {
  double sum = 0.0, count = 0.0;
  for (std::size_t j = 0; j < a.x.size() && j < b.x.size(); ++j) {
    sum += (a.x[j] - b.x[j]).squaredNorm();
    count += static_cast<double>(a.x[j].cols());
  }
  return count > 0.0 ? std::sqrt(sum / count) / size : kNaN;
}

bool is_implicit(Integrator m) { return m == Integrator::ImplicitEuler || m == Integrator::FastMassSpring; }

// The substeps per frame of each run of `method`, largest step first, without repeats.
std::vector<int> sweep(Integrator method, const FineSettings& s, int n_se, int n_xpbd) {
  const std::vector<double>& factors = method == Integrator::XPBD ? s.xpbd_factors
                                       : is_implicit(method)      ? s.implicit_factors
                                                                  : s.explicit_factors;
  const int base = method == Integrator::XPBD || is_implicit(method) ? n_xpbd : n_se;
  std::vector<int> out;
  for (double f : factors) {
    const int n = std::max(1, static_cast<int>(std::lround(base / f)));
    if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
  }
  std::sort(out.begin(), out.end());
  return out;
}

FinePoint measure(const Model& model, Integrator method, int n, const Start& start, const Run& ref,
                  const FineResult& r, const FineSettings& s) {
  FinePoint p;
  p.method = method;
  p.substeps = n;
  p.h = r.frame / n;
  Run run = simulate(model, method, n, start.state, s);
  if (run.finite && run.seconds < kRepeatBelow)
    run.seconds = std::min(run.seconds, simulate(model, method, n, start.state, s).seconds);
  p.finite = run.finite;
  p.steps = run.steps;
  p.cpu_per_second = run.seconds / r.interval;
  p.max_strain = run.finite ? run.max_strain : kNaN;
  p.error = run.finite ? relative_rms(run, ref, r.size) : kNaN;
  if (!std::isfinite(p.error)) p.finite = false;
  return p;
}

FineRow summarise(Integrator method, const FineResult& r, const FineSettings& s) {
  FineRow row;
  row.method = method;
  row.strain_h = row.strain_cpu = row.strain_error = row.run_h = row.run_cpu = kNaN;
  std::vector<Point> curve;  // largest step first
  for (const FinePoint& p : r.points) {
    if (p.method != method) continue;
    if (p.finite && p.max_strain <= s.strain_cap && std::isnan(row.strain_h)) {
      row.strain_h = p.h;
      row.strain_cpu = p.cpu_per_second;
      row.strain_error = p.error;
    }
    // every finite run below the cloth's size (a blow-up); an error under the reference's own
    // difference is that floor, not resolved, but it is under the target all the same when
    // the target is above the floor (print_fine_summary says whether it is)
    if (p.finite && p.error <= s.error_target && !(p.cpu_per_second >= row.run_cpu)) {
      row.run_h = p.h;
      row.run_cpu = p.cpu_per_second;
    }
    if (p.finite && p.error <= 1.0) {
      Point q;
      q.method = method;
      q.dt = p.h;
      q.error = p.error;
      q.seconds = p.cpu_per_second;
      curve.push_back(q);
    }
  }
  std::vector<const Point*> pts;
  for (const Point& q : curve) pts.push_back(&q);
  row.target_cpu = time_to(pts, s.error_target, row.target_bound);
  return row;
}

}  // namespace

FineResult run_fine(const Model& model, const std::string& scene, const FineSettings& s, std::ostream& progress) {
  if (s.samples < 1 || s.frames < s.samples || s.frames % s.samples != 0)
    throw std::invalid_argument("fine study: the frames must be a whole number of samples");
  FineResult r;
  r.scene = scene;
  r.masses = model.mass_count();
  r.size = cloth_size(model);
  r.frame = model.options.dt;
  r.interval = s.frames * r.frame;
  const StabilityReport stab = analyse_stability(model);
  r.dt_stable = stab.dt_stable_symplectic;
  const int n_se = plan_substeps(r.frame, r.dt_stable, SubstepPolicy{}).substeps;
  const int n_xpbd = plan_substeps(r.frame, xpbd_step(model), SubstepPolicy{}).substeps;
  r.h_se = r.frame / n_se;
  r.h_xpbd = r.frame / n_xpbd;
  progress << "[" << scene << "] " << r.masses << " masses, " << model.spring_count() << " springs; "
           << "omega_max " << fmt(stab.omega_max) << " rad/s, symplectic Euler dt_stable " << fmt(r.dt_stable)
           << " s; planned steps: symplectic Euler " << fmt(r.h_se)
           << " s, xpbd " << fmt(r.h_xpbd) << " s\n[" << scene << "] the fall (" << to_string(model.options.integrator)
           << ") ..." << std::flush;
  const Start start = fall_to_contact(model, s.lead);
  r.first_contact = start.first_contact;
  r.start = start.state.t;
  const int n_ref = std::max(1, static_cast<int>(std::lround(n_se / s.ref_factor)));
  r.h_ref = r.frame / n_ref;
  progress << " first contact at " << fmt(r.first_contact) << " s; measured from " << fmt(r.start) << " s for "
           << fmt(r.interval) << " s\n[" << scene << "] reference: rk4 at h_ref " << fmt(r.h_ref)
           << " s and h_ref/2 ..." << std::flush;
  const Run ref = simulate(model, Integrator::RK4, n_ref, start.state, s);
  const Run ref2 = simulate(model, Integrator::RK4, 2 * n_ref, start.state, s);
  if (!ref.finite || !ref2.finite) throw std::runtime_error(scene + ": the reference solution is not finite");
  r.ref_check = relative_rms(ref, ref2, r.size);
  r.ref_contacts = ref2.contacts;
  progress << " done (" << fmt(ref.seconds + ref2.seconds) << " s), difference " << fmt(r.ref_check) << ", "
           << ref2.contacts << " points in contact at most\n";
  std::vector<Integrator> methods = s.methods;
  if (methods.empty()) methods.assign(all_integrators().begin(), all_integrators().end());
  for (Integrator m : methods)
    for (int n : sweep(m, s, n_se, n_xpbd)) {
      FinePoint p = measure(model, m, n, start, ref2, r, s);
      p.planned = n == (m == Integrator::SymplecticEuler ? n_se : m == Integrator::XPBD ? n_xpbd : -1);
      progress << "[" << scene << "] " << std::left << std::setw(17) << to_string(m) << " h " << std::setw(10)
               << fmt(p.h) << " error " << std::setw(10) << (p.finite ? fmt(p.error) : "not finite") << " strain "
               << std::setw(10) << fmt(p.max_strain) << " cpu/s " << fmt(p.cpu_per_second) << "\n"
               << std::flush;
      r.points.push_back(p);
    }
  r.se_cpu = r.speedup = r.speedup_run = kNaN;
  for (const FinePoint& p : r.points)
    if (p.planned && p.method == Integrator::SymplecticEuler) r.se_cpu = p.cpu_per_second;
  for (Integrator m : methods) {
    r.rows.push_back(summarise(m, r, s));
    if (m == Integrator::XPBD) {
      r.speedup = r.se_cpu / r.rows.back().target_cpu;
      r.speedup_run = r.se_cpu / r.rows.back().run_cpu;
    }
  }
  return r;
}

void print_fine_summary(const FineResult& r, const FineSettings& s, std::ostream& out) {
  out << "== " << r.scene << " (fine, stiff): " << r.masses << " masses, cloth size " << fmt(r.size)
      << " m, symplectic Euler dt_stable " << fmt(r.dt_stable) << " s, frame " << fmt(r.frame) << " s\n";
  out << "first contact (fall) at " << fmt(r.first_contact) << " s; measured interval " << fmt(r.start) << " to "
      << fmt(r.start + r.interval) << " s; reference rk4 h_ref " << fmt(r.h_ref) << " s vs h_ref/2 differ by "
      << fmt(r.ref_check) << ", the floor of the errors: the target " << fmt(s.error_target) << " is "
      << fmt(s.error_target / r.ref_check) << "x above it"
      << (s.error_target >= 5.0 * r.ref_check ? "" : " (NOT resolved: under 5x)") << "\n";
  out << "cpu per simulated second (cpu/s); strain <= " << fmt(100.0 * s.strain_cap) << " %: the largest step whose "
      << "run stays at or below it\n";
  out << std::left << std::setw(18) << "method" << std::setw(12) << "h at strain" << std::setw(14)
      << "cpu/s there" << std::setw(12) << "its error" << std::setw(16)
      << "cpu/s to " + fmt(100.0 * s.error_target) + " %" << "cheapest run there (h, cpu/s)\n";
  for (const FineRow& row : r.rows)
    out << std::setw(18) << to_string(row.method) << std::setw(12) << fmt(row.strain_h) << std::setw(14)
        << (std::isnan(row.strain_cpu) ? std::string("none") : fmt(row.strain_cpu) + " s") << std::setw(12)
        << fmt(row.strain_error)
        << std::setw(16)
        << (std::isnan(row.target_cpu) ? std::string("not reached")
                                       : (row.target_bound ? "<= " : "") + fmt(row.target_cpu) + " s")
        << (std::isnan(row.run_h) ? std::string("none") : fmt(row.run_h) + " s, " + fmt(row.run_cpu) + " s") << "\n";
  out << "target: xpbd to " << fmt(100.0 * s.error_target) << " % against symplectic Euler at its planned step (h "
      << fmt(r.h_se) << " s, " << fmt(r.se_cpu) << " cpu/s): ";
  if (std::isnan(r.speedup)) {
    out << "xpbd does not reach it -> NOT met (>= 10x)\n";
    return;
  }
  out << fmt(r.speedup) << "x cheaper (interpolated), " << fmt(r.speedup_run)
      << "x at its cheapest run at or below it -> " << (r.speedup >= 10.0 && r.speedup_run >= 10.0 ? "met" : "NOT met")
      << " (>= 10x in both)\n";
}

void write_fine_csv(const FineResult& r, const std::string& dir) {
  std::ostringstream o;
  o << "method,substeps,h,planned,finite,error,cpu_per_second,max_strain,steps\n" << std::setprecision(9);
  for (const FinePoint& p : r.points)
    o << to_string(p.method) << "," << p.substeps << "," << p.h << "," << (p.planned ? 1 : 0) << ","
      << (p.finite ? 1 : 0) << "," << p.error << "," << p.cpu_per_second << "," << p.max_strain << "," << p.steps
      << "\n";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create directory '" + dir + "': " + ec.message());
  const std::string path = (std::filesystem::path(dir) / (r.scene + ".csv")).string();
  if (const std::string err = io::write_output_file(path, o.str()); !err.empty()) throw std::runtime_error(err);
}

}  // namespace clothsim::wp
