// Work-precision study; see workprecision.hpp and docs/work-precision.md.
#include <clothsim/integrators.hpp>
#include <clothsim/output_file.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>
#include <clothsim/workprecision.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace clothsim::wp {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Trajectory {
  std::vector<Eigen::Matrix3Xd> x;  ///< positions at the sample times
  bool finite = true;
  long steps = 0;
  double seconds = 0.0;
  double first_contact = -1.0;  ///< s, first step with a point in a collider band; -1: none
};

// One run of `method` at `dt` to the horizon; positions kept at the sample times.
Trajectory simulate(const Model& base, Integrator method, double dt, const Settings& s) {
  Model m = base;
  m.options.integrator = method;
  m.options.dt = dt;
  const long per_sample = std::lround(s.horizon / s.samples / dt);
  if (std::abs(static_cast<double>(per_sample) * dt * s.samples - s.horizon) > 1e-9 * s.horizon)
    throw std::logic_error("work-precision: dt does not divide the sample interval");
  Trajectory tr;
  tr.x.assign(static_cast<std::size_t>(s.samples), Eigen::Matrix3Xd());
  State st = make_state(m);
  Workspace ws = make_workspace(m);
  const double t0 = cpu_seconds();
  for (int j = 0; j < s.samples && tr.finite; ++j) {
    for (long i = 0; i < per_sample; ++i) {
      ++tr.steps;
      if (!step(m, st, ws).finite) {
        tr.finite = false;
        break;
      }
      if (tr.first_contact < 0.0 && ws.last_contacts > 0) tr.first_contact = st.t;
    }
    tr.x[static_cast<std::size_t>(j)] = st.x;
  }
  tr.seconds = cpu_seconds() - t0;
  return tr;
}

double rms_error(const Trajectory& a, const Trajectory& b, double size) {
  double sum = 0.0;
  double count = 0.0;
  for (std::size_t j = 0; j < a.x.size(); ++j) {
    sum += (a.x[j] - b.x[j]).squaredNorm();
    count += static_cast<double>(a.x[j].cols());
  }
  return std::sqrt(sum / count) / size;
}

std::string fmt(double v, int prec = 3) {
  if (std::isnan(v)) return "-";
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

}  // namespace

double cloth_size(const Model& m) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (Eigen::Index i = 0; i < m.x0.cols(); ++i) {
    lo = lo.cwiseMin(m.x0.col(i));
    hi = hi.cwiseMax(m.x0.col(i));
  }
  return (hi - lo).norm();
}

double time_to(const std::vector<const Point*>& pts, double target, bool& bound) {
  bound = false;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    bool stays = true;
    for (std::size_t j = i; j < pts.size(); ++j) stays = stays && pts[j]->error <= target;
    if (!stays) continue;
    if (i == 0) {
      bound = true;
      return pts[i]->seconds;
    }
    const Point& a = *pts[i - 1];
    const Point& b = *pts[i];
    const double u = (std::log(target) - std::log(a.error)) / (std::log(b.error) - std::log(a.error));
    return std::exp(std::log(a.seconds) + u * (std::log(b.seconds) - std::log(a.seconds)));
  }
  return kNaN;
}

