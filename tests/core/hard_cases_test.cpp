// The hard cases of docs/stability.md. Each test asserts what the theory says; hard case 11
// (convergence order) is in integrators_test.cpp.
#include <clothsim/collision.hpp>
#include <clothsim/integrators.hpp>
#include <clothsim/model_builder.hpp>
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {


// A floor at y = 0, 20 x 20 m, normal +y; optionally a degenerate (collinear) triangle.
std::shared_ptr<const ColliderSet> floor_collider(bool with_degenerate = false) {
  auto set = std::make_shared<ColliderSet>();
  Eigen::Matrix3Xd v(3, 4);
  v << -10, 10, 10, -10, 0, 0, 0, 0, -10, -10, 10, 10;
  const std::vector<std::uint32_t> idx = {0, 3, 2, 0, 2, 1};
  set->add_object("floor", v, idx);
  if (with_degenerate) {
    Eigen::Matrix3Xd d(3, 3);
    d << 0.0, 0.1, 0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0;  // collinear, on the floor
    const std::vector<std::uint32_t> di = {0, 1, 2};
    set->add_object("sliver", d, di);
  }
  set->build();
  return set;
}

// One free mass at height y0 above the floor.
Model point_over_floor(const Options& o, double y0, bool with_degenerate = false) {
  ModelBuilder b(o, "point");
  Eigen::Matrix3Xd x(3, 1);
  x << 0.05, y0, 0.0;
  b.add_cloth(x, {}, {});
  b.set_colliders(floor_collider(with_degenerate));
  return b.build();
}

// --- 1: symplectic Euler blows up at 2 / omega_max, omega_max ~ sqrt(k) ------------------

bool blows_up(const Model& base, double dt) {
  Model m = base;
  m.options.dt = dt;
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  std::uint64_t seed = 12345;
  for (Eigen::Index i = 0; i < s.v.size(); ++i) {  // tiny random kick: every mode excited
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    s.v.data()[i] = 1e-6 * (static_cast<double>(seed >> 11) * 0x1.0p-53 - 0.5);
  }
  for (int i = 0; i < 3000; ++i) {
    if (!step(m, s, ws).finite) return true;
    if ((s.x - m.x0).cwiseAbs().maxCoeff() > 1e-2) return true;
  }
  return false;
}

TEST(HardCase01, SymplecticEulerBlowUpAtTwoOverOmegaScalesAsInverseSqrtK) {
  std::vector<double> lk, ldt;
  for (double k : {1e2, 1e3, 1e4, 1e5}) {
    Options o = seed_options();
    o.gravity_x = o.gravity_y = o.gravity_z = 0.0;
    o.damping = 0.0;
    o.k_struct = k;
    o.k_bend = k / 8.0;
    const Model m = test::grid_model(o, 6, 6);
    const double omega = omega_max_lanczos(m).omega;
    const double limit = 2.0 / omega;
    EXPECT_LE(omega, omega_max_bound(m, false) * (1 + 1e-12));
    double lo = 0.8 * limit, hi = 1.2 * limit;
    ASSERT_FALSE(blows_up(m, lo)) << "k " << k;
    ASSERT_TRUE(blows_up(m, hi)) << "k " << k;
    for (int i = 0; i < 14; ++i) {
      const double mid = 0.5 * (lo + hi);
      (blows_up(m, mid) ? hi : lo) = mid;
    }
    EXPECT_GE(hi / limit, 0.95) << "k " << k;
    EXPECT_LE(hi / limit, 1.05) << "k " << k;
    lk.push_back(std::log(k));
    ldt.push_back(std::log(hi));
  }
  // least-squares slope of log dt_blowup against log k
  const double n = static_cast<double>(lk.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < lk.size(); ++i) {
    sx += lk[i];
    sy += ldt[i];
    sxx += lk[i] * lk[i];
    sxy += lk[i] * ldt[i];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  EXPECT_NEAR(slope, -0.5, 0.01);
}

// --- 2: dt at 3x the limit: the guard substeps (or refuses); never NaN --------------------

TEST(HardCase02, ThreeTimesTheLimitIsSubsteppedOrRefused) {
  Options o = seed_options();
  const Model base = test::grid_model(o, 8, 8, {0u, 7u});
  const StabilityReport r = analyse_stability(base);
  const double dt = 3.0 * r.dt_stable;
  // without the guard it does blow up (so the guard is what saves it)
  {
    Model m = base;
    m.options.dt = dt;
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    bool finite = true;
    for (int i = 0; i < 2000 && finite; ++i)
      finite = step(m, s, ws).finite && s.x.cwiseAbs().maxCoeff() < 1e3;
    EXPECT_FALSE(finite);
  }
  const SubstepPlan plan = plan_substeps(dt, r.dt_stable, parse_substeps("auto"));
  ASSERT_TRUE(plan.ok);
  EXPECT_GE(plan.substeps, 4);  // 3 / 0.9 -> 4
  EXPECT_LT(plan.h, r.dt_stable);
  EXPECT_NE(plan.message.find("substeps"), std::string::npos);
  Model m = base;
  m.options.dt = plan.h;
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 2000; ++i) ASSERT_TRUE(step(m, s, ws).finite) << "step " << i;
  EXPECT_LT((s.x - m.x0).cwiseAbs().maxCoeff(), 2.0);  // hangs, does not explode

  const SubstepPlan off = plan_substeps(dt, r.dt_stable, parse_substeps("off"));
  EXPECT_FALSE(off.ok);
  EXPECT_NE(off.message.find("dt_stable"), std::string::npos) << off.message;
  // an explicit count is taken as asked, with a warning when it is above the limit
  const SubstepPlan two = plan_substeps(dt, r.dt_stable, parse_substeps("2"));
  EXPECT_TRUE(two.ok);
  EXPECT_NE(two.message.find("warning"), std::string::npos) << two.message;
  const SubstepPlan four = plan_substeps(dt, r.dt_stable, parse_substeps("4"));
  EXPECT_TRUE(four.ok);
  EXPECT_TRUE(four.message.empty()) << four.message;
  EXPECT_THROW(parse_substeps("many"), std::invalid_argument);
  EXPECT_THROW(parse_substeps("0"), std::invalid_argument);
}

// Between the safe step (0.9 dt_stable) and dt_stable: auto substeps and says dt is above the
// safe step (not "exceeds dt_stable", which is false); off refuses exactly when auto would
// substep; a fixed count there warns. Below the safe step all three take dt as it is.
TEST(HardCase02, OffRefusesExactlyWhenAutoSubsteps) {
  const double dt_stable = 0.01072;
  const SubstepPolicy autop = parse_substeps("auto"), off = parse_substeps("off"), one = parse_substeps("1");
  const SubstepPlan a = plan_substeps(0.01, dt_stable, autop);
  ASSERT_TRUE(a.ok);
  EXPECT_EQ(a.substeps, 2);
  EXPECT_EQ(a.message.find("exceeds"), std::string::npos) << a.message;
  EXPECT_NE(a.message.find("above the safe step 0.009648 s (0.9 x dt_stable 0.01072 s)"), std::string::npos)
      << a.message;
  const SubstepPlan o = plan_substeps(0.01, dt_stable, off);
  EXPECT_FALSE(o.ok) << "off must refuse where auto substeps: " << o.message;
  EXPECT_NE(o.message.find("safe step 0.009648 s"), std::string::npos) << o.message;
  EXPECT_NE(o.message.find("--substeps 2"), std::string::npos) << o.message;
  const SubstepPlan f = plan_substeps(0.01, dt_stable, one);
  EXPECT_TRUE(f.ok);
  EXPECT_NE(f.message.find("warning"), std::string::npos) << f.message;
  EXPECT_NE(f.message.find("may blow up"), std::string::npos) << f.message;
  // the boundary: off agrees with auto on a sweep of dt across the safe step
  for (double x = 0.85; x <= 1.05; x += 0.001) {
    const double dt = x * dt_stable;
    const SubstepPlan pa = plan_substeps(dt, dt_stable, autop), po = plan_substeps(dt, dt_stable, off);
    EXPECT_EQ(pa.substeps > 1, !po.ok) << "dt " << dt;
    EXPECT_EQ(pa.message.empty(), po.message.empty()) << "dt " << dt;
  }
  // the exact safe step itself is safe
  EXPECT_TRUE(plan_substeps(0.9 * dt_stable, dt_stable, off).ok);
  EXPECT_EQ(plan_substeps(0.9 * dt_stable, dt_stable, autop).substeps, 1);
}

// --- 3: a hanging chain with a 1000:1 mass ratio settles to the exact statics ------------

TEST(HardCase03, ChainWithMassRatio1000StaticRestExact) {
  const int n = 10;
  const double l = 0.1, k = 400.0, g = 9.81;
  for (Integrator method : {Integrator::ImplicitEuler, Integrator::FastMassSpring}) {
    Options o = seed_options();
    o.k_struct = k;
    o.damping = 0.5;
    o.dt = 0.05;
    o.integrator = method;
    ModelBuilder b(o, "chain");
    Eigen::Matrix3Xd x(3, n);
    std::vector<SpringSpec> springs;
    for (int i = 0; i < n; ++i) x.col(i) = Eigen::Vector3d(0, -l * i, 0);
    for (int i = 1; i < n; ++i)
      springs.push_back({static_cast<std::uint32_t>(i - 1), static_cast<std::uint32_t>(i), 0, l});
    const std::vector<std::uint32_t> pins = {0};
    b.add_cloth(x, springs, pins);
    Model m = b.build();
    for (int i = 1; i < n; ++i) {
      m.mass[i] = (i % 2) ? 1.0 : 0.001;
      m.inv_mass[i] = 1.0 / m.mass[i];
    }
    // exact statics: spring i carries the weight of masses i..n-1
    std::vector<double> y(n, 0.0);
    for (int i = 1; i < n; ++i) {
      double below = 0.0;
      for (int j = i; j < n; ++j) below += m.mass[j];
      y[i] = y[i - 1] - (l + below * g / k);
    }
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    for (int i = 0; i < 4000; ++i) ASSERT_TRUE(step(m, s, ws).finite);
    for (int i = 1; i < n; ++i)
      EXPECT_NEAR(s.x(1, i), y[i], 1e-6 * std::abs(y[i])) << to_string(method) << " mass " << i;
  }
}

// --- 4: pinned corners under load: bit-identical pins, reactions = weight ----------------

TEST(HardCase04, PinnedCornersHoldTheWeight) {
  Options o = seed_options();
  o.damping = 1.0;
  o.dt = 0.02;
  o.integrator = Integrator::ImplicitEuler;
  const int w = 5;
  const Model m = test::grid_model(o, w, w, {0u, static_cast<std::uint32_t>(w - 1)});
  for (Integrator method : all_integrators()) {  // pins exact under every method
    Model mm = m;
    mm.options.integrator = method;
    mm.options.dt = method == Integrator::ExplicitEuler ? 1e-4 : 0.002;
    State s = make_state(mm);
    Workspace ws = make_workspace(mm);
    for (int i = 0; i < 100; ++i) ASSERT_TRUE(step(mm, s, ws).finite);
    for (std::size_t i = 0; i < mm.mass_count(); ++i) {
      if (!mm.pinned[i]) continue;
      EXPECT_EQ(std::memcmp(s.x.col(static_cast<Eigen::Index>(i)).data(),
                              mm.x0.col(static_cast<Eigen::Index>(i)).data(), 3 * sizeof(double)), 0)
          << to_string(method);
    }
  }
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 5000; ++i) ASSERT_TRUE(step(m, s, ws).finite);
  Eigen::Matrix3Xd fs = Eigen::Matrix3Xd::Zero(3, s.x.cols());
  add_spring_forces(m, s.x, fs);
  Eigen::Vector3d reaction = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (m.pinned[i])
      reaction -= fs.col(static_cast<Eigen::Index>(i)) + m.mass[static_cast<Eigen::Index>(i)] * gravity(o);
  const Eigen::Vector3d weight = m.mass.sum() * gravity(o);
  EXPECT_LE((reaction + weight).norm(), 1e-6 * weight.norm())
      << "reaction " << reaction.transpose() << " weight " << weight.transpose();
}

