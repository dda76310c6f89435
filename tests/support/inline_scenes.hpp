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

/// A 1 m square cloth of n x n points in the XZ plane at y = 0 (point (i, j) is mass j n + i,
/// at x = i / (n - 1), z = j / (n - 1)), triangulated (two triangles a quad), with structural
/// springs on the triangles' edges and bend springs across the quads' shared edges; pinned at
/// `pins` (its masses and spring constants come from the areas: a material's cloth).
inline Model square_cloth_pinned(const Options& o, int n, const std::vector<std::uint32_t>& pins) {
  Eigen::Matrix3Xd x(3, n * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.col(j * n + i) = Eigen::Vector3d(double(i) / (n - 1), 0.0, double(j) / (n - 1));
  auto id = [n](int i, int j) { return static_cast<std::uint32_t>(j * n + i); };
  std::vector<SpringSpec> s;
  std::vector<std::uint32_t> t;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      t.insert(t.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      s.push_back({id(i, j), id(i + 1, j + 1), 0});  // the diagonal
      if (i + 2 < n) s.push_back({id(i, j), id(i + 2, j + 1), 1});  // across the edge (i+1, j)-(i+1, j+1)
      if (j + 2 < n) s.push_back({id(i, j), id(i + 1, j + 2), 1});  // across the edge (i, j+1)-(i+1, j+1)
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (i + 1 < n) s.push_back({id(i, j), id(i + 1, j), 0});
      if (j + 1 < n) s.push_back({id(i, j), id(i, j + 1), 0});
    }
  ModelBuilder b(o, "square");
  b.add_cloth(x, s, pins, t);
  return b.build();
}

/// square_cloth_pinned() pinned at its two corners at z = 0 unless `pinned` is false.
inline Model square_cloth(const Options& o, int n, bool pinned = true) {
  const auto last = static_cast<std::uint32_t>(n - 1);
  return square_cloth_pinned(o, n, pinned ? std::vector<std::uint32_t>{0, last} : std::vector<std::uint32_t>{});
}

}  // namespace clothsim::test
