// The high-resolution skirt (16 640 masses): the same cloth as the skirt with 47x the
// masses, so its baked params are the skirt's scaled to keep the cloth's physics (total mass,
// damping and penalty per kilogram, spring stiffness), and it must do what the skirt does.
#include "skirt_behaviour.hpp"

#include <clothsim/stability.hpp>

#include <gtest/gtest.h>
#include <skirt.h>
#include <skirt_hires.h>

namespace clothsim {
namespace {

const b2o::Scene& hires() { return b2o::gen::skirt_hires::scene; }
const b2o::Scene& skirt() { return b2o::gen::skirt::scene; }

TEST(SkirtHiresScene, ParamsAreTheSkirtsScaledToTheResolution) {
  const Model hi = build_model(hires(), scene_options(hires()));
  const Model lo = build_model(skirt(), scene_options(skirt()));
  ASSERT_GE(hi.mass_count(), 16000u);
  const double ratio = static_cast<double>(hi.mass_count()) / static_cast<double>(lo.mass_count());
  const Options &h = hi.options, &l = lo.options;
  EXPECT_NEAR(hi.mass.sum() / lo.mass.sum(), 1.0, 1e-3) << "same total mass";
  EXPECT_NEAR(h.damping / h.mass, l.damping / l.mass, 1e-3 * l.damping / l.mass) << "same damping per kg";
  EXPECT_NEAR(h.k_rep / h.mass, l.k_rep / l.mass, 1e-3 * l.k_rep / l.mass) << "same penalty per kg";
  EXPECT_EQ(h.k_struct, l.k_struct);
  EXPECT_EQ(h.epsilon, l.epsilon);
  EXPECT_NEAR(h.mass * ratio, l.mass, 1e-3 * l.mass);
  // dt within the stability guard's limit, and not far below it (a waste of steps)
  const StabilityReport r = analyse_stability(hi);
  EXPECT_LT(h.dt, 0.95 * r.dt_stable);
  EXPECT_GT(h.dt, 0.7 * r.dt_stable);
}

TEST(SkirtHiresScene, LandsWrapsSlidesOffAndRestsOnTheFloor) {
  test::SkirtRun hi;
  test::check_skirt(hires(), 10, &hi);
}

}  // namespace
}  // namespace clothsim
