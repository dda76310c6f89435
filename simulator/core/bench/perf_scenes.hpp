// Scenes for the performance benchmarks: a triangulated N x N cloth (structural
// springs on every mesh edge, bend springs across every interior edge, the converter's rule)
// lying over a unit icosphere collider, and the memory a Model/State/Workspace holds.
#pragma once

#include <clothsim/collision.hpp>
#include <clothsim/collision_meshes.hpp>
#include <clothsim/model_builder.hpp>
#include <clothsim/step.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace clothsim::perf {

/// Springs of an N x N grid triangulated with one diagonal per quad, ordered as blender2ogl
/// bakes them: structural edges sorted by (a, b), then bend pairs sorted by (a, b).
inline std::vector<SpringSpec> triangulated_grid_springs(int n) {
  auto id = [n](int i, int j) { return static_cast<std::uint64_t>(j * n + i); };
  std::vector<std::uint64_t> tris;  // 3 per triangle
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const std::uint64_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      tris.insert(tris.end(), {a, b, c, a, c, d});
    }
  // (edge key, opposite vertex) for each triangle edge
  std::vector<std::pair<std::uint64_t, std::uint64_t>> edges;
  edges.reserve(tris.size());
  for (std::size_t t = 0; t < tris.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t p = tris[t + e], q = tris[t + (e + 1) % 3], o = tris[t + (e + 2) % 3];
      edges.emplace_back((std::min(p, q) << 32) | std::max(p, q), o);
    }
  std::sort(edges.begin(), edges.end());
  std::vector<std::uint64_t> structural, bend;
  for (std::size_t k = 0; k < edges.size();) {
    std::size_t e = k;
    while (e < edges.size() && edges[e].first == edges[k].first) ++e;
    structural.push_back(edges[k].first);
    if (e - k == 2) {
      const std::uint64_t p = edges[k].second, q = edges[k + 1].second;
      bend.push_back((std::min(p, q) << 32) | std::max(p, q));
    }
    k = e;
  }
  std::sort(bend.begin(), bend.end());
  bend.erase(std::unique(bend.begin(), bend.end()), bend.end());
  std::vector<SpringSpec> out;
  out.reserve(structural.size() + bend.size());
  for (auto k : structural) out.push_back({static_cast<std::uint32_t>(k >> 32), static_cast<std::uint32_t>(k), 0});
  for (auto k : bend) out.push_back({static_cast<std::uint32_t>(k >> 32), static_cast<std::uint32_t>(k), 1});
  return out;
}

/// N x N masses spanning [-1.2, 1.2]^2 in x, z, lying 0.05 m above a unit sphere at the origin
/// (inside the collision band eps = 0.1) where it is under them and at y = 0.05 elsewhere.
inline Eigen::Matrix3Xd draped_grid(int n) {
  Eigen::Matrix3Xd x(3, n * n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double px = -1.2 + 2.4 * i / (n - 1), pz = -1.2 + 2.4 * j / (n - 1);
      const double r2 = px * px + pz * pz;
      x.col(j * n + i) = Eigen::Vector3d(px, std::sqrt(std::max(1.0 - r2, 0.0)) + 0.05, pz);
    }
  return x;
}

/// A unit icosphere collider of 20 * 4^level triangles (level 3: 1280 ... level 8: 1.3M).
inline std::shared_ptr<ColliderSet> sphere_collider(int level) {
  const auto m = meshes::icosphere(level, 1.0);
  auto set = std::make_shared<ColliderSet>();
  set->add_object("sphere", m.vertices, m.indices);
  set->build();
  return set;
}

/// The N x N cloth (no pins), optionally over a collider.
inline Model grid_model(int n, std::shared_ptr<const ColliderSet> colliders = nullptr, Options o = seed_options()) {
  ModelBuilder b(o, "perf_grid");
  const auto springs = triangulated_grid_springs(n);
  b.add_cloth(draped_grid(n), springs, {});
  if (colliders) b.set_colliders(std::move(colliders));
  return b.build();
}

template <class V>
std::size_t vec_bytes(const V& v) {
  return v.size() * sizeof(typename V::value_type);
}

/// Bytes held per mass, by part (the collider's structure is not included).
struct Memory {
  double model = 0, state = 0, workspace = 0;
};
inline Memory memory_per_mass(const Model& m, const State& s, const Workspace& ws) {
  const double n = static_cast<double>(m.mass_count());
  const std::size_t model = m.bytes();
  const std::size_t state = sizeof(double) * static_cast<std::size_t>(s.x.size() + s.v.size());
  const std::size_t work = sizeof(double) * static_cast<std::size_t>(ws.f.size() + ws.pinned_x.size()) +
                           vec_bytes(ws.pinned_index) + vec_bytes(ws.contact_hint) + vec_bytes(ws.spring_f) +
                           (ws.adjacency ? ws.adjacency->bytes() : 0);
  return {static_cast<double>(model) / n, static_cast<double>(state) / n, static_cast<double>(work) / n};
}

}  // namespace clothsim::perf
