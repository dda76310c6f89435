// The twist scene (NVIDIA Warp's example_cloth_self_contact): a 1 m square pinned along two
// opposite edges that turn in opposite senses at pi/3 rad/s. After 1.5 s the edges are at the
// closed-form angle, the cloth between them is within reach of its pins and has never passed
// through itself.
#include "scene_run.hpp"

#include <gtest/gtest.h>
#include <twist.h>

#include <iostream>
#include <numbers>

namespace clothsim {
namespace {

TEST(TwistScene, EdgesTurnToTheClosedFormAngleAndTheClothFollows) {
  const b2o::Scene& scene = b2o::gen::twist::scene;
  const Options o = scene_options(scene);
  EXPECT_EQ(o.pin_spin, std::numbers::pi / 3.0) << "the scene bakes pin_spin";
  const Model m = build_model(scene, o);
  EXPECT_EQ(m.options.material, Material::Cotton);
  std::vector<Eigen::Index> pins;
  for (std::size_t i = 0; i < m.pinned.size(); ++i)
    if (m.pinned[i]) pins.push_back(static_cast<Eigen::Index>(i));
  ASSERT_EQ(pins.size(), 2u * 41u) << "both edges, every vertex";

  // (the first 1.5 s; the whole 10 s takes minutes: docs/scenes.md, "twist")
  const double seconds = 1.5;
  const State s = test::run_for(m, seconds);
  ASSERT_TRUE(s.x.allFinite());
  EXPECT_NEAR(s.t, seconds, 1e-9);
  // each edge turns right-handed about its outward axis (-x for the edge at x = -0.5, +x for
  // the one at +0.5) through the cloth's centre
  const Eigen::Vector3d centre = m.x0.rowwise().mean();
  const double angle = o.pin_spin * s.t;
  for (const Eigen::Index p : pins) {
    const Eigen::Vector3d u(m.x0(0, p) < centre.x() ? -1.0 : 1.0, 0.0, 0.0);
    const Eigen::Vector3d r = m.x0.col(p) - centre;
    const Eigen::Vector3d want =
        centre + std::cos(angle) * r + std::sin(angle) * u.cross(r) + (1.0 - std::cos(angle)) * u.dot(r) * u;
    EXPECT_LT((s.x.col(p) - want).norm(), 1e-9) << "pin " << p;
  }
  // within reach: every mass is closer to a pin than 1.3 times its rest distance to the
  // nearest pin (its edge: the cloth's strain limit and long-range attachments hold it), and
  // none passes beyond the pinned edges
  double worst = 0.0;
  for (Eigen::Index i = 0; i < s.x.cols(); ++i) {
    double now = 1e300, rest = 1e300;
    for (const Eigen::Index p : pins) {
      now = std::min(now, (s.x.col(i) - s.x.col(p)).norm());
      rest = std::min(rest, (m.x0.col(i) - m.x0.col(p)).norm());
    }
    if (rest > 0.0) worst = std::max(worst, now / rest);
    EXPECT_LE(now, 1.3 * rest + 0.01) << "mass " << i << " is out of its pins' reach";
    EXPECT_LE(std::abs(s.x(0, i) - centre.x()), 0.5 + 0.01) << "mass " << i << " beyond the edges";
  }
  std::cout << "twist: farthest from its pins " << worst << " x its rest distance; max strain "
            << 100.0 * max_strain(m, s.x) << " %\n";
}

}  // namespace
}  // namespace clothsim
