// Coulomb friction against a collider, against its closed forms (Bridson, Fedkiw, Anderson
// 2002): on an incline a point stays for tan(theta) < mu_s and slides with
// a = g (sin(theta) - mu_k cos(theta)) above it; a point sliding at v0 on a level plane stops
// after v0^2 / (2 mu g); and friction never adds energy. For the position-based contact
// (XPBD) and the penalty contact with the velocity filter (symplectic Euler).
#include <clothsim/collision.hpp>
#include <clothsim/model_builder.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

namespace clothsim {
namespace {

constexpr double kG = 9.81;

// A 20 x 20 m plane through the origin, tilted by theta about z (its downhill is +x).
std::shared_ptr<ColliderSet> incline(double theta) {
  auto set = std::make_shared<ColliderSet>();
  Eigen::Matrix3Xd v(3, 4);
  const double c = std::cos(theta), s = std::sin(theta);
  // corners in the plane's own frame (u along the slope, w across), then tilted
  const double corners[4][2] = {{-10, -10}, {10, -10}, {10, 10}, {-10, 10}};
  for (int k = 0; k < 4; ++k) v.col(k) = Eigen::Vector3d(corners[k][0] * c, -corners[k][0] * s, corners[k][1]);
  set->add_object("incline", v, std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2});
  set->build();
  return set;
}

// One point of 0.01 kg resting on the incline at its contact distance (the penalty's resting
// depth for the force-based contact), with velocity v0 along the slope.
struct Slide {
  Model model;
  State state;
  Workspace ws;
  Eigen::Vector3d down;  // unit vector down the slope
};

Slide slide(Integrator method, double theta, double mu_k, double mu_s, double v0 = 0.0) {
  Options o = seed_options();
  o.mass = 0.01;
  o.damping = 0.0;
  o.k_rep = 1e4;
  o.epsilon = 0.01;
  o.friction = mu_k;
  o.static_friction = mu_s;
  o.integrator = method;
  o.dt = 2e-4;
  const Eigen::Vector3d nrm(std::sin(theta), std::cos(theta), 0.0);
  const double rest = method == Integrator::XPBD ? o.epsilon : o.epsilon - o.mass * kG * std::cos(theta) / o.k_rep;
  ModelBuilder b(o, "point");
  Eigen::Matrix3Xd x(3, 1);
  x.col(0) = rest * nrm;
  b.add_cloth(x, {}, {});
  b.set_colliders(incline(theta));
  Slide s{b.build(), {}, {}, Eigen::Vector3d(std::cos(theta), -std::sin(theta), 0.0)};
  s.state = make_state(s.model);
  s.state.v.col(0) = v0 * s.down;
  s.ws = make_workspace(s.model);
  return s;
}

double along(const Slide& s) { return s.down.dot(s.state.x.col(0) - s.model.x0.col(0)); }

double energy(const Slide& s) {
  return 0.5 * s.model.mass[0] * s.state.v.col(0).squaredNorm() - s.model.mass[0] * s.model.gravity.dot(s.state.x.col(0));
}

constexpr Integrator kMethods[] = {Integrator::XPBD, Integrator::SymplecticEuler};

TEST(Friction, AnInclineBelowTheStaticAngleHoldsThePoint) {
  for (const Integrator method : kMethods) {
    const double mu_s = 0.5, theta = std::atan(0.45);  // tan(theta) = 0.45 < mu_s
    Slide s = slide(method, theta, 0.4, mu_s);
    for (int i = 0; i < 5000; ++i) ASSERT_TRUE(step(s.model, s.state, s.ws).finite);  // 1 s
    EXPECT_LT(std::abs(along(s)), 1e-6) << to_string(method);
    EXPECT_LT(s.state.v.col(0).norm(), 1e-6) << to_string(method);
  }
}

TEST(Friction, AboveTheStaticAngleThePointSlidesWithTheKineticDeceleration) {
  for (const Integrator method : kMethods) {
    const double mu_k = 0.3, theta = std::atan(0.6);  // above mu_s = 0.4
    Slide s = slide(method, theta, mu_k, 0.4);
    const double t = 1.0, a = kG * (std::sin(theta) - mu_k * std::cos(theta));
    for (int i = 0; i < 5000; ++i) ASSERT_TRUE(step(s.model, s.state, s.ws).finite);
    EXPECT_NEAR(along(s), 0.5 * a * t * t, 0.02 * 0.5 * a * t * t) << to_string(method);
    EXPECT_NEAR(s.down.dot(s.state.v.col(0)), a * t, 0.02 * a * t) << to_string(method);
  }
}

TEST(Friction, ASlidePointStopsAfterTheClosedFormDistance) {
  for (const Integrator method : kMethods) {
    const double mu = 0.3, v0 = 1.0;  // v0^2 / (2 mu g) = 0.170 m in 0.340 s
    Slide s = slide(method, 0.0, mu, mu, v0);
    for (int i = 0; i < 5000; ++i) ASSERT_TRUE(step(s.model, s.state, s.ws).finite);
    const double expected = v0 * v0 / (2.0 * mu * kG);
    EXPECT_NEAR(along(s), expected, 0.02 * expected) << to_string(method);
    EXPECT_LT(s.state.v.col(0).norm(), 1e-9) << to_string(method);
  }
}

TEST(Friction, NeverAddsEnergy) {
  for (const Integrator method : kMethods)
    for (const double theta : {0.0, 0.3, 0.7}) {
      Slide s = slide(method, theta, 0.2, 0.3, 2.0);
      double last = energy(s);
      for (int i = 0; i < 5000; ++i) {
        ASSERT_TRUE(step(s.model, s.state, s.ws).finite);
        const double e = energy(s);
        // (the penalty's spring holds a little energy at its resting depth: a micro-joule)
        EXPECT_LE(e, last + 1e-6) << to_string(method) << " theta " << theta << " step " << i;
        last = std::min(last, e);
      }
    }
}

}  // namespace
}  // namespace clothsim
