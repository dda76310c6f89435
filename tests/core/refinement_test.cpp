// A material behaves alike at any mesh resolution: one square cloth hanging from two corners at
// 20 x 20, 40 x 40 and 80 x 80 quads has the same total mass, sags as far (the mean height of
// its centre of mass over a swing) and swings at the same frequency (the zero crossings of its
// centre of mass under the pins), each within 5 %, and stretches less than 10 %; with
// self-contact on it swings and stretches as without.
#include <clothsim/stability.hpp>
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {

struct Swing {
  double mass = 0.0;    ///< kg
  double sag = 0.0;     ///< m, the mean height of the centre of mass over the second swing
  double period = 0.0;  ///< s, between its first two crossings of z = 0 (under the pins) from z > 0
  double strain = 0.0;  ///< the largest structural strain of the run
};

Swing swing(int n, Switch self_collision = Switch::Off) {
  Options o;
  o.self_collision = self_collision;
  const Model m = test::square_cloth(o, n);
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.substeps = static_cast<int>(std::ceil(m.options.dt / (0.9 * xpbd_step(m))));  // (as clothsim plans it)
  Swing w;
  w.mass = m.mass.sum();
  std::vector<double> crossings;
  double z_last = 0.5, sum = 0.0;
  int count = 0;
  for (int k = 0; k < 350; ++k) {  // 3.5 s of dt 0.01
    for (int q = 0; q < ws.substeps; ++q) EXPECT_TRUE(step(m, s, ws).finite);
    w.strain = std::max(w.strain, max_strain(m, s.x));
    const Eigen::Vector3d com = s.x * m.mass / w.mass;
    if (z_last >= 0.0 && com.z() < 0.0) crossings.push_back(s.t);
    z_last = com.z();
    if (crossings.size() == 1) sum += com.y(), ++count;
  }
  EXPECT_GE(crossings.size(), 2u) << n;
  if (crossings.size() >= 2) w.period = crossings[1] - crossings[0];
  w.sag = count > 0 ? -sum / count : 0.0;
  return w;
}

TEST(Refinement, AHangingClothSagsAndSwingsAlikeAtAnyResolution) {
  const Swing coarse = swing(21), medium = swing(41), fine = swing(81);
  for (const Swing* w : {&coarse, &medium, &fine}) EXPECT_LE(w->strain, 0.10);  // cotton: under 10 %
  for (const Swing* w : {&medium, &fine}) {
    EXPECT_NEAR(w->mass, coarse.mass, 1e-12 * coarse.mass);
    EXPECT_NEAR(w->sag, coarse.sag, 0.05 * coarse.sag);
    EXPECT_NEAR(w->period, coarse.period, 0.05 * coarse.period);
  }
  EXPECT_NEAR(coarse.mass, 0.15, 1e-12);  // cotton, 1 m^2
  EXPECT_GT(coarse.period, 1.0);          // a pendulum of about half a metre
  std::printf("sag %.4f %.4f %.4f m, period %.4f %.4f %.4f s, strain %.3f %.3f %.3f\n", coarse.sag, medium.sag,
              fine.sag, coarse.period, medium.period, fine.period, coarse.strain, medium.strain, fine.strain);
  // with self-contact: the same swing and strain (its bounds do not hold the strain limiter back)
  for (const auto& [n, off] : {std::pair{21, &coarse}, std::pair{41, &medium}, std::pair{81, &fine}}) {
    const Swing on = swing(n, Switch::On);
    EXPECT_NEAR(on.sag, off->sag, 0.05 * off->sag) << n;
    EXPECT_NEAR(on.period, off->period, 0.05 * off->period) << n;
    EXPECT_NEAR(on.strain, off->strain, 0.005) << n;
    std::printf("%d x %d with self-contact: sag %.4f m, period %.4f s, strain %.3f\n", n - 1, n - 1, on.sag, on.period,
                on.strain);
  }
}

}  // namespace
}  // namespace clothsim
