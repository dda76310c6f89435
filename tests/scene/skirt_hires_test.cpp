// The high-resolution skirt (16 640 masses): the same cloth as the skirt, baked with the same
// material line and nothing scaled by hand; it must weigh, drape and behave as the skirt does.
#include "skirt_behaviour.hpp"

#include <clothsim/stability.hpp>

#include <gtest/gtest.h>
#include <skirt.h>

#include <cmath>
#include <iostream>
#include <skirt_hires.h>

namespace clothsim {
namespace {

const b2o::Scene& hires() { return b2o::gen::skirt_hires::scene; }
const b2o::Scene& skirt() { return b2o::gen::skirt::scene; }

TEST(SkirtHiresScene, BakedWithTheSkirtsMaterialLine) {
  const Options hi = scene_options(hires()), lo = scene_options(skirt());
  for (const OptionInfo& row : option_table()) EXPECT_EQ(row.text(hi), row.text(lo)) << row.name;
  const Model h = build_model(hires(), hi), l = build_model(skirt(), lo);
  ASSERT_GE(h.mass_count(), 16000u);
  EXPECT_NEAR(h.mass.sum() / l.mass.sum(), 1.0, 0.01) << "the same cloth weighs the same";
}

// A cloth with the defaults (cotton) drapes the same at both resolutions, within 10 % of the
// cloth's size at 1, 2 and 3 s: the centre of mass and the bounding box's corners.
TEST(SkirtHiresScene, DrapesAsTheSkirtAt1And2And3Seconds) {
  const Model h = build_model(hires(), Options{}), l = build_model(skirt(), Options{});
  const double size = (l.x0.rowwise().maxCoeff() - l.x0.rowwise().minCoeff()).norm();
  State sh = make_state(h), sl = make_state(l);
  Workspace wh = test::planned_workspace(h), wl = test::planned_workspace(l);
  const int per_second = static_cast<int>(std::lround(1.0 / l.options.dt));
  for (int second = 1; second <= 3; ++second) {
    for (int i = 0; i < per_second; ++i) ASSERT_TRUE(test::step_dt(h, sh, wh) && test::step_dt(l, sl, wl));
    const Eigen::Vector3d dc = sh.x.rowwise().mean() - sl.x.rowwise().mean();
    const Eigen::Vector3d dlo = sh.x.rowwise().minCoeff() - sl.x.rowwise().minCoeff();
    const Eigen::Vector3d dhi = sh.x.rowwise().maxCoeff() - sl.x.rowwise().maxCoeff();
    std::cout << second << " s: centres " << dc.norm() << " m apart, boxes " << dlo.norm() << ", " << dhi.norm()
              << " m (cloth size " << size << " m)\n";
    EXPECT_LT(dc.norm(), 0.1 * size) << "centres at " << second << " s";
    EXPECT_LT(dlo.norm(), 0.1 * size) << "lower corners at " << second << " s";
    EXPECT_LT(dhi.norm(), 0.1 * size) << "upper corners at " << second << " s";
  }
}

TEST(SkirtHiresScene, LandsWrapsSlidesOffAndRestsOnTheFloor) {
  test::SkirtRun hi;
  test::check_skirt(hires(), 10, &hi);
}

}  // namespace
}  // namespace clothsim
