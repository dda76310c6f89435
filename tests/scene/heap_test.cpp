// The heap scene: a 0.25 m x 3 m strip let go end first 0.3 m above a floor folds onto itself
// and ends at rest on the floor, in a heap much smaller than its length, its layers apart.
#include "scene_run.hpp"

#include <gtest/gtest.h>
#include <heap.h>

#include <cmath>
#include <iostream>

namespace clothsim {
namespace {

TEST(HeapScene, TheStripEndsInAHeapOnTheFloorAtRest) {
  const b2o::Scene& scene = b2o::gen::heap::scene;
  const Model m = build_model(scene, scene_options(scene));
  EXPECT_EQ(m.options.material, Material::Cotton);
  // the strip's length (it lies in the y-z plane, tilted) and width (along x)
  const double length = std::hypot(m.x0.row(1).maxCoeff() - m.x0.row(1).minCoeff(),
                                   m.x0.row(2).maxCoeff() - m.x0.row(2).minCoeff());
  const double width = m.x0.row(0).maxCoeff() - m.x0.row(0).minCoeff();
  const State s = test::run_for(m, 5.0);
  ASSERT_TRUE(s.x.allFinite());
  const double lowest = s.x.row(1).minCoeff(), highest = s.x.row(1).maxCoeff();
  const double dx = s.x.row(0).maxCoeff() - s.x.row(0).minCoeff();
  const double dz = s.x.row(2).maxCoeff() - s.x.row(2).minCoeff();
  const double ke = kinetic_energy(m, s);
  std::cout << "heap: y " << lowest << " .. " << highest << " m, on the floor " << dx << " x " << dz
            << " m (the strip is " << length << " m long), kinetic energy " << ke << " J, max strain "
            << 100.0 * max_strain(m, s.x) << " %\n";
  EXPECT_GE(lowest, -m.contact.band) << "through the floor";
  EXPECT_LT(highest, 0.3) << "not down on the floor";
  EXPECT_LT(ke, 1e-3) << "still moving after 5 s";
  EXPECT_LT(std::max(dx, dz), 0.5 * length) << "lies out flat instead of heaping";
  // several layers, each kept apart by self-contact: the heap stands many contact distances
  // high and covers (its bounding box) no more floor than the strip's own area
  EXPECT_GT(highest - lowest, 10.0 * m.contact.distance) << "one layer, not a heap";
  EXPECT_LT(dx * dz, 1.1 * length * width) << "spread out, not a heap";
}

}  // namespace
}  // namespace clothsim
