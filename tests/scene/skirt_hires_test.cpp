// The high-resolution skirt (16 640 masses): the same cloth as the skirt, baked with the same
// material line and nothing scaled by hand; it must weigh, drape and behave as the skirt does.
#include "skirt_behaviour.hpp"

#include <gtest/gtest.h>
#include <skirt.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <utility>
#include <vector>
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

// Where the cloth spreads along each axis: the 5th and 95th percentiles of its masses (a
// single flap does not move them).
std::pair<Eigen::Vector3d, Eigen::Vector3d> spread(const Eigen::Matrix3Xd& x) {
  Eigen::Vector3d lo, hi;
  std::vector<double> v(static_cast<std::size_t>(x.cols()));
  for (int r = 0; r < 3; ++r) {
    for (Eigen::Index k = 0; k < x.cols(); ++k) v[static_cast<std::size_t>(k)] = x(r, k);
    std::sort(v.begin(), v.end());
    lo[r] = v[v.size() / 20];
    hi[r] = v[v.size() - 1 - v.size() / 20];
  }
  return {lo, hi};
}

// A cloth with the defaults (cotton) drapes the same at both resolutions, within 10 % of the
// cloth's size at 1, 2 and 3 s: its centre of mass and its spread along each axis.
TEST(SkirtHiresScene, DrapesAsTheSkirtAt1And2And3Seconds) {
  Options o;
  o.self_collision = Switch::Off;  // (its cost at 16 640 masses: docs/performance.md, "Self-contact")
  const Model h = build_model(hires(), o), l = build_model(skirt(), o);
  const double size = (l.x0.rowwise().maxCoeff() - l.x0.rowwise().minCoeff()).norm();
  State sh = make_state(h), sl = make_state(l);
  Workspace wh = test::planned_workspace(h), wl = test::planned_workspace(l);
  const int per_second = static_cast<int>(std::lround(1.0 / l.options.dt));
  for (int second = 1; second <= 3; ++second) {
    for (int i = 0; i < per_second; ++i) ASSERT_TRUE(test::step_dt(h, sh, wh) && test::step_dt(l, sl, wl));
    const Eigen::Vector3d dc = sh.x.rowwise().mean() - sl.x.rowwise().mean();
    const auto [hlo, hhi] = spread(sh.x);
    const auto [llo, lhi] = spread(sl.x);
    std::cout << second << " s: centres " << dc.norm() << " m apart, spreads " << (hlo - llo).norm() << ", "
              << (hhi - lhi).norm() << " m (cloth size " << size << " m)\n";
    EXPECT_LT(dc.norm(), 0.1 * size) << "centres at " << second << " s";
    EXPECT_LT((hlo - llo).norm(), 0.1 * size) << "lower spread at " << second << " s";
    EXPECT_LT((hhi - lhi).norm(), 0.1 * size) << "upper spread at " << second << " s";
  }
}

// The seed's story at 16 640 masses, without self-contact (its cost: docs/performance.md).
TEST(SkirtHiresScene, LandsWrapsSlidesOffAndRestsOnTheFloor) {
  test::SkirtRun hi;
  test::check_skirt(hires(), 10, &hi, Switch::Off);
}

// With self-contact (the scene's default): no layer passes through another in any frame
// 0.05 s apart while the skirt falls onto the sphere and starts to wrap it.
TEST(SkirtHiresScene, NoSelfCrossingWhileItLandsAndWraps) {
  const Model m = build_model(hires(), scene_options(hires()));
  ASSERT_EQ(m.options.self_collision, Switch::On);
  State s = make_state(m);
  Workspace ws = test::planned_workspace(m);
  for (long i = 1; i <= std::lround(0.6 / m.options.dt); ++i) {
    ASSERT_TRUE(test::step_dt(m, s, ws)) << "step " << i;
    if (test::crossing_frame(m, i)) {
      ASSERT_EQ(test::expect_no_crossings(m, s), 0u);
    }
  }
}

}  // namespace
}  // namespace clothsim