Result run(const Model& model, const std::string& scene, const Settings& s, std::ostream& progress) {
  Result r;
  r.scene = scene;
  r.size = cloth_size(model);
  const StabilityReport stab = analyse_stability(model);
  r.dt_stable = stab.dt_stable_symplectic;
  progress << "[" << scene << "] " << model.mass_count() << " masses, " << model.spring_count()
           << " springs; omega_max " << fmt(stab.omega_max) << " rad/s (springs " << fmt(stab.omega_springs)
           << ", contact " << fmt(stab.omega_contact) << ") -> symplectic Euler dt_stable " << fmt(r.dt_stable) << " s\n";
  const double dt_top = s.top_factor * r.dt_stable;
  const double dt_min = dt_top / std::pow(2.0, s.levels - 1);
  // The implicit methods start at dt_top * 2^j, as high as implicit_top_factor allows while
  // a sample interval still holds a whole step. Every dt must land exactly on the sample
  // times: the horizon is a whole number of dt_top_implicit * samples.
  Settings st = s;
  double dt_top_implicit = dt_top;
  while (2.0 * dt_top_implicit <= s.implicit_top_factor * r.dt_stable * (1 + 1e-9) &&
         2.0 * dt_top_implicit * s.samples <= s.horizon * (1 + 1e-9))
    dt_top_implicit *= 2.0;
  const double unit = dt_top_implicit * s.samples;
  st.horizon = std::max(1.0, std::round(s.horizon / unit)) * unit;
  r.horizon = st.horizon;

  r.h_ref = dt_min / s.ref_refine;
  progress << "[" << scene << "] reference: rk4 at h_ref " << fmt(r.h_ref) << " s and h_ref/2 over "
           << fmt(st.horizon) << " s ..." << std::flush;
  const Trajectory ref = simulate(model, Integrator::RK4, r.h_ref, st);
  const Trajectory ref2 = simulate(model, Integrator::RK4, r.h_ref / 2, st);
  if (!ref.finite || !ref2.finite) throw std::runtime_error(scene + ": the reference solution is not finite");
  r.ref_check = rms_error(ref, ref2, r.size);
  r.first_contact = ref.first_contact;
  progress << " done (" << fmt(ref.seconds + ref2.seconds) << " s), difference " << fmt(r.ref_check) << "\n";

  std::vector<Integrator> methods = s.methods;
  if (methods.empty()) methods.assign(all_integrators().begin(), all_integrators().end());
  const std::size_t total = methods.size() * static_cast<std::size_t>(s.levels);
  std::size_t done = 0;
  for (Integrator m : methods) {
    for (int k = 0; k < s.levels; ++k) {
      Point p;
      p.method = m;
      const bool implicit = m == Integrator::ImplicitEuler || m == Integrator::FastMassSpring ||
                            m == Integrator::XPBD;
      p.dt = (implicit ? dt_top_implicit : dt_top) / std::pow(2.0, k);
      Trajectory warm = simulate(model, m, p.dt, st);  // warm-up; also gives the error
      p.finite = warm.finite;
      p.steps = warm.steps;
      p.seconds = warm.seconds;
      if (p.finite) {
        p.error = rms_error(warm, ref, r.size);
        p.finite = std::isfinite(p.error);
        const int reps = warm.seconds > 2.0 ? 1 : s.repeats;
        for (int i = 0; i < reps && p.finite; ++i)
          p.seconds = std::min(p.seconds, simulate(model, m, p.dt, st).seconds);
        if (!p.finite) p.error = kNaN;
      } else {
        p.error = kNaN;
      }
      // shown: above the reference's accuracy, below 100 % of the cloth's size (a blow-up)
      p.resolved = p.finite && p.error >= 10.0 * r.ref_check && p.error <= 1.0;
      r.points.push_back(p);
      ++done;
      progress << "[" << scene << " " << done << "/" << total << "] " << std::left << std::setw(17)
               << to_string(m) << " dt " << std::setw(10) << fmt(p.dt) << " error "
               << std::setw(10) << (p.finite ? fmt(p.error) : "not finite") << " cpu "
               << fmt(p.seconds) << " s"
               << (p.finite && !p.resolved ? (p.error > 1.0 ? " (blew up)" : " (below reference)") : "")
               << "\n"
               << std::flush;
    }
  }
  // symplectic Euler at its largest stable dt (the largest <= 0.95 dt_stable that lands on the
  // sample times): the baseline of the target
  {
    const double interval = st.horizon / st.samples;
    const double dt_se = interval / std::ceil(interval / (0.95 * r.dt_stable));
    r.se_limit_dt = dt_se;
    Trajectory t = simulate(model, Integrator::SymplecticEuler, dt_se, st);
    r.se_limit_error = t.finite ? rms_error(t, ref, r.size) : kNaN;
    r.se_limit_seconds = t.seconds;
    for (int i = 0; i < s.repeats && t.finite; ++i)
      r.se_limit_seconds = std::min(r.se_limit_seconds,
                                    simulate(model, Integrator::SymplecticEuler, dt_se, st).seconds);
  }
  r.smallest_error = kNaN;
  for (const Point& p : r.points)
    if (p.resolved && (std::isnan(r.smallest_error) || p.error < r.smallest_error)) r.smallest_error = p.error;

  double best = kNaN;
  for (Integrator m : methods) {
    std::vector<const Point*> pts;
    for (const Point& p : r.points)
      if (p.method == m && p.resolved) pts.push_back(&p);
    MethodSummary ms;
    ms.method = m;
    double sum = 0.0;
    int n = 0;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i)
      if (pts[i]->error < 0.3) {  // beyond ~30 % the run is not in its asymptotic regime
        sum += std::log2(pts[i]->error / pts[i + 1]->error);
        ++n;
      }
    ms.order = n > 0 ? sum / n : kNaN;
    ms.time_1pc = time_to(pts, 1e-2, ms.bound_1pc);
    ms.time_01pc = time_to(pts, 1e-3, ms.bound_01pc);
    ms.time_1e4 = time_to(pts, 1e-4, ms.bound_1e4);
    if (!std::isnan(ms.time_1pc) && (std::isnan(best) || ms.time_1pc < best)) {
      best = ms.time_1pc;
      r.best_1pc = m;
    }
    r.summary.push_back(ms);
  }
  r.speedup_1pc = std::isnan(best) ? kNaN : r.se_limit_seconds / best;
  // at a tighter error, equal error for both: symplectic Euler's own curve vs the best other
  double se = kNaN, other = kNaN;
  for (const MethodSummary& ms : r.summary) {
    if (std::isnan(ms.time_1e4)) continue;
    if (ms.method == Integrator::SymplecticEuler) {
      se = ms.time_1e4;
    } else if (std::isnan(other) || ms.time_1e4 < other) {
      other = ms.time_1e4;
      r.best_1e4 = ms.method;
    }
  }
  r.speedup_1e4 = se / other;
  return r;
}

