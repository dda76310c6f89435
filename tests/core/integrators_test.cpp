// The integrators against their theory: names, pins, order of convergence
// (hard case 11), energy behaviour, stability limits of the linear test equation.
#include <clothsim/integrators.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {

Model hanging_grid(Integrator m, double dt, int w = 6, int h = 6) {
  Options o = seed_options();
  o.dt = dt;
  o.integrator = m;
  // pin the two corners of the first row
  return test::grid_model(o, w, h, {0u, static_cast<std::uint32_t>(w - 1)});
}

State run(const Model& model, double t_end) {
  State s = make_state(model);
  Workspace ws = make_workspace(model);
  const auto n = static_cast<long>(std::llround(t_end / model.options.dt));
  for (long i = 0; i < n; ++i)
    if (!step(model, s, ws).finite) break;
  return s;
}

TEST(Integrators, NamesRoundTrip) {
  for (Integrator m : all_integrators()) {
    const auto parsed = parse_integrator(to_string(m));
    ASSERT_TRUE(parsed.has_value()) << to_string(m);
    EXPECT_EQ(*parsed, m);
  }
  EXPECT_EQ(parse_integrator("leapfrog"), Integrator::Verlet);
  EXPECT_EQ(parse_integrator("liu"), Integrator::FastMassSpring);
  EXPECT_FALSE(parse_integrator("rk5").has_value());
  EXPECT_NE(integrator_names().find("fast-mass-spring"), std::string::npos);
}

TEST(Integrators, EveryMethodRunsFiniteAndKeepsPinsBitIdentical) {
  for (Integrator m : all_integrators()) {
    // explicit Euler needs a small step (its region misses the imaginary axis)
    const Model model = hanging_grid(m, m == Integrator::ExplicitEuler ? 1e-4 : 0.005);
    const State s = run(model, 0.2);
    EXPECT_TRUE(s.x.allFinite() && s.v.allFinite()) << to_string(m);
    for (std::size_t i = 0; i < model.mass_count(); ++i)
      if (model.pinned[i]) {
        const auto c = static_cast<Eigen::Index>(i);
        EXPECT_EQ(std::memcmp(s.x.col(c).data(), model.x0.col(c).data(), 3 * sizeof(double)), 0)
            << to_string(m) << " moved pin " << i;
      }
    // the cloth fell: the free corner is lower than at the start
    const auto last = static_cast<Eigen::Index>(model.mass_count() - 1);
    EXPECT_LT(s.x(1, last), model.x0(1, last) - 0.01) << to_string(m);
  }
}

// Final-position error of a run against a reference, RMS over masses.
double rms_error(const State& a, const State& b) {
  return std::sqrt((a.x - b.x).squaredNorm() / static_cast<double>(a.x.cols()));
}

// Hard case 11: convergence order on a small undamped nonlinear system (a 3x3 hanging
// net), dt halved four times, reference RK4 at a far smaller step.
double measured_order(Integrator m, double dt0, double t_end) {
  Options o = seed_options();
  o.damping = 0.0;
  o.k_struct = 40.0;
  o.k_bend = 5.0;
  o.integrator = Integrator::RK4;
  o.dt = 1.0 / 40000.0;  // RK4 error ~ (h omega)^4 ~ 1e-12: far below every run's
  Model ref_model = test::grid_model(o, 3, 3, {0u, 2u});
  const State ref = run(ref_model, t_end);
  double sum = 0.0;
  double prev = 0.0;
  for (int k = 0; k < 4; ++k) {
    Model model = ref_model;
    model.options.integrator = m;
    model.options.dt = dt0 / std::pow(2.0, k);
    const double e = rms_error(run(model, t_end), ref);
    if (std::getenv("CLOTHSIM_VERBOSE")) std::printf("%s dt %g error %g\n", to_string(m), model.options.dt, e);
    if (k > 0) sum += std::log2(prev / e);
    prev = e;
  }
  return sum / 3.0;
}

TEST(HardCase11, ConvergenceOrder) {
  EXPECT_NEAR(measured_order(Integrator::SymplecticEuler, 0.01, 1.0), 1.0, 0.1);
  EXPECT_NEAR(measured_order(Integrator::ExplicitEuler, 2e-4, 1.0), 1.0, 0.1);
  EXPECT_NEAR(measured_order(Integrator::Verlet, 0.01, 1.0), 2.0, 0.1);
  EXPECT_NEAR(measured_order(Integrator::Midpoint, 0.01, 1.0), 2.0, 0.1);
  EXPECT_NEAR(measured_order(Integrator::RK4, 0.02, 1.0), 4.0, 0.3);
  EXPECT_NEAR(measured_order(Integrator::ImplicitEuler, 2.5e-4, 1.0), 1.0, 0.1);
  EXPECT_NEAR(measured_order(Integrator::XPBD, 2.5e-4, 1.0), 1.0, 0.1);
}

