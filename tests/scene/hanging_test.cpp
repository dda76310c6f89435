// The hanging cloth with its own baked params: hangs from its two pins and comes to rest.
#include "scene_run.hpp"

#include <gtest/gtest.h>
#include <hanging.h>

#include <cstring>

namespace clothsim {
namespace {

const b2o::Scene& scene() { return b2o::gen::hanging::scene; }

TEST(HangingScene, HangsFromItsTwoPinsAndComesToRest) {
  EXPECT_TRUE(read_scene_params(scene()).unknown.empty());
  const Options o = scene_options(scene());
  EXPECT_LT(o.dt, Options{}.dt) << "the hanging scene bakes its own (smaller) dt";
  const Model m = build_model(scene(), o);
  ASSERT_EQ(m.cloths.size(), 1u);
  std::vector<Eigen::Index> pins;
  for (std::size_t i = 0; i < m.pinned.size(); ++i)
    if (m.pinned[i]) pins.push_back(static_cast<Eigen::Index>(i));
  ASSERT_EQ(pins.size(), 2u);

  State s = make_state(m);
  Workspace ws = make_workspace(m);
  const int steps = static_cast<int>(std::lround(20.0 / o.dt));
  for (int i = 1; i <= steps; ++i) ASSERT_TRUE(step(m, s, ws).finite) << "step " << i;

  for (auto p : pins)
    EXPECT_EQ(std::memcmp(s.x.col(p).data(), m.x0.col(p).data(), 3 * sizeof(double)), 0) << "pin " << p << " moved";
  EXPECT_LT(kinetic_energy(m, s), 1e-4) << "not at rest after 20 s";
  // a 2 m square hanging from two corners of one edge reaches about 2 m below them
  const double top = m.x0.row(1).maxCoeff();
  const double drop = top - s.x.row(1).minCoeff();
  EXPECT_GT(drop, 1.8);
  EXPECT_LT(drop, 2.2) << "stretches too much";
  double max_strain = 0.0;
  for (std::size_t k = 0; k < m.spring_count(); ++k)
    if (m.spring_kind[k] == 0)
      max_strain = std::max(max_strain, (s.x.col(m.spring_a[k]) - s.x.col(m.spring_b[k])).norm() /
                                            m.rest_length0[static_cast<Eigen::Index>(k)]);
  EXPECT_LT(max_strain, 1.1);
}

}  // namespace
}  // namespace clothsim