void print_summary(const Result& r, std::ostream& out) {
  out << "== " << r.scene << ": cloth size " << fmt(r.size) << " m, horizon " << fmt(r.horizon)
      << " s, symplectic Euler dt_stable " << fmt(r.dt_stable) << " s\n";
  if (r.first_contact >= 0.0) out << "first contact (reference run) at t = " << fmt(r.first_contact) << " s\n";
  out << "reference check: rk4 h_ref " << fmt(r.h_ref) << " s vs h_ref/2 differ by " << fmt(r.ref_check)
      << "; smallest error shown " << fmt(r.smallest_error) << " -> "
      << (r.ref_check < 0.1 * r.smallest_error ? "OK (< 1/10)" : "NOT OK (>= 1/10)") << "\n";
  out << std::left << std::setw(18) << "method" << std::setw(10) << "order" << std::setw(16)
      << "cpu to 1 %" << std::setw(16) << "cpu to 0.1 %" << "cpu to 1e-4\n";
  for (const MethodSummary& m : r.summary)
    out << std::setw(18) << to_string(m.method) << std::setw(10) << fmt(m.order, 3) << std::setw(16)
        << (std::isnan(m.time_1pc) ? std::string("not reached")
                                   : (m.bound_1pc ? "<= " : "") + fmt(m.time_1pc) + " s")
        << std::setw(16)
        << (std::isnan(m.time_01pc) ? std::string("not reached")
                                    : (m.bound_01pc ? "<= " : "") + fmt(m.time_01pc) + " s")
        << (std::isnan(m.time_1e4) ? std::string("not reached")
                                   : (m.bound_1e4 ? "<= " : "") + fmt(m.time_1e4) + " s")
        << "\n";
  out << "symplectic Euler at its limit (dt " << fmt(r.se_limit_dt) << " s): error " << fmt(r.se_limit_error) << ", cpu "
      << fmt(r.se_limit_seconds) << " s\n";
  if (std::isnan(r.speedup_1pc))
    out << "target (best method at 1 % >= 10x faster than symplectic Euler at its limit): no method reached 1 %\n";
  else if (r.best_1pc == Integrator::SymplecticEuler)
    // (its own cheapest run to 1 % against its run at the limit: no comparison of methods)
    out << "target: no method reaches 1 % in less cpu than symplectic Euler itself (its cheapest run there takes "
        << fmt(1.0 / r.speedup_1pc) << "x the cpu of its run at the limit) -> NOT met (>= 10x)\n";
  else
    out << "target: best at 1 % is " << to_string(r.best_1pc) << ", a speed-up of " << fmt(r.speedup_1pc)
        << "x over symplectic Euler at its limit (that cpu time over this one's) -> "
        << (r.speedup_1pc >= 10.0 ? "met" : "NOT met") << " (>= 10x)\n";
  if (!std::isnan(r.speedup_1e4))
    out << "at equal error 1e-4: best is " << to_string(r.best_1e4) << ", a speed-up of " << fmt(r.speedup_1e4)
        << "x over symplectic Euler\n";
}

