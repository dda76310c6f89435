// The bytes a mass costs in the Model and the State: a material's cloth stores its springs'
// scales, its faces and, pinned, its long-range attachments (16 B a mass) besides the seed
// model's arrays, and its rest lengths in float; within 25 % of the seed model's arrays in
// double (positions, masses, inverse masses, pin flags, 17 B a spring; positions and
// velocities: 191 B a mass on the 512 x 512 grid, docs/performance.md "Memory") on one mesh.
#include <clothsim/step.hpp>

#include <gtest/gtest.h>

#include <iostream>

#include "inline_scenes.hpp"

namespace clothsim {
namespace {

double bytes_per_mass(const Model& m) {
  const State s = make_state(m);
  const auto state = sizeof(double) * static_cast<std::size_t>(s.x.size() + s.v.size());
  return static_cast<double>(m.bytes() + state) / static_cast<double>(m.mass_count());
}

TEST(Memory, AMaterialsClothStaysWithinAQuarterOfTheSeedModels) {
  const Model m = test::square_cloth(Options{}, 200, false);
  const double springs = static_cast<double>(m.spring_count()) / static_cast<double>(m.mass_count());
  const double seed = 24 + 8 + 8 + 1 + 17 * springs + 48;
  const double free = bytes_per_mass(m);
  EXPECT_LE(free, 1.25 * seed) << "the seed model's arrays: " << seed << " B per mass";
  const double pinned = bytes_per_mass(test::square_cloth(Options{}, 200, true));
  EXPECT_NEAR(pinned - free, 2.0 * (sizeof(std::uint32_t) + sizeof(float)), 0.5);
  EXPECT_LE(pinned, 1.25 * seed) << "the seed model's arrays: " << seed << " B per mass";
  std::cout << "bytes per mass: " << free << " free, " << pinned << " pinned at two corners\n";
}

}  // namespace
}  // namespace clothsim
