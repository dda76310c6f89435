// A 10 x 10 m floor at y = 0 (two triangles, normals up) for tests that need a collider.
#pragma once

#include <clothsim/collision.hpp>

#include <memory>
#include <vector>

namespace clothsim::test {

inline std::shared_ptr<ColliderSet> floor_collider() {
  auto floor = std::make_shared<ColliderSet>();
  Eigen::Matrix3Xd fv(3, 4);
  fv << -5, 5, 5, -5, 0, 0, 0, 0, -5, -5, 5, 5;
  floor->add_object("floor", fv, std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2});
  floor->build();
  return floor;
}

}  // namespace clothsim::test