// --- 5: zero-length springs and coincident endpoints ------------------------------------

TEST(HardCase05, ZeroLengthAndCoincidentSpringsFiniteMomentumConserved) {
  Options o = seed_options();
  o.gravity_x = o.gravity_y = o.gravity_z = 0.0;
  o.damping = 0.0;
  o.dt = 0.001;
  Eigen::Matrix3Xd x(3, 4);
  x << 0.0, 0.1, 0.5, 0.5,  //
      0.0, 0.0, 0.0, 0.0,   //
      0.0, 0.0, 0.0, 0.0;   // masses 2 and 3 coincide
  const std::vector<SpringSpec> springs = {
      {0, 1, 0, 0.0},   // zero rest length, ends apart
      {2, 3, 0, 0.1},   // ends coincide, rest length > 0
      {1, 2, 0, -1.0},  // an ordinary spring
      {0, 3, 1, 0.0}};  // zero rest length bend spring
  for (Integrator method : all_integrators()) {
    Options om = o;
    om.integrator = method;
    if (method == Integrator::ExplicitEuler) om.dt = 1e-5;
    ModelBuilder b(om, "degenerate");
    b.add_cloth(x, springs, {});
    const Model m = b.build();
    State s = make_state(m);
    s.v.col(0) << 0.3, -0.2, 0.1;
    s.v.col(3) << -0.1, 0.4, 0.0;
    Workspace ws = make_workspace(m);
    // implicit Euler conserves momentum to its CG tolerance: make that tight here
    ws.integrator_scratch = make_integrator_scratch(m);
    ImplicitSettings tight;
    tight.cg_tolerance = 1e-14;
    set_implicit_settings(*ws.integrator_scratch, tight);
    Eigen::Matrix3Xd f(3, 4);
    compute_forces(m, s.x, s.v, f, ws);
    ASSERT_TRUE(f.allFinite()) << to_string(method);
    const Eigen::Vector3d p0 = s.v * m.mass;
    for (int i = 0; i < 2000; ++i) ASSERT_TRUE(step(m, s, ws).finite) << to_string(method);
    const Eigen::Vector3d p1 = s.v * m.mass;
    const bool solves = method == Integrator::ImplicitEuler || method == Integrator::FastMassSpring;
    // explicit methods: round-off only; solvers: their tolerance / the Cholesky's round-off
    EXPECT_LE((p1 - p0).norm(), solves ? 1e-9 * p0.norm() : 1e-12) << to_string(method);
  }
}

