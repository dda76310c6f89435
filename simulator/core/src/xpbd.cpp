// XPBD (Macklin, Mueller, Chentanez 2016; "Small Steps", Macklin et al. 2019): springs as
// compliant distance constraints, one Gauss-Seidel pass per step.
#include "integrator_scratch.hpp"
#include "stages.hpp"

namespace clothsim::detail {

void xpbd(const Model& m, State& s, Workspace& ws, double h) {
  IntegratorScratch& sc = *ws.integrator_scratch;
  // Predict with every force but the springs (gravity, damping, contact, drag: explicit),
  // then one Gauss-Seidel pass of compliant distance constraints, alpha = 1/k; lambda starts
  // at 0 every step (one iteration per small step, as "Small Steps" recommends).
  compute_forces(m, s.x, s.v, ws.f, ws);
  sc.f2.setZero();
  add_spring_forces(m, s.x, sc.f2);
  sc.fext = ws.f - sc.f2;
  sc.xs = s.x;  // x(t)
  s.v.noalias() += h * accel(m, sc.fext);
  s.x.noalias() += h * s.v;
  const double inv_h2 = 1.0 / (h * h);
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const auto a = m.spring_a[k], b = m.spring_b[k];
    const double wa = m.inv_mass[a], wb = m.inv_mass[b];
    const double ks = m.spring_stiffness(k);
    if (ks <= 0.0 || wa + wb == 0.0) continue;
    const Eigen::Vector3d e = s.x.col(a) - s.x.col(b);
    const double len = e.norm();
    if (len == 0.0) continue;  // no direction: no correction (as the force stage)
    const double c = len - m.rest_length0[static_cast<Eigen::Index>(k)];
    const double dlambda = -c / (wa + wb + inv_h2 / ks);
    const Eigen::Vector3d corr = (dlambda / len) * e;
    s.x.col(a) += wa * corr;
    s.x.col(b) -= wb * corr;
  }
  s.v = (s.x - sc.xs) / h;
}


}  // namespace clothsim::detail
