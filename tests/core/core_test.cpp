// The core's physics against closed forms: springs, oscillator, free fall, chain, pins.
#include "inline_scenes.hpp"

#include <clothsim/step.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>
#include <tuple>

namespace clothsim {
namespace {

Options no_gravity() {
  Options o = seed_options();
  o.gravity_x = o.gravity_y = o.gravity_z = 0.0;
  o.damping = 0.0;
  return o;
}

Model two_masses(const Options& o, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double rest,
                 std::vector<std::uint32_t> pins = {}) {
  ModelBuilder mb(o, "pair");
  Eigen::Matrix3Xd x(3, 2);
  x.col(0) = a;
  x.col(1) = b;
  const SpringSpec s{0, 1, 0, rest};
  mb.add_cloth(x, std::span(&s, 1), pins);
  return mb.build();
}

TEST(Springs, ForceMagnitudeAndDirectionStretched) {
  const Options o = no_gravity();
  const Eigen::Vector3d a(0.1, 0.2, 0.3), b(0.4, -0.2, 1.5);
  const Model m = two_masses(o, a, b, 0.5);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, 2);
  add_spring_forces(m, m.x0, f);
  const double len = (a - b).norm();
  ASSERT_GT(len, 0.5);
  // stretched: each end is pulled toward the other with k (len - rest)
  EXPECT_NEAR(f.col(0).norm(), o.k_struct * (len - 0.5), 1e-12);
  EXPECT_NEAR(f.col(0).normalized().dot((b - a).normalized()), 1.0, 1e-12);
  EXPECT_NEAR((f.col(0) + f.col(1)).norm(), 0.0, 1e-12);
}

TEST(Springs, CompressedPushesApartAndBendUsesKBend) {
  const Options o = no_gravity();
  ModelBuilder mb(o);
  Eigen::Matrix3Xd x(3, 2);
  x << 0, 0.3, 0, 0, 0, 0;
  const SpringSpec s{0, 1, 1, 1.0};  // a bend spring compressed to 0.3
  mb.add_cloth(x, std::span(&s, 1), {});
  const Model m = mb.build();
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, 2);
  add_spring_forces(m, m.x0, f);
  EXPECT_NEAR(f(0, 0), -o.k_bend * 0.7, 1e-12);
  EXPECT_NEAR(f(0, 1), o.k_bend * 0.7, 1e-12);
}

TEST(Springs, RestLengthDefaultsToTheRestDistance) {
  const Model m = test::grid_model(no_gravity(), 3, 3);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, 9);
  add_spring_forces(m, m.x0, f);
  // (the rest length is stored in float: off by at most half a float's step)
  const double k = std::max(m.spring_modulus[0], m.spring_modulus[1]);
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 4.0 * k * m.rest_length0.maxCoeff() * std::numeric_limits<float>::epsilon());
}

// One free mass on a spring to a pinned one, no gravity: the damped oscillator
// u(t) = e^{-beta t} (u0 cos(wd t) + beta u0 / wd sin(wd t)), beta = gamma / 2m.
double oscillator_error(double dt) {
  Options o = no_gravity();
  o.damping = 0.05;
  o.dt = dt;
  const double rest = 0.5, u0 = 0.05;
  const Model m = two_masses(o, Eigen::Vector3d::Zero(), Eigen::Vector3d(rest + u0, 0, 0), rest, {0});
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  const double w0 = std::sqrt(o.k_struct / o.mass), beta = o.damping / (2 * o.mass);
  const double wd = std::sqrt(w0 * w0 - beta * beta);
  double err = 0.0;
  const int n = static_cast<int>(std::lround(0.5 / dt));
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(step(m, s, ws).finite);
    const double t = s.t;
    const double u = std::exp(-beta * t) * (u0 * std::cos(wd * t) + beta * u0 / wd * std::sin(wd * t));
    err = std::max(err, std::abs((s.x(0, 1) - rest) - u));
    EXPECT_EQ(s.x(1, 1), 0.0);
  }
  return err / u0;
}

TEST(Integrator, DampedOscillatorMatchesClosedFormToFirstOrder) {
  const double e1 = oscillator_error(2e-4), e2 = oscillator_error(1e-4);
  EXPECT_LT(e2, 1e-2);
  // symplectic Euler is first order: halving dt about halves the error
  EXPECT_GT(e1 / e2, 1.6);
  EXPECT_LT(e1 / e2, 2.4);
}

