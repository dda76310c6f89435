// Self-contact's hard cases (docs/collision.md, "Self-contact"): a fold closing at 10 m/s, two
// cloths meeting at 10 m/s, two layers pressed onto a floor, a cloth twisted by its pins, and a
// cloth that starts through itself (every step checked with count_self_crossings()); and the
// stage on two threads against one.
#include <clothsim/collision/point_triangle.hpp>
#include <clothsim/model_builder.hpp>
#include <clothsim/self_crossings.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "floor_collider.hpp"
#include "inline_scenes.hpp"

namespace clothsim {
namespace {

// A grid of n x n masses over a 1 m square, mapped through place(u, v) with u, v in [0, 1]:
// its positions, structural springs on the triangles' edges, bend springs across quads.
struct Sheet {
  Eigen::Matrix3Xd x;
  std::vector<SpringSpec> springs;
  std::vector<std::uint32_t> triangles;
};

template <class Place>
Sheet sheet(int n, Place place) {
  Sheet s;
  s.x.resize(3, n * n);
  auto id = [n](int i, int j) { return static_cast<std::uint32_t>(j * n + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) s.x.col(id(i, j)) = place(double(i) / (n - 1), double(j) / (n - 1));
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      s.triangles.insert(s.triangles.end(),
                         {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      s.springs.push_back({id(i, j), id(i + 1, j + 1), 0});
      if (i + 2 < n) s.springs.push_back({id(i, j), id(i + 2, j + 1), 1});
      if (j + 2 < n) s.springs.push_back({id(i, j), id(i + 1, j + 2), 1});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (i + 1 < n) s.springs.push_back({id(i, j), id(i + 1, j), 0});
      if (j + 1 < n) s.springs.push_back({id(i, j), id(i, j + 1), 0});
    }
  return s;
}

// Steps `seconds` (substeps of 0.5 ms), checking after every step that the state is finite
// and no edge passes through a triangle; the most crossings seen, and the stage's counts.
std::size_t run_checked(const Model& m, State& s, double seconds, SelfContactCounts* counts = nullptr) {
  Workspace ws = make_workspace(m);
  ws.substeps = 20;
  std::size_t worst = 0;
  const long steps = std::lround(seconds / m.options.dt) * ws.substeps;
  for (long k = 0; k < steps; ++k) {
    if (!step(m, s, ws).finite) {
      ADD_FAILURE() << "not finite at t = " << s.t;
      break;
    }
    const std::size_t now = count_self_crossings(m, s.x).crossings;
    worst = std::max(worst, now);
  }
  if (counts) *counts = self_contact_counts(ws).value_or(SelfContactCounts{});
  return worst;
}

// The smallest distance between masses of two ranges [a0, a1) and [b0, b1).
double nearest(const Eigen::Matrix3Xd& x, Eigen::Index a0, Eigen::Index a1, Eigen::Index b0, Eigen::Index b1) {
  double d = 1e300;
  for (Eigen::Index i = a0; i < a1; ++i)
    for (Eigen::Index j = b0; j < b1; ++j) d = std::min(d, (x.col(i) - x.col(j)).norm());
  return d;
}

// A strip folded into a U (two flat layers 4 cm apart joined by a half circle), its upper
// layer thrown at the lower one at 10 m/s: the fold closes but the layers never pass.
TEST(SelfContact, AFoldClosingAtTenMetresASecondNeverPasses) {
  Options o;
  o.gravity_y = 0.0;
  const double rho = 0.02, flat = 0.5, len = 2 * flat + std::numbers::pi * rho;
  const Sheet u = sheet(21, [&](double a, double b) {
    const double along = a * len, z = b * 0.5;
    if (along <= flat) return Eigen::Vector3d(along, 0.0, z);
    if (along >= flat + std::numbers::pi * rho) return Eigen::Vector3d(len - along, 2 * rho, z);
    const double phi = (along - flat) / rho;
    return Eigen::Vector3d(flat + rho * std::sin(phi), rho - rho * std::cos(phi), z);
  });
  ModelBuilder b(o, "fold");
  b.add_cloth(u.x, u.springs, {}, u.triangles);
  const Model m = b.build();
  ASSERT_EQ(m.options.self_collision, Switch::On);
  State s = make_state(m);
  for (Eigen::Index k = 0; k < s.x.cols(); ++k)
    if (m.x0(1, k) > 1.5 * rho && m.x0(0, k) < flat - 0.05) s.v(1, k) = -10.0;
  EXPECT_EQ(run_checked(m, s, 0.3), 0u);
  // the layers' masses stay apart (a tenth of the contact distance at least)
  double closest = 1e300;
  for (Eigen::Index k = 0; k < s.x.cols(); ++k)
    for (Eigen::Index l = 0; l < s.x.cols(); ++l)
      if (m.x0(1, k) < 1e-9 && m.x0(1, l) > 1.5 * rho) closest = std::min(closest, (s.x.col(k) - s.x.col(l)).norm());
  EXPECT_GT(closest, 0.1 * m.contact.distance);
}

// Two cloths meeting head-on at 10 m/s (closing speed 20 m/s), the upper turned 45 degrees:
// they stay apart by a part of the contact distance and never cross.
TEST(SelfContact, TwoClothsMeetingHeadOnStayApart) {
  Options o;
  o.gravity_y = 0.0;
  const Sheet lo = sheet(17, [](double a, double b) { return Eigen::Vector3d(a, 0.0, b); });
  const double c = std::cos(std::numbers::pi / 4), sn = std::sin(std::numbers::pi / 4);
  const Sheet hi = sheet(17, [&](double a, double b) {
    const double px = a - 0.5, pz = b - 0.5;
    return Eigen::Vector3d(0.5 + c * px - sn * pz, 0.05, 0.5 + sn * px + c * pz);
  });
  ModelBuilder b(o, "two");
  b.add_cloth(lo.x, lo.springs, {}, lo.triangles);
  b.add_cloth(hi.x, hi.springs, {}, hi.triangles);
  const Model m = b.build();
  State s = make_state(m);
  const Eigen::Index half = lo.x.cols();
  s.v.row(1).head(half).setConstant(10.0);
  s.v.row(1).tail(half).setConstant(-10.0);
  EXPECT_EQ(run_checked(m, s, 0.2), 0u);
  EXPECT_GT(nearest(s.x, 0, half, half, 2 * half), 0.1 * m.contact.distance);
}

// Two layers of n x n masses over a floor, 2 cm apart, the upper 0.8 times as wide.
Model layers_over_floor(int n) {
  Options o;
  const Sheet lo = sheet(n, [](double a, double b) { return Eigen::Vector3d(a - 0.5, 0.05, b - 0.5); });
  const Sheet hi = sheet(n, [](double a, double b) { return Eigen::Vector3d(0.8 * a - 0.4, 0.07, 0.8 * b - 0.4); });
  ModelBuilder b(o, "pressed");
  b.add_cloth(lo.x, lo.springs, {}, lo.triangles);
  b.add_cloth(hi.x, hi.springs, {}, hi.triangles);
  b.set_colliders(test::floor_collider());
  return b.build();
}

// Two layers thrown onto a floor at 10 m/s, the upper pressing the lower against it.
TEST(SelfContact, TwoLayersPressedOntoAFloorStaySeparate) {
  const Model m = layers_over_floor(17);
  State s = make_state(m);
  s.v.row(1).setConstant(-10.0);
  EXPECT_EQ(run_checked(m, s, 1.0), 0u);
  const Eigen::Index half = s.x.cols() / 2;
  EXPECT_GT(s.x.row(1).tail(half).minCoeff(), 0.0);
  EXPECT_GT(nearest(s.x, 0, half, half, 2 * half), 0.1 * m.contact.distance);
}

// The stage on two threads (large enough layers that the holds split between them): the same
// bits as on one, through an impact that holds masses and relaxes the springs around them.
TEST(SelfContact, TwoThreadsGiveTheSameBitsAsOne) {
  const Model m = layers_over_floor(48);
  ASSERT_GE(m.mass_count(), 4096u) << "enough masses for two threads";
  State s1 = make_state(m), s2 = make_state(m);
  s1.v.row(1).setConstant(-10.0), s2.v.row(1).setConstant(-10.0);
  Workspace w1 = make_workspace(m), w2 = make_workspace(m);
  w1.substeps = w2.substeps = 20, w2.threads = 2;
  for (int k = 0; k < 200; ++k) {
    ASSERT_TRUE(step(m, s1, w1).finite && step(m, s2, w2).finite);
    ASSERT_TRUE(s1.x == s2.x && s1.v == s2.v) << "step " << k;
  }
  EXPECT_LT(s1.x.row(1).head(s1.x.cols() / 2).maxCoeff(), 0.01) << "the lower layer lies on the floor";
  EXPECT_EQ(count_self_crossings(m, s1.x).crossings, 0u);
}

// Two upright layers 1 cm apart falling edge first (no drag) as one at 10 m/s and more: their
// gaps do not change, so the bounds follow their common move and one detection does for the fall.
TEST(SelfContact, LayersFallingAsOneNeedOneDetection) {
  Options o;
  const Sheet lo = sheet(17, [](double a, double b) { return Eigen::Vector3d(a, b, 0.0); });
  const Sheet hi = sheet(17, [](double a, double b) { return Eigen::Vector3d(a, b, 0.01); });
  ModelBuilder b(o, "falling");
  b.add_cloth(lo.x, lo.springs, {}, lo.triangles);
  b.add_cloth(hi.x, hi.springs, {}, hi.triangles);
  const Model m = b.build();
  State s = make_state(m);
  s.v.row(1).setConstant(-10.0);
  Workspace ws = make_workspace(m);
  ws.substeps = 20;
  const long steps = std::lround(0.2 / m.options.dt) * ws.substeps;
  for (long k = 0; k < steps; ++k) ASSERT_TRUE(step(m, s, ws).finite);
  EXPECT_LT(s.v.row(1).maxCoeff(), -10.5);  // (it fell 0.2 s, faster and faster)
  EXPECT_EQ(count_self_crossings(m, s.x).crossings, 0u);
  const auto counts = self_contact_counts(ws);
  ASSERT_TRUE(counts.has_value());
  EXPECT_EQ(counts->detections, 1u);
}

// The least distance from a free mass to a triangle of free masses it is not a corner of,
// over its distance at rest where that is less than the contact distance (the pair's target).
double least_gap_part(const Model& m, const Eigen::Matrix3Xd& x) {
  double least = 1e300;
  const auto& t = m.triangles;
  for (Eigen::Index v = 0; v < x.cols(); ++v) {
    if (m.pinned[static_cast<std::size_t>(v)]) continue;
    for (std::size_t k = 0; k + 2 < t.size(); k += 3) {
      const auto a = Eigen::Index{t[k]}, b = Eigen::Index{t[k + 1]}, c = Eigen::Index{t[k + 2]};
      if (a == v || b == v || c == v || m.pinned[t[k]] || m.pinned[t[k + 1]] || m.pinned[t[k + 2]]) continue;
      const double now = std::sqrt(point_triangle(x.col(v), x.col(a), x.col(b), x.col(c)).distance_sq);
      const double rest = std::sqrt(point_triangle(m.x0.col(v), m.x0.col(a), m.x0.col(b), m.x0.col(c)).distance_sq);
      least = std::min(least, now / std::min(m.contact.distance, rest));
    }
  }
  return least;
}

// A square whose two opposite edges turn in opposite senses at pi/3 rad/s (pin_spin, as in the
// twist scene) for 6 s: the cloth wraps around itself into a rope, its layers pressed together,
// and never passes; no gap between free elements closes below its part kSelfLeastGap (0.02)
// of its target. (Later a turning pin drags its edge through the next row: docs/collision.md,
// "Limits".)
Model twisted_square(double spin) {
  Options o;
  o.pin_spin = spin;
  std::vector<std::uint32_t> pins;
  const int n = 21;
  for (int j = 0; j < n; ++j) pins.push_back(static_cast<std::uint32_t>(j * n)), pins.push_back(static_cast<std::uint32_t>(j * n + n - 1));
  return test::square_cloth_pinned(o, n, pins);
}

TEST(SelfContact, AClothTwistedByItsPinsNeverPassesInItsFirstSixSeconds) {
  const Model m = twisted_square(std::numbers::pi / 3.0);
  State s = make_state(m);
  SelfContactCounts counts;
  EXPECT_EQ(run_checked(m, s, 6.0, &counts), 0u);
  EXPECT_GE(least_gap_part(m, s.x), 0.0199);  // (rounding)
  EXPECT_EQ(counts.pin_overruns, 0u) << "no pin came nearer than its step's move";
  EXPECT_LT(counts.split_steps, 120u) << "at most 1 % of the 12 000 steps needed parts";
}

// Pins that turn 60 times as fast move more in a step than the first row's gaps, by more than
// the step's parts could cover: the stage counts the pairs it cannot cover, from the first
// steps on (the run's warning).
TEST(SelfContact, PinsThatTurnPastTheirGapsAreCounted) {
  const Model m = twisted_square(20.0 * std::numbers::pi);
  State s = make_state(m);
  SelfContactCounts counts;
  run_checked(m, s, 0.1, &counts);
  EXPECT_GT(counts.pin_overruns, 0u);
  EXPECT_GE(counts.first_pin_overrun_t, 0.0);
  EXPECT_LT(counts.first_pin_overrun_t, 0.1);
}

// Two cloths that start through each other: the stage keeps them finite and near where they
// were (it cannot undo the crossing and does not fling them apart).
TEST(SelfContact, ClothsThatStartThroughEachOtherStayFinite) {
  Options o;
  o.gravity_y = 0.0;
  const Sheet flat = sheet(11, [](double a, double b) { return Eigen::Vector3d(a, 0.0, b); });
  const Sheet upright = sheet(10, [](double a, double b) { return Eigen::Vector3d(a + 0.013, b - 0.5, 0.51); });
  ModelBuilder b(o, "crossed");
  b.add_cloth(flat.x, flat.springs, {}, flat.triangles);
  b.add_cloth(upright.x, upright.springs, {}, upright.triangles);
  const Model m = b.build();
  ASSERT_GT(count_self_crossings(m, m.x0).crossings, 0u);
  State s = make_state(m);
  run_checked(m, s, 0.5);
  EXPECT_LT((s.x - m.x0).colwise().norm().maxCoeff(), 0.1) << "flung apart";
}

}  // namespace
}  // namespace clothsim