// --- 6: degenerate triangles in the cloth and in a collider -----------------------------

TEST(HardCase06, DegenerateTrianglesNoNaNNeighboursStillCollide) {
  Options o = seed_options();
  o.dt = 0.001;
  o.damping = 0.5;
  // 3 x 3 cloth at y = 0.3 with a duplicated corner (a zero-area triangle) joined by a
  // zero-length spring, over a floor that carries a collinear sliver triangle.
  Eigen::Matrix3Xd x = test::grid_positions(3, 3, 0.1, 0.3);
  x.conservativeResize(3, 10);
  x.col(9) = x.col(4);
  std::vector<SpringSpec> springs = test::grid_springs(3, 3);
  springs.push_back({4, 9, 0, 0.0});
  springs.push_back({9, 5, 0, -1.0});
  springs.push_back({9, 1, 0, -1.0});
  for (Integrator method : {Integrator::SymplecticEuler, Integrator::RK4, Integrator::ImplicitEuler}) {
    Options om = o;
    om.integrator = method;
    ModelBuilder b(om, "degenerate");
    b.add_cloth(x, springs, {});
    b.set_colliders(floor_collider(true));
    const Model m = b.build();
    ASSERT_EQ(m.colliders->degenerate_count(1), 1u);
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    for (int i = 0; i < 3000; ++i) ASSERT_TRUE(step(m, s, ws).finite) << to_string(method);
    // everyone rests in the floor's band, the masses over the sliver included
    EXPECT_GT(s.x.row(1).minCoeff(), 0.0) << to_string(method);
    EXPECT_LT(s.x.row(1).maxCoeff(), o.epsilon) << to_string(method);
  }
}

