// step() never allocates: this executable replaces the global operator new and counts.
#include "floor_collider.hpp"
#include "inline_scenes.hpp"

#include <clothsim/collision.hpp>
#include <clothsim/step.hpp>
#include <gtest/gtest.h>

#include "alloc_counter.hpp"

namespace clothsim {
namespace {

TEST(Step, NeverAllocates) {
  Options o = seed_options();
  ModelBuilder mb(o, "grid on a floor");
  const auto springs = test::grid_springs(10, 10);
  mb.add_cloth(test::grid_positions(10, 10, 0.1, 0.3), springs, std::vector<std::uint32_t>{0});
  mb.set_colliders(test::floor_collider());
  const Model m = mb.build();
  State s = make_state(m);
  const long at_start = alloc_counter::count();
  Workspace ws = make_workspace(m);
  ASSERT_GT(alloc_counter::count() - at_start, 0) << "the counter works: make_workspace allocates";
  s.drag = Drag{55, Eigen::Vector3d(0.5, 1.0, 0.5), 5.0};
  step(m, s, ws);  // warm-up
  const long before = alloc_counter::count();
  for (int i = 0; i < 200; ++i) ASSERT_TRUE(step(m, s, ws).finite);
  EXPECT_EQ(alloc_counter::count() - before, 0);
  EXPECT_GT(ws.last_contacts, 0u);  // the floor was touched, so the penalty path ran
}

}  // namespace
}  // namespace clothsim