namespace {

// By the output rule (clothsim/output_file.hpp): a regular file through a temporary file and a
// rename, a device in place, a directory refused; any failure throws, naming the file.
void write_output(const std::filesystem::path& path, const std::string& text) {
  if (const std::string err = io::write_output_file(path.string(), text); !err.empty())
    throw std::runtime_error(err);
}

std::string csv(const Result& r) {
  std::ostringstream o;
  o << "method,dt,error,seconds,steps,finite\n";
  o << std::setprecision(9);
  for (const Point& p : r.points)
    o << to_string(p.method) << "," << p.dt << "," << (p.finite ? p.error : kNaN) << "," << p.seconds << ","
      << p.steps << "," << (p.finite ? 1 : 0) << "\n";
  return o.str();
}

// A log-log plot, x = error, y = CPU seconds, one polyline per method.
std::string svg(const Result& r) {
  const double W = 820, H = 560, L = 80, R = 200, T = 40, B = 60;
  double emin = 1e300, emax = 0, smin = 1e300, smax = 0;
  for (const Point& p : r.points)
    if (p.resolved) {
      emin = std::min(emin, p.error);
      emax = std::max(emax, p.error);
      smin = std::min(smin, p.seconds);
      smax = std::max(smax, p.seconds);
    }
  if (emax <= 0) emin = 1e-4, emax = 1, smin = 1e-3, smax = 1;
  const double ex0 = std::floor(std::log10(std::min(emin, 1e-3))), ex1 = std::ceil(std::log10(emax));
  const double sy0 = std::floor(std::log10(smin)), sy1 = std::ceil(std::log10(smax));
  auto X = [&](double e) { return L + (std::log10(e) - ex0) / std::max(ex1 - ex0, 1.0) * (W - L - R); };
  auto Y = [&](double s) { return H - B - (std::log10(s) - sy0) / std::max(sy1 - sy0, 1.0) * (H - T - B); };
  static const char* colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
  std::ostringstream o;
  o << std::fixed << std::setprecision(1);
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << L << "\" y=\"24\" font-size=\"15\">work-precision: " << r.scene
    << " (RMS position error / cloth size vs CPU time)</text>\n";
  for (double e = ex0; e <= ex1; e += 1) {
    o << "<line x1=\"" << X(std::pow(10, e)) << "\" y1=\"" << T << "\" x2=\"" << X(std::pow(10, e)) << "\" y2=\""
      << H - B << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << X(std::pow(10, e)) << "\" y=\"" << H - B + 18 << "\" text-anchor=\"middle\">1e"
      << static_cast<int>(e) << "</text>\n";
  }
  for (double sy = sy0; sy <= sy1; sy += 1) {
    o << "<line x1=\"" << L << "\" y1=\"" << Y(std::pow(10, sy)) << "\" x2=\"" << W - R << "\" y2=\""
      << Y(std::pow(10, sy)) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << L - 6 << "\" y=\"" << Y(std::pow(10, sy)) + 4 << "\" text-anchor=\"end\">1e"
      << static_cast<int>(sy) << " s</text>\n";
  }
  for (double target : {1e-2, 1e-3})
    if (target >= std::pow(10, ex0) && target <= std::pow(10, ex1))
      o << "<line x1=\"" << X(target) << "\" y1=\"" << T << "\" x2=\"" << X(target) << "\" y2=\"" << H - B
        << "\" stroke=\"#888\" stroke-dasharray=\"5,4\"/>\n";
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << W - L - R << "\" height=\"" << H - T - B
    << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << (L + W - R) / 2 << "\" y=\"" << H - 20
    << "\" text-anchor=\"middle\">error (RMS over masses and sample times, / cloth size)</text>\n";
  o << "<text transform=\"translate(20," << (T + H - B) / 2
    << ") rotate(-90)\" text-anchor=\"middle\">CPU time of the run, s</text>\n";
  int ci = 0, legend = 0;
  for (Integrator m : all_integrators()) {
    std::vector<const Point*> pts;
    for (const Point& p : r.points)
      if (p.method == m && p.resolved) pts.push_back(&p);
    const char* c = colors[ci++ % 8];
    if (pts.empty()) continue;
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"2\" points=\"";
    for (const Point* p : pts) o << X(p->error) << "," << Y(p->seconds) << " ";
    o << "\"/>\n";
    for (const Point* p : pts)
      o << "<circle cx=\"" << X(p->error) << "\" cy=\"" << Y(p->seconds) << "\" r=\"3.5\" fill=\"" << c << "\"/>\n";
    const double ly = T + 16 + 20 * legend++;
    o << "<line x1=\"" << W - R + 14 << "\" y1=\"" << ly - 4 << "\" x2=\"" << W - R + 40 << "\" y2=\"" << ly - 4
      << "\" stroke=\"" << c << "\" stroke-width=\"3\"/><text x=\"" << W - R + 46 << "\" y=\"" << ly << "\">"
      << to_string(m) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace

std::string check_outputs(const std::string& dir, const std::string& scene) {
  if (std::string why = io::check_output_dir(dir); !why.empty()) return why;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return {};  // created by write_outputs
  for (const char* ext : {".csv", ".svg"})
    if (std::string why = io::check_output_file((std::filesystem::path(dir) / (scene + ext)).string()); !why.empty())
      return why;
  return {};
}

void write_outputs(const Result& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create directory '" + dir + "': " + ec.message());
  write_output(std::filesystem::path(dir) / (r.scene + ".csv"), csv(r));
  write_output(std::filesystem::path(dir) / (r.scene + ".svg"), svg(r));
}

}  // namespace clothsim::wp
