// The time integrators, chosen at run time (the list: CLOTHSIM_INTEGRATORS in options.hpp).
//
// step() calls one of them; every method calls the one force stage, compute_forces() of
// step.hpp (gravity, the damping of report eq. 6, springs, penalty contact, drag); the
// implicit ones add the spring Jacobian. Each has its own file in src/.
//
//   explicit-euler     x += h v(t); v += h a(x(t), v(t))             order 1, energy grows
//   symplectic-euler   the core's (report eqs. 1-7)                   order 1, symplectic
//   verlet             leapfrog drift-kick-drift, damping by implicit midpoint
//                                                                     order 2, symplectic, 1 force/step
//   midpoint           explicit midpoint (RK2)                        order 2, 2 forces/step
//   rk4                classic Runge-Kutta                            order 4, 4 forces/step
//   implicit-euler     Baraff & Witkin 1998: one Newton step, (M + h gamma + h^2 K) dv =
//                      h (f - h K v), matrix-free block-Jacobi CG; contact explicit
//   fast-mass-spring   Liu et al. 2013: implicit Euler by local/global iterations with a
//                      prefactored sparse Cholesky (rebuilt when dt or stiffness change)
//   xpbd               Macklin et al. 2016/2019: springs as compliant constraints (alpha = 1/k),
//                      one Gauss-Seidel pass per step: use it with small steps (substeps)
#pragma once

#include <clothsim/sim.hpp>

#include <memory>

namespace clothsim {

struct Workspace;

/// Scratch of the integrators other than symplectic Euler, sized once per Model.
/// Kept by the Workspace; the implicit solvers keep their factorization here.
struct IntegratorScratch;
std::shared_ptr<IntegratorScratch> make_integrator_scratch(const Model& model);

/// Tuning of the implicit solvers (defaults used by step()).
struct ImplicitSettings {
  double cg_tolerance = 1e-8;     ///< relative residual of the CG solve
  int cg_max_iterations = 500;
  int fms_iterations = 10;        ///< local/global iterations per step (Liu et al. use ~10)
};
void set_implicit_settings(IntegratorScratch& scratch, const ImplicitSettings& settings);

/// Statistics of the last implicit solve (for docs and tests).
struct ImplicitStats {
  int cg_iterations = 0;
  double cg_residual = 0.0;
  int factorizations = 0;  ///< times the fast mass-spring matrix was factored so far
};
ImplicitStats implicit_stats(const IntegratorScratch& scratch);

}  // namespace clothsim
