// Tiny scenes built in code for the core's tests.
#pragma once

#include <clothsim/model_builder.hpp>

#include <vector>

namespace clothsim::test {

/// A w x h grid in the XZ plane at height y0, spacing d, with structural springs along rows
/// and columns and bend springs to every other point (report fig. 3, rectangular grid).
inline Eigen::Matrix3Xd grid_positions(int w, int h, double d, double y0) {
  Eigen::Matrix3Xd x(3, w * h);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) x.col(j * w + i) = Eigen::Vector3d(i * d, y0, j * d);
  return x;
}

inline std::vector<SpringSpec> grid_springs(int w, int h) {
  std::vector<SpringSpec> s;
  auto id = [w](int i, int j) { return static_cast<std::uint32_t>(j * w + i); };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      if (i + 1 < w) s.push_back({id(i, j), id(i + 1, j), 0});
      if (j + 1 < h) s.push_back({id(i, j), id(i, j + 1), 0});
    }
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      if (i + 2 < w) s.push_back({id(i, j), id(i + 2, j), 1});
      if (j + 2 < h) s.push_back({id(i, j), id(i, j + 2), 1});
    }
  return s;
}

inline Model grid_model(const Options& o, int w, int h, std::vector<std::uint32_t> pins = {}) {
  ModelBuilder b(o, "grid");
  const auto springs = grid_springs(w, h);
  b.add_cloth(grid_positions(w, h, 0.1, 0.0), springs, pins);
  return b.build();
}

}  // namespace clothsim::test