// --- 7: tunnelling: held below the guard's speed, warned above it -----------------------

double lowest_y(Model m, double t_end) {
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  double lo = s.x(1, 0);
  const auto n = static_cast<int>(t_end / m.options.dt);
  for (int i = 0; i < n; ++i) {
    if (!step(m, s, ws).finite) return -INFINITY;
    lo = std::min(lo, s.x(1, 0));
  }
  return lo;
}

TEST(HardCase07, TunnellingGuard) {
  Options o = seed_options();
  o.damping = 0.0;
  o.dt = 0.001;
  o.k_rep = 100.0;  // stop speed eps sqrt(k_rep / m) = 1.58 m/s: short drops
  o.epsilon = 0.05;
  const double g = 9.81;
  const double v_max = max_stoppable_speed(o.epsilon, o.k_rep, o.mass, o.dt);
  // below: 0.9 v_max at the surface (the guard measures the fall to the lowest collider point)
  {
    const double v = 0.9 * v_max;
    const Model m = point_over_floor(o, v * v / (2 * g));
    const TunnellingReport r = check_tunnelling(m, o.dt);
    EXPECT_FALSE(r.warn) << r.message;
    EXPECT_GT(lowest_y(m, 3.0), -o.epsilon);  // never gets through the band
  }
  // above: 3 v_max
  {
    const double v = 3.0 * v_max;
    const Model m = point_over_floor(o, v * v / (2 * g));
    const TunnellingReport r = check_tunnelling(m, o.dt);
    EXPECT_TRUE(r.warn);
    EXPECT_NE(r.message.find("tunnelling"), std::string::npos);
    EXPECT_LT(lowest_y(m, 3.0), -2.0 * o.epsilon);  // and it does fall through
  }
}