TEST(Integrators, StableDtMatchesTheory) {
  const double w = 100.0;
  EXPECT_NEAR(stable_dt(Integrator::SymplecticEuler, w) * w, 2.0, 1e-9);
  EXPECT_NEAR(stable_dt(Integrator::Verlet, w) * w, 2.0, 1e-9);
  EXPECT_NEAR(stable_dt(Integrator::RK4, w) * w, 2.0 * std::sqrt(2.0), 1e-6);
  EXPECT_EQ(stable_dt(Integrator::ExplicitEuler, w), 0.0);  // undamped: never stable
  const double zeta = 0.5;  // damped explicit Euler: |1 + h lambda|^2 = 1 - 2 h zeta + h^2 w^2 <= 1
  EXPECT_NEAR(stable_dt(Integrator::ExplicitEuler, w, zeta), 2 * zeta / (w * w), 1e-9);
  EXPECT_TRUE(std::isinf(stable_dt(Integrator::ImplicitEuler, w, zeta)));
}

// Damping far above omega (--mass 1e-45 with damping 0.1: zeta 5e43 1/s, omega 1.6e24 rad/s):
// the explicitly damped method is stable for h zeta below about 1, so a tiny dt_stable is
// found (not 0, which would read "unstable at every step size (no damping)"); XPBD damps
// implicitly and is stable at any step.
TEST(Integrators, StableDtWithDampingFarAboveOmegaIsTinyNotZero) {
  const double w = 1.6e24, zeta = 5e43;
  EXPECT_TRUE(std::isinf(stable_dt(Integrator::XPBD, w, zeta)));
  for (Integrator m : {Integrator::SymplecticEuler}) {
    const double h = stable_dt(m, w, zeta);
    EXPECT_GT(h, 0.0) << to_string(m);
    EXPECT_LT(h * zeta, 2.0) << to_string(m);
    EXPECT_GT(h * zeta, 0.1) << to_string(m);
  }
  EXPECT_TRUE(std::isinf(stable_dt(Integrator::ImplicitEuler, w, zeta)));
  // overflowed inputs have no usable step (and do not loop)
  EXPECT_EQ(stable_dt(Integrator::ImplicitEuler, std::numeric_limits<double>::infinity(), 0.5), 0.0);
  EXPECT_EQ(stable_dt(Integrator::XPBD, 100.0, std::numeric_limits<double>::infinity()), 0.0);
}

TEST(Integrators, NeverStableReasonSaysWhy) {
  StabilityReport r;
  r.omega_max = 100.0;
  r.zeta = 0.0;
  EXPECT_NE(never_stable_reason(r, Integrator::ExplicitEuler).find("none (damping 0)"), std::string::npos);
  r.zeta = 1e-3;
  const std::string weak = never_stable_reason(r, Integrator::ExplicitEuler);
  EXPECT_EQ(weak.find("no damping"), std::string::npos) << weak;
  EXPECT_NE(weak.find("little"), std::string::npos) << weak;
  r.omega_max = std::numeric_limits<double>::infinity();
  EXPECT_NE(never_stable_reason(r, Integrator::XPBD).find("too light"), std::string::npos);
}

TEST(Integrators, FastMassSpringFactorsOnceAndApproachesImplicitEuler) {
  Model a = hanging_grid(Integrator::FastMassSpring, 0.01);
  Model b = hanging_grid(Integrator::ImplicitEuler, 0.01);
  State sa = make_state(a), sb = make_state(b);
  Workspace wa = make_workspace(a), wb = make_workspace(b);
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(step(a, sa, wa).finite);
    ASSERT_TRUE(step(b, sb, wb).finite);
  }
  EXPECT_EQ(implicit_stats(*wa.integrator_scratch).factorizations, 1);
  EXPECT_GT(implicit_stats(*wb.integrator_scratch).cg_iterations, 0);
  // both are implicit Euler (one Newton step vs ten local/global iterations): close, not equal
  EXPECT_LT(rms_error(sa, sb), 0.01);
  // a new dt refactors
  a.options.dt = 0.005;
  step(a, sa, wa);
  EXPECT_EQ(implicit_stats(*wa.integrator_scratch).factorizations, 2);
}

TEST(Integrators, ImplicitMethodsStableFarAboveTheExplicitLimit) {
  for (Integrator m : {Integrator::ImplicitEuler, Integrator::FastMassSpring}) {
    Model model = hanging_grid(m, 0.01);
    const double limit = analyse_stability(model).dt_stable_symplectic;
    model.options.dt = 10.0 * limit;
    const State s = run(model, 2.0);
    ASSERT_TRUE(s.x.allFinite()) << to_string(m);
    // no energy blow-up: every mass within the cloth's reach of the pins
    EXPECT_LT((s.x.colwise() - model.x0.col(0)).colwise().norm().maxCoeff(), 3.0) << to_string(m);
  }
}

}  // namespace
}  // namespace clothsim