TEST(Integrator, FreeFallFollowsTheSymplecticEulerRecurrence) {
  Options o = seed_options();
  o.damping = 0.07;
  o.dt = 0.01;
  ModelBuilder mb(o);
  Eigen::Matrix3Xd x(3, 1);
  x << 0.25, 3.0, -1.0;
  mb.add_cloth(x, {}, {});
  const Model m = mb.build();
  State s = make_state(m);
  s.v.col(0) = Eigen::Vector3d(0.5, 2.0, 0.0);
  Workspace ws = make_workspace(m);
  Eigen::Vector3d xr = x.col(0), vr = s.v.col(0);
  for (int i = 0; i < 300; ++i) {
    ASSERT_TRUE(step(m, s, ws).finite);
    xr = xr + o.dt * vr;                                   // eq. 1
    const Eigen::Vector3d f = o.mass * gravity(o) - o.damping * vr;
    vr = vr + o.dt * (f * (1.0 / o.mass));                 // eqs. 6-7
    for (int c = 0; c < 3; ++c) {
      ASSERT_DOUBLE_EQ(s.x(c, 0), xr[c]) << "step " << i;
      ASSERT_DOUBLE_EQ(s.v(c, 0), vr[c]) << "step " << i;
    }
  }
  // without damping the recurrence has a closed form: y_n = y0 + n h vy0 - h^2 g n(n-1)/2
  o.damping = 0.0;
  ModelBuilder mb2(o);
  mb2.add_cloth(x, {}, {});
  const Model m2 = mb2.build();
  State s2 = make_state(m2);
  Workspace ws2 = make_workspace(m2);
  const int n = 200;
  for (int i = 0; i < n; ++i) ASSERT_TRUE(step(m2, s2, ws2).finite);
  const double expected = 3.0 - o.dt * o.dt * 9.81 * n * (n - 1) / 2.0;
  EXPECT_NEAR(s2.x(1, 0), expected, 1e-12 * std::abs(expected));
  EXPECT_NEAR(s2.v(1, 0), -9.81 * o.dt * n, 1e-12 * 9.81 * o.dt * n);
}

TEST(Integrator, HangingChainReachesTheAnalyticEquilibrium) {
  Options o = seed_options();
  o.damping = 1.0;  // beta = 5/s: every mode rings down within a few seconds
  o.dt = 0.005;
  const int n = 10;
  const double l = 0.1;
  Eigen::Matrix3Xd x(3, n);
  std::vector<SpringSpec> springs;
  for (int i = 0; i < n; ++i) x.col(i) = Eigen::Vector3d(0, -i * l, 0);
  for (int i = 1; i < n; ++i) springs.push_back({std::uint32_t(i - 1), std::uint32_t(i), 0, -1.0});
  ModelBuilder mb(o, "chain");
  const std::uint32_t pin = 0;
  mb.add_cloth(x, springs, std::span(&pin, 1));
  const Model m = mb.build();
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 3000; ++i) ASSERT_TRUE(step(m, s, ws).finite);
  // spring j carries the weight of the n - j masses below it
  double y = 0.0;
  for (int j = 1; j < n; ++j) {
    y -= l + o.mass * 9.81 * (n - j) / o.k_struct;
    EXPECT_NEAR(s.x(1, j), y, 1e-6 * std::abs(y)) << "mass " << j;
    EXPECT_NEAR(s.x(0, j), 0.0, 1e-12);
  }
}

