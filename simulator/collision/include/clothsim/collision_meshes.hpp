// Small procedural meshes for the collision tests and benchmarks (header-only, Eigen only).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace clothsim::meshes {

struct Mesh {
  Eigen::Matrix3Xd vertices;           ///< 3 x V
  std::vector<std::uint32_t> indices;  ///< 3 per triangle, counter-clockwise from the front
  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Icosphere: 20 * 4^levels outward-facing triangles on a sphere of `radius` about `centre`.
inline Mesh icosphere(int levels, double radius = 1.0,
                      const Eigen::Vector3d& centre = Eigen::Vector3d::Zero()) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t},  {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<std::uint32_t> f = {0, 11, 5, 0, 5,  1,  0, 1, 7, 0, 7,  10, 0, 10, 11,
                                  1, 5,  9, 5, 11, 4,  11, 10, 2, 10, 7, 6, 7, 1,  8,
                                  3, 9,  4, 3, 4,  2,  3, 2, 6, 3, 6,  8,  3, 8,  9,
                                  4, 9,  5, 2, 4,  11, 6, 2, 10, 8, 6, 7, 9, 8,  1};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const auto i = static_cast<std::uint32_t>(v.size() - 1);
      mid.emplace(key, i);
      return i;
    };
    std::vector<std::uint32_t> g;
    g.reserve(f.size() * 4);
    for (std::size_t i = 0; i < f.size(); i += 3) {
      const std::uint32_t a = f[i], b = f[i + 1], c = f[i + 2];
      const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      for (std::uint32_t x : {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca}) g.push_back(x);
    }
    f.swap(g);
  }
  Mesh m;
  m.vertices.resize(3, static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    m.vertices.col(static_cast<Eigen::Index>(i)) = centre + radius * v[i];
  m.indices = std::move(f);
  return m;
}

/// A square floor of n x n quads (2 triangles each) at height y, spanning [-half, half] in x
/// and z, facing +y.
inline Mesh floor_grid(int n, double half, double y) {
  Mesh m;
  const int k = n + 1;
  m.vertices.resize(3, k * k);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      m.vertices.col(i * k + j) = Eigen::Vector3d(-half + 2.0 * half * i / n, y,
                                                  -half + 2.0 * half * j / n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto a = static_cast<std::uint32_t>(i * k + j), b = a + 1,
                 c = static_cast<std::uint32_t>((i + 1) * k + j), d = c + 1;
      // (B-A) along +z, (C-A) along +x: z x x = +y.
      for (std::uint32_t x : {a, b, c, c, b, d}) m.indices.push_back(x);
    }
  return m;
}

}  // namespace clothsim::meshes