// --- 8: resting contact depth eps - m g / k_rep -----------------------------------------

TEST(HardCase08, RestingContactDepth) {
  Options o = seed_options();
  o.damping = 1.0;
  o.dt = 0.001;
  const Model m = point_over_floor(o, 0.3);
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 10000; ++i) ASSERT_TRUE(step(m, s, ws).finite);
  const double expect = o.epsilon - o.mass * 9.81 / o.k_rep;
  EXPECT_NEAR(s.x(1, 0), expect, 1e-6 * expect);
  EXPECT_LT(s.v.col(0).norm(), 1e-4);
}

// --- 9: 10^6 undamped symplectic Euler steps: energy error bounded ---------------------

double energy(const Model& m, const State& s) {
  double e = 0.0;
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    const auto c = static_cast<Eigen::Index>(i);
    e += 0.5 * m.mass[c] * s.v.col(c).squaredNorm() - m.mass[c] * gravity(m.options).dot(s.x.col(c));
  }
  for (std::size_t k = 0; k < m.spring_count(); ++k) {
    const double len = (s.x.col(m.spring_a[k]) - s.x.col(m.spring_b[k])).norm();
    const double st = len - m.rest_length0[static_cast<Eigen::Index>(k)];
    e += 0.5 * m.spring_stiffness(k) * st * st;
  }
  return e;
}

Model spring_pendulum(const Options& o) {
  ModelBuilder b(o, "pendulum");
  Eigen::Matrix3Xd x(3, 2);
  x << 0.0, 0.05, 0.0, -0.12, 0.0, 0.0;
  const std::vector<SpringSpec> springs = {{0, 1, 0, 0.1}};
  const std::vector<std::uint32_t> pins = {0};
  b.add_cloth(x, springs, pins);
  return b.build();
}

TEST(HardCase09, MillionUndampedStepsEnergyBounded) {
  Options o = seed_options();
  o.damping = 0.0;
  o.dt = 0.002;
  const Model m = spring_pendulum(o);
  State s = make_state(m);
  s.v.col(1) << 0.3, 0.0, 0.2;
  Workspace ws = make_workspace(m);
  const double e0 = energy(m, s);
  const int n = 1000000;
  double first = 0.0, second = 0.0;
  for (int i = 1; i <= n; ++i) {
    ASSERT_TRUE(step(m, s, ws).finite);
    const double err = std::abs(energy(m, s) - e0);
    if (i <= n / 10) first = std::max(first, err);
    if (i > n / 2) second = std::max(second, err);
  }
  EXPECT_GT(first, 0.0);
  EXPECT_LE(second, 1.1 * first) << "first 10 % " << first << ", second half " << second;
}

// --- 10: damped runs: energy never grows beyond the O(h omega) oscillation ---------------

TEST(HardCase10, DampedEnergyNeverGrowsBeyondTheory) {
  Options o = seed_options();
  o.gravity_x = o.gravity_y = o.gravity_z = 0.0;
  o.damping = 0.1;
  o.dt = 0.004;
  for (Integrator method : {Integrator::SymplecticEuler, Integrator::Verlet, Integrator::Midpoint,
                            Integrator::RK4, Integrator::ImplicitEuler, Integrator::FastMassSpring}) {
    Options om = o;
    om.integrator = method;
    const Model m = spring_pendulum(om);
    const double omega = std::sqrt(m.spring_stiffness(0) / m.mass[1]);
    const double ho = o.dt * omega;
    const double bound = ho / (1.0 - ho / 2.0);  // symplectic Euler's, the loosest of these
    State s = make_state(m);
    s.v.col(1) << 0.3, 0.0, 0.2;
    Workspace ws = make_workspace(m);
    const double e0 = energy(m, s);
    double lowest = e0, worst = 0.0;
    for (int i = 0; i < 20000; ++i) {
      ASSERT_TRUE(step(m, s, ws).finite);
      const double e = energy(m, s);
      worst = std::max(worst, e - lowest);
      lowest = std::min(lowest, e);
    }
    EXPECT_LE(worst, bound * e0) << to_string(method);
    EXPECT_LT(energy(m, s), 0.5 * e0) << to_string(method);  // and it does dissipate
  }
}

