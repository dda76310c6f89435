// The integrators never allocate after their first step (the scratch is made once, on first
// use): this executable replaces the global operator new and counts.
#include "floor_collider.hpp"
#include "inline_scenes.hpp"

#include <clothsim/collision.hpp>
#include <clothsim/integrators.hpp>
#include <clothsim/step.hpp>
#include <gtest/gtest.h>

#include "alloc_counter.hpp"

namespace clothsim {
namespace {

long allocations_in_steps(Integrator method) {
  Options o = seed_options();
  o.integrator = method;
  o.dt = method == Integrator::ExplicitEuler ? 1e-4 : 0.002;
  ModelBuilder mb(o, "grid on a floor");
  const auto springs = test::grid_springs(8, 8);
  mb.add_cloth(test::grid_positions(8, 8, 0.1, 0.12), springs, std::vector<std::uint32_t>{0});
  mb.set_colliders(test::floor_collider());
  const Model m = mb.build();
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  step(m, s, ws);  // warm-up: makes the scratch (and the fast mass-spring factorization)
  const long before = alloc_counter::count();
  for (int i = 0; i < 100; ++i)
    if (!step(m, s, ws).finite) return -1;
  return alloc_counter::count() - before;
}

TEST(Integrators, NeverAllocateAfterTheFirstStep) {
  // all of them, the implicit ones included (matrix-free CG; the prefactored Cholesky's solves)
  for (Integrator method : all_integrators())
    EXPECT_EQ(allocations_in_steps(method), 0) << to_string(method);
}

}  // namespace
}  // namespace clothsim