TEST(Integrator, PinnedMassesStayBitIdentical) {
  Options o = seed_options();
  Model m = test::grid_model(o, 6, 6, {0, 5});
  m.x0(0, 5) = -0.0 * m.x0(0, 5);  // a negative zero must survive
  m.x0(1, 5) = -0.0;
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  const Eigen::Matrix3Xd before = s.x;
  for (int i = 0; i < 200; ++i) ASSERT_TRUE(step(m, s, ws).finite);
  EXPECT_EQ(std::memcmp(s.x.col(0).data(), before.col(0).data(), 3 * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(s.x.col(5).data(), before.col(5).data(), 3 * sizeof(double)), 0);
  EXPECT_TRUE(std::signbit(s.x(1, 5)));
  EXPECT_EQ(s.v.col(0).squaredNorm(), 0.0);
  EXPECT_LT(s.x(1, 35), -0.1);  // the free corner fell
}

TEST(Integrator, SameRunTwiceIsBitIdentical) {
  Options o = seed_options();
  const Model m = test::grid_model(o, 8, 8, {0, 7});
  auto run = [&m] {
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    for (int i = 0; i < 300; ++i) step(m, s, ws);
    return state_hash(s);
  };
  EXPECT_EQ(run(), run());
}

TEST(Integrator, StepDoesNotChangeTheModelAndCountsTime) {
  Options o = seed_options();
  const Model m = test::grid_model(o, 4, 4, {0});
  const Eigen::Matrix3Xd x0 = m.x0;
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 10; ++i) step(m, s, ws);
  EXPECT_EQ(s.steps, 10u);
  EXPECT_NEAR(s.t, 0.1, 1e-12);
  EXPECT_EQ(m.x0, x0);
}

TEST(Stability, GershgorinStepIsStableAndTwiceItBlowsUp) {
  Options o = no_gravity();
  const Model probe = test::grid_model(o, 6, 6);
  const double dt_safe = 2.0 / gershgorin_omega_max(probe);
  auto finite_after = [&](double dt) {
    Options oo = o;
    oo.dt = dt;
    const Model m = test::grid_model(oo, 6, 6);
    State s = make_state(m);
    for (Eigen::Index i = 0; i < s.v.cols(); ++i) s.v.col(i) = Eigen::Vector3d(0.01 * ((i * 7) % 5), 0.02 * ((i * 3) % 4), 0.0);
    Workspace ws = make_workspace(m);
    for (int i = 0; i < 3000; ++i)
      if (!step(m, s, ws).finite) return false;
    return s.x.cwiseAbs().maxCoeff() < 10.0;
  };
  EXPECT_TRUE(finite_after(0.98 * dt_safe));
  EXPECT_FALSE(finite_after(2.0 * dt_safe));
}

TEST(Integrator, NonFiniteIsReported) {
  Options o = seed_options();
  o.dt = 1.0;  // far above the stability limit
  const Model m = test::grid_model(o, 5, 5, {0});
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  bool finite = true;
  for (int i = 0; i < 2000 && finite; ++i) finite = step(m, s, ws).finite;
  EXPECT_FALSE(finite);
}

TEST(Drag, PullsTheMassTowardTheTarget) {
  const Options o = no_gravity();
  const Model m = test::grid_model(o, 3, 3);
  State s = make_state(m);
  s.drag = Drag{4, m.x0.col(4) + Eigen::Vector3d(0, 1, 0), 10.0};
  Workspace ws = make_workspace(m);
  step(m, s, ws);
  EXPECT_GT(s.v(1, 4), 0.0);
  EXPECT_EQ(s.v(1, 0), 0.0);
}

// A target beyond the reach pulls as one at the reach: k * reach along the pull, not k * 100.
TEST(Drag, TargetBeyondTheReachPullsAsAtTheReach) {
  const Options o = no_gravity();
  const Model m = test::grid_model(o, 3, 3);
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  const Eigen::Vector3d dir = Eigen::Vector3d(1.0, 2.0, -2.0) / 3.0;
  Eigen::Matrix3Xd f_near(3, 9), f_far(3, 9);
  ws.drag = Drag{4, m.x0.col(4) + 0.05 * dir, 10.0, 0.1};  // within the reach: k * 0.05
  compute_forces(m, s.x, s.v, f_near, ws);
  ws.drag = Drag{4, m.x0.col(4) + 100.0 * dir, 10.0, 0.1};  // far beyond: k * 0.1, not k * 100
  compute_forces(m, s.x, s.v, f_far, ws);
  EXPECT_NEAR((f_near.col(4) - 10.0 * 0.05 * dir).norm(), 0.0, 1e-12);
  EXPECT_NEAR((f_far.col(4) - 10.0 * 0.1 * dir).norm(), 0.0, 1e-12);
  EXPECT_EQ(f_far.col(0), f_near.col(0));  // the other masses do not feel it
}