// --- 12: elastic bounce: rebound <= drop height (1 + h omega_c); explicit Euler fails ----

double rebound_height(Integrator method, double h, double drop, double mass = Options{}.mass) {
  Options o = seed_options();
  o.mass = mass;
  o.damping = 0.0;
  o.dt = h;
  o.integrator = method;
  const Model m = point_over_floor(o, o.epsilon + drop);
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  bool touched = false;
  double apex = -INFINITY;
  for (int i = 0; i < static_cast<int>(2.0 / h); ++i) {
    if (!step(m, s, ws).finite) return INFINITY;
    if (s.x(1, 0) < o.epsilon) touched = true;
    if (touched && s.x(1, 0) > o.epsilon) apex = std::max(apex, s.x(1, 0) - o.epsilon);
    if (touched && s.v(1, 0) < 0 && s.x(1, 0) > o.epsilon) break;  // first apex passed
  }
  return apex;
}

TEST(HardCase12, ElasticBounceDoesNotGainHeight) {
  const double h = 0.002, drop = 0.3;
  const Options o = seed_options();
  const double omega_c = std::sqrt(o.k_rep / o.mass);
  const double allowed = drop * (1.0 + h * omega_c);
  for (Integrator method : {Integrator::SymplecticEuler, Integrator::Verlet, Integrator::RK4,
                            Integrator::ImplicitEuler}) {
    const double r = rebound_height(method, h, drop);
    EXPECT_LE(r, allowed) << to_string(method);
    EXPECT_GT(r, 0.0) << to_string(method);  // it bounces
  }
  EXPECT_GT(rebound_height(Integrator::ExplicitEuler, h, drop), allowed);
}

// The penalty contact is explicit in every integrator (the implicit ones solve only the
// springs implicitly), and a one-sided spring taken explicitly gains energy per bounce as
// h omega_c nears 2: dropped 0.3 m, a point rebounds 0.889 m at h omega_c = 1.8, 0.308 m at 1.
// So dt_stable stays at or under 1 / (0.9 omega_c) for the implicit methods too (their springs
// alone give inf): at its safe step (0.9 x) the rebound is within the bound above, for the
// implicit methods and symplectic Euler. XPBD's contact is a position projection: it never
// bounces higher than the drop, at its step or at the default dt.
TEST(HardCase12, ImplicitMethodsAreLimitedByTheExplicitContact) {
  Options o = seed_options();
  o.mass = 0.01;  // omega_c = sqrt(600 / 0.01) = 245 rad/s: the default dt 0.01 gives h omega_c 2.45
  o.damping = 0.0;
  const double omega_c = std::sqrt(o.k_rep / o.mass), drop = 0.3;
  for (Integrator method : {Integrator::ImplicitEuler, Integrator::FastMassSpring, Integrator::SymplecticEuler}) {
    o.integrator = method;
    const StabilityReport r = analyse_stability(point_over_floor(o, 1.0));
    EXPECT_LE(r.dt_stable, 1.0 / (0.9 * omega_c) * (1.0 + 1e-12)) << to_string(method);
    EXPECT_GT(r.dt_stable, 0.5 / omega_c) << to_string(method);
    EXPECT_TRUE(r.contact_limited) << to_string(method);
    const double h = 0.9 * r.dt_stable, rebound = rebound_height(method, h, drop, o.mass);
    EXPECT_LE(rebound, drop * (1.0 + h * omega_c)) << to_string(method);
  }
  for (const double h : {xpbd_step(point_over_floor(o, 1.0)), 0.01})
    EXPECT_LE(rebound_height(Integrator::XPBD, h, drop, o.mass), drop) << h;
}

}  // namespace
}  // namespace clothsim
