// Pins that turn (the option pin_spin): every group of pinned masses turns about the axis from
// its cloth's centre through the group's centre, so that a square pinned along two opposite
// edges is twisted; against the closed form (Rodrigues' rotation of the rest positions).
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {

constexpr int kN = 11;  // points a side of the 1 m square

// The square with its two edges x = 0 and x = 1 pinned (all points i = 0 and i = n - 1).
Model edges_pinned(const Options& o) {
  std::vector<std::uint32_t> pins;
  for (int j = 0; j < kN; ++j)
    pins.insert(pins.end(), {static_cast<std::uint32_t>(j * kN), static_cast<std::uint32_t>(j * kN + kN - 1)});
  return test::square_cloth_pinned(o, kN, pins);
}

// Runs `seconds` with the planned substeps; false when a state was not finite.
bool run(const Model& m, State& s, double seconds) {
  Workspace ws = make_workspace(m);
  ws.substeps = plan_substeps(m.options.dt, analyse_stability(m).dt_stable, SubstepPolicy{}).substeps;
  const long steps = std::lround(seconds / m.options.dt) * ws.substeps;
  for (long k = 0; k < steps; ++k)
    if (!step(m, s, ws).finite) return false;
  return true;
}

// p turned by `angle` about the unit axis u through c, right-handed.
Eigen::Vector3d turned(const Eigen::Vector3d& p, const Eigen::Vector3d& c, const Eigen::Vector3d& u, double angle) {
  const Eigen::Vector3d r = p - c;
  return c + std::cos(angle) * r + std::sin(angle) * u.cross(r) + (1.0 - std::cos(angle)) * u.dot(r) * u;
}

TEST(PinSpin, TwistedEdgesAreAtTheClosedFormAngle) {
  Options o;
  o.pin_spin = std::numbers::pi / 3.0;
  const Model m = edges_pinned(o);
  State s = make_state(m);
  ASSERT_TRUE(run(m, s, 2.0));
  const Eigen::Vector3d centre(0.5, 0.0, 0.5);  // the mean of the rest positions
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    if (!m.pinned[i]) continue;
    const auto c = static_cast<Eigen::Index>(i);
    // the edge x = 0 turns about -x, the edge x = 1 about +x (each about its outward axis)
    const Eigen::Vector3d u(m.x0(0, c) < 0.5 ? -1.0 : 1.0, 0.0, 0.0);
    const Eigen::Vector3d want = turned(m.x0.col(c), centre, u, o.pin_spin * s.t);
    EXPECT_LT((s.x.col(c) - want).norm(), 1e-9) << "pin " << i;
    const Eigen::Vector3d v = o.pin_spin * u.cross(want - centre);
    EXPECT_LT((s.v.col(c) - v).norm(), 1e-9) << "pin " << i;
  }
  EXPECT_TRUE(s.x.allFinite());
}

TEST(PinSpin, OppositeEdgesTurnInOppositeSenses) {
  Options o;
  o.pin_spin = std::numbers::pi / 3.0;
  const Model m = edges_pinned(o);
  State s = make_state(m);
  ASSERT_TRUE(run(m, s, 0.5));
  // the corners at z = 1 of both edges: each edge's angle about +x, seen from the centre
  const auto angle = [&](Eigen::Index i) { return std::atan2(s.x(1, i), s.x(2, i) - 0.5); };
  const Eigen::Index left = (kN - 1) * kN, right = (kN - 1) * kN + kN - 1;
  const double turn = o.pin_spin * s.t;
  EXPECT_NEAR(angle(left), turn, 1e-9) << "the edge x = 0 turns right-handed about -x: up at z = 1";
  EXPECT_NEAR(angle(right), -turn, 1e-9) << "the edge x = 1 turns right-handed about +x: down at z = 1";
  EXPECT_GT(s.x(1, left), 0.0);
  EXPECT_LT(s.x(1, right), 0.0);
}

TEST(PinSpin, ZeroKeepsEveryPinsBits) {
  const Options o;  // pin_spin 0
  const Model m = edges_pinned(o);
  EXPECT_EQ(m.pin_axis.cols(), 0) << "no spin: no pin table";
  State s = make_state(m);
  ASSERT_TRUE(run(m, s, 1.0));
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    if (!m.pinned[i]) continue;
    const auto c = static_cast<Eigen::Index>(i);
    EXPECT_EQ(std::memcmp(s.x.col(c).data(), m.x0.col(c).data(), 3 * sizeof(double)), 0) << "pin " << i << " moved";
    EXPECT_TRUE((s.v.col(c).array() == 0.0).all()) << "pin " << i;
  }
}

TEST(PinSpin, AGroupOnItsClothsCentreStaysPut) {
  Options o;
  o.pin_spin = 1.0;
  const auto centre = static_cast<std::uint32_t>((kN / 2) * kN + kN / 2);  // (0.5, 0, 0.5)
  const Model m = test::square_cloth_pinned(o, kN, {centre});
  ASSERT_EQ(m.pin_axis.cols(), 1);
  EXPECT_TRUE(m.pin_axis.col(0).isZero()) << "no outward axis";
  State s = make_state(m);
  ASSERT_TRUE(run(m, s, 0.5));
  EXPECT_EQ(s.x.col(centre), m.x0.col(centre));
}

}  // namespace
}  // namespace clothsim