TEST(Options, ValidateRefusesBadValues) {
  EXPECT_EQ(validate_options(Options{}), "");
  Options o = seed_options();
  o.dt = 0.0;
  EXPECT_NE(validate_options(o).find("dt"), std::string::npos);
  o = Options{};
  o.dt = -0.01;
  EXPECT_NE(validate_options(o).find("dt"), std::string::npos);
  o = Options{};
  o.mass = 0.0;
  EXPECT_NE(validate_options(o).find("mass"), std::string::npos);
  o = Options{};
  o.k_struct = std::nan("");
  EXPECT_NE(validate_options(o).find("k_struct"), std::string::npos);
  o = Options{};
  o.gravity_y = INFINITY;
  EXPECT_NE(validate_options(o).find("gravity"), std::string::npos);
}

TEST(Builder, RefusesBadIndices) {
  ModelBuilder mb(seed_options());
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 2);
  const SpringSpec bad{0, 2, 0};
  EXPECT_THROW(mb.add_cloth(x, std::span(&bad, 1), {}), std::invalid_argument);
  const SpringSpec self{1, 1, 0};
  EXPECT_THROW(mb.add_cloth(x, std::span(&self, 1), {}), std::invalid_argument);
  const std::uint32_t pin = 5;
  EXPECT_THROW(mb.add_cloth(x, {}, std::span(&pin, 1)), std::invalid_argument);
}

TEST(Builder, ConcatenatesClothsWithGlobalIndices) {
  ModelBuilder mb(seed_options());
  const auto sp = test::grid_springs(2, 2);
  mb.add_cloth(test::grid_positions(2, 2, 0.1, 0.0), sp, {});
  const std::uint32_t pin = 1;
  mb.add_cloth(test::grid_positions(2, 2, 0.1, 1.0), sp, std::span(&pin, 1));
  const Model m = mb.build();
  ASSERT_EQ(m.cloths.size(), 2u);
  EXPECT_EQ(m.mass_count(), 8u);
  EXPECT_EQ(m.cloths[1].first_mass, 4u);
  EXPECT_EQ(m.cloths[1].first_spring, sp.size());
  for (std::size_t s = 0; s < sp.size(); ++s) {  // the second cloth's springs: the first's, moved by 4
    EXPECT_EQ(m.spring_a[sp.size() + s], 4u + m.spring_a[s]);
    EXPECT_EQ(m.spring_b[sp.size() + s], 4u + m.spring_b[s]);
  }
  EXPECT_EQ(m.pinned[5], 1);
  EXPECT_EQ(m.inv_mass[5], 0.0);
  EXPECT_DOUBLE_EQ(m.inv_mass[4], 10.0);
}

// step() reports a state with one NaN or infinite coordinate or velocity, wherever it is
// (the first or last value, inside a vector block or its tail, any slice) and on any thread
// count; a finite state is finite however large its values (no sum that overflows). A pinned
// mass ends a step where it was with velocity 0, so only its position counts.
TEST(Step, FiniteCheckFindsOneNonFiniteValueAnywhere) {
  const Eigen::Index n = 5002;  // above the threaded check's 4096 values; 4 masses a block: 2 left over
  Eigen::Matrix3Xd pos(3, n);
  for (Eigen::Index i = 0; i < n; ++i) pos.col(i) = Eigen::Vector3d(0.01 * static_cast<double>(i), 1.0, 0.0);
  ModelBuilder mb(seed_options());
  const std::uint32_t pins[] = {2, static_cast<std::uint32_t>(n - 2)};  // in a block, left over
  mb.add_cloth(pos, {}, pins);
  const Model m = mb.build();
  for (int threads : {1, 2}) {
    for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()})
      for (const Eigen::Index at : {Eigen::Index{0}, Eigen::Index{5}, Eigen::Index{7503}, 3 * n - 2, 3 * n - 1})
        for (const bool in_x : {true, false}) {
          State s = make_state(m);
          Workspace ws = make_workspace(m);
          ws.threads = threads;
          (in_x ? s.x : s.v).data()[at] = bad;
          EXPECT_FALSE(step(m, s, ws).finite) << threads << " threads, " << bad << " at " << at << (in_x ? " in x" : " in v");
        }
    for (const Eigen::Index pin : {Eigen::Index{2}, n - 2}) {
      State s = make_state(m);
      Workspace ws = make_workspace(m);
      s.v(1, pin) = std::numeric_limits<double>::quiet_NaN();  // a pinned mass's velocity is set to 0
      EXPECT_TRUE(step(m, s, ws).finite) << threads << " threads, pin " << pin;
      EXPECT_EQ(s.v(1, pin), 0.0);
      s.x(1, pin) = std::numeric_limits<double>::infinity();  // its position is kept
      EXPECT_FALSE(step(m, s, ws).finite) << threads << " threads, pin " << pin;
    }
    State s = make_state(m);
    s.x.setConstant(1e305);  // their sum would overflow
    Workspace ws = make_workspace(m);
    ws.threads = threads;
    EXPECT_TRUE(step(m, s, ws).finite) << threads << " threads";
  }
}

