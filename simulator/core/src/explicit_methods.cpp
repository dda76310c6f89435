// The explicit integrators of the work-precision study: explicit Euler, explicit midpoint,
// classic Runge-Kutta and leapfrog (Verlet). Each calls the force stage per evaluation.
#include "integrator_scratch.hpp"
#include "stages.hpp"

namespace clothsim::detail {

void explicit_euler(const Model& m, State& s, Workspace& ws, double h) {
  compute_forces(m, s.x, s.v, ws.f, ws);
  s.x.noalias() += h * s.v;
  s.v.noalias() += h * accel(m, ws.f);
}

void midpoint(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.xs.noalias() = s.x + (0.5 * h) * s.v;
  sc.vs.noalias() = s.v + (0.5 * h) * accel(m, ws.f);
  compute_forces(m, sc.xs, sc.vs, ws.f, ws);
  s.x.noalias() += h * sc.vs;
  s.v.noalias() += h * accel(m, ws.f);
}

void rk4(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  // Stage i: position slope = the stage's velocity vs, velocity slope = a(xs, vs).
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.acc_x = s.v;
  sc.acc_v.noalias() = accel(m, ws.f);
  sc.xs.noalias() = s.x + (0.5 * h) * s.v;
  sc.vs.noalias() = s.v + (0.5 * h) * sc.acc_v;  // acc_v == k1 here
  for (int stage = 2; stage <= 4; ++stage) {
    compute_forces(m, sc.xs, sc.vs, ws.f, ws);
    const double w = stage == 4 ? 1.0 : 2.0;
    sc.acc_x.noalias() += w * sc.vs;
    sc.f2.noalias() = accel(m, ws.f);  // k_stage of v
    sc.acc_v.noalias() += w * sc.f2;
    if (stage < 4) {
      const double c = stage == 2 ? 0.5 * h : h;
      sc.xs.noalias() = s.x + c * sc.vs;
      sc.vs.noalias() = s.v + c * sc.f2;
    }
  }
  s.x.noalias() += (h / 6.0) * sc.acc_x;
  s.v.noalias() += (h / 6.0) * sc.acc_v;
}

void verlet(const Model& m, State& s, Workspace& ws, double h) {
  // Drift-kick-drift. The force stage's damping -gamma v is evaluated at v(t); replacing it by
  // the midpoint (v(t) + v(t+h))/2 keeps the method second order with damping:
  // v' = v + h/m (f(x_half, v) ) / (1 + h gamma / (2 m)).
  s.x.noalias() += (0.5 * h) * s.v;
  compute_forces(m, s.x, s.v, ws.f, ws);
  for (Eigen::Index i = 0; i < s.x.cols(); ++i) {
    const double im = m.inv_mass[i], g = m.damping_of(static_cast<std::size_t>(i));
    s.v.col(i) += (h * im / (1.0 + 0.5 * h * g * im)) * ws.f.col(i);
  }
  s.x.noalias() += (0.5 * h) * s.v;
}


}  // namespace clothsim::detail