// The builder turns every spring from its lower mass and orders them by it, highest first,
// keeping the springs (ends, kind, rest length) and the order of equals: then each mass meets
// its springs, in index order, first as the a end and then as the b end.
TEST(Builder, OrdersSpringsSoThatEachMassMeetsItsAEndsFirst) {
  ModelBuilder mb(seed_options());
  std::vector<SpringSpec> sp = test::grid_springs(5, 4);
  for (std::size_t s = 0; s < sp.size(); s += 3) std::swap(sp[s].a, sp[s].b);  // some turned around
  sp[1].rest_length = 0.25;
  const Eigen::Matrix3Xd pos = test::grid_positions(5, 4, 0.1, 0.0);
  mb.add_cloth(pos, sp, {});
  const Model m = mb.build();
  ASSERT_EQ(m.spring_count(), sp.size());
  std::multiset<std::tuple<std::uint32_t, std::uint32_t, int, float>> want, got;
  for (const auto& s : sp)
    want.emplace(std::min(s.a, s.b), std::max(s.a, s.b), s.kind,
                 static_cast<float>(s.rest_length >= 0.0 ? s.rest_length : (pos.col(s.a) - pos.col(s.b)).norm()));
  for (std::size_t s = 0; s < m.spring_count(); ++s) {
    EXPECT_LT(m.spring_a[s], m.spring_b[s]);
    if (s > 0) {
      EXPECT_GE(m.spring_a[s - 1], m.spring_a[s]);
    }
    got.emplace(m.spring_a[s], m.spring_b[s], m.spring_kind[s], m.rest_length0[static_cast<Eigen::Index>(s)]);
  }
  EXPECT_EQ(want, got);
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    bool b_end_seen = false;
    for (std::size_t s = 0; s < m.spring_count(); ++s) {
      if (m.spring_b[s] == i) b_end_seen = true;
      if (m.spring_a[s] == i) {
        EXPECT_FALSE(b_end_seen) << "mass " << i << ", spring " << s;
      }
    }
  }
}

}  // namespace
}  // namespace clothsim

// --- contact through the full step (needs the collision module) --------------------------
#include <clothsim/collision.hpp>

namespace clothsim {
namespace {

class RestingOnFloor : public ::testing::TestWithParam<double> {};

// A mass dropped onto a floor rests at height d = eps - m g / k_rep above the surface,
// where the penalty k_rep (eps - d) carries its weight m g.
TEST_P(RestingOnFloor, DepthIsEpsMinusWeightOverKRep) {
  Options o = seed_options();
  o.k_rep = GetParam();
  o.damping = 2.0;  // rings down within a few hundred steps
  ModelBuilder mb(o, "floor");
  Eigen::Matrix3Xd x(3, 1);
  x << 0.1, 0.3, 0.2;
  mb.add_cloth(x, {}, {});
  auto floor = std::make_shared<ColliderSet>();
  Eigen::Matrix3Xd fv(3, 4);
  fv << -1, 1, 1, -1, 0, 0, 0, 0, -1, -1, 1, 1;
  const std::vector<std::uint32_t> tris{0, 2, 1, 0, 3, 2};  // counter-clockwise seen from +Y
  floor->add_object("floor", fv, tris);
  floor->build();
  mb.set_colliders(floor);
  const Model m = mb.build();
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 3000; ++i) ASSERT_TRUE(step(m, s, ws).finite);
  const double expected = o.epsilon - o.mass * 9.81 / o.k_rep;
  EXPECT_NEAR(s.x(1, 0), expected, 1e-9);
  EXPECT_EQ(s.max_penetration, 0.0);  // never behind the surface
}

INSTANTIATE_TEST_SUITE_P(KRep, RestingOnFloor, ::testing::Values(50.0, 300.0, 1000.0));

}  // namespace
}  // namespace clothsim
