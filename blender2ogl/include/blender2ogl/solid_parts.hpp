// Which parts of a triangle mesh are closed solids, which way their faces point, and their
// volume: the one check behind the converter's bake warnings (a collider whose faces point
// inwards) and the simulator's start-up warnings (colliders of scenes made in code, cloth
// that starts inside one). Header-only, C++17, the standard library only.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <unordered_map>
#include <vector>

namespace b2o {

/// One connected part of a mesh (triangles joined through shared corners).
struct SolidPart {
  bool closed = true;               ///< every edge in exactly two triangles
  std::size_t same_direction = 0;   ///< edges whose two triangles both run along them one way
  std::size_t triangles = 0;
  double volume = 0.0;  ///< signed, sum of A.(B x C) / 6 about the mesh's first corner: > 0 outwards
  double size = 0.0;    ///< the largest |coordinate| about that corner (the scale for "zero")
  /// Inside another part of the mesh that is a closed, outward solid: a cavity (a hollow
  /// ball's inner wall), whose faces rightly point into the hollow.
  bool cavity = false;
  /// Closed, every edge used once each way, a volume below zero and no cavity: its faces
  /// point inwards.
  bool inward() const { return closed && same_direction == 0 && !cavity && volume < -1e-9 * size * size * size; }
  /// Closed, but with faces pointing both ways (some edges used twice the same way).
  bool inconsistent() const { return closed && same_direction > 0; }
};

/// The parts of a triangle soup: `corners` holds 9 numbers per triangle (A, B, C, counter-
/// clockwise seen from the front). Corners are joined by exact position (an export splits
/// vertices at UV seams); triangles with two corners at one position are left out (no edge of
/// a closed surface). Parts in the order of their first triangle.
inline std::vector<SolidPart> solid_parts(const double* corners, std::size_t triangles) {
  using Key = std::array<std::uint64_t, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 0x9E3779B97F4A7C15ull;
      for (std::uint64_t x : k) h = (h ^ x) * 0xff51afd7ed558ccdull, h ^= h >> 29;
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_map<Key, std::uint32_t, KeyHash> weld;
  std::vector<const double*> point;
  auto id = [&](const double* p) {
    Key k;
    for (std::size_t c = 0; c < 3; ++c) {
      const double v = p[c] + 0.0;  // -0.0 is the position +0.0
      std::memcpy(&k[c], &v, sizeof v);
    }
    const auto [it, added] = weld.try_emplace(k, static_cast<std::uint32_t>(point.size()));
    if (added) point.push_back(p);
    return it->second;
  };
  std::vector<std::array<std::uint32_t, 3>> tris;
  for (std::size_t t = 0; t < triangles; ++t) {
    const std::array<std::uint32_t, 3> v = {id(corners + 9 * t), id(corners + 9 * t + 3), id(corners + 9 * t + 6)};
    if (v[0] != v[1] && v[1] != v[2] && v[0] != v[2]) tris.push_back(v);
  }
  // connected parts: union-find over the joined corners
  std::vector<std::uint32_t> parent(point.size());
  for (std::uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  struct Directed {
    std::uint64_t key;  // (min << 32) | max
    bool forward;       // min -> max as the triangle runs
  };
  std::vector<Directed> edges;
  edges.reserve(3 * tris.size());
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t a = t[static_cast<std::size_t>(e)], b = t[static_cast<std::size_t>((e + 1) % 3)];
      edges.push_back({(std::min(a, b) << 32) | std::max(a, b), a < b});
      parent[root(static_cast<std::uint32_t>(a))] = root(static_cast<std::uint32_t>(b));
    }
  std::vector<SolidPart> parts;
  std::unordered_map<std::uint32_t, std::size_t> part_index;  // root corner -> part
  auto part_of = [&](std::uint32_t corner) -> SolidPart& {
    const auto [it, added] = part_index.try_emplace(root(corner), parts.size());
    if (added) parts.emplace_back();
    return parts[it->second];
  };
  // volumes about the first corner: the same for a closed surface, with less rounding
  const double* o = tris.empty() ? nullptr : point[tris.front()[0]];
  std::vector<std::size_t> tri_part;  // each triangle's part
  tri_part.reserve(tris.size());
  for (const auto& t : tris) {
    SolidPart& part = part_of(t[0]);
    tri_part.push_back(static_cast<std::size_t>(&part - parts.data()));
    const double *a = point[t[0]], *b = point[t[1]], *c = point[t[2]];
    const double p[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]};
    const double q[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
    const double r[3] = {c[0] - o[0], c[1] - o[1], c[2] - o[2]};
    part.volume += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
                    p[2] * (q[0] * r[1] - q[1] * r[0])) / 6.0;
    for (int k = 0; k < 3; ++k)
      part.size = std::max({part.size, std::fabs(p[k]), std::fabs(q[k]), std::fabs(r[k])});
    ++part.triangles;
  }
  std::sort(edges.begin(), edges.end(), [](const Directed& x, const Directed& y) { return x.key < y.key; });
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    SolidPart& part = part_of(static_cast<std::uint32_t>(edges[i].key >> 32));
    if (j - i != 2)
      part.closed = false;
    else if (edges[i].forward == edges[i + 1].forward)
      ++part.same_direction;
    i = j;
  }
  // Cavities: a part with its faces inwards whose first corner is inside a closed outward part
  // (generalised winding number of that part's triangles > 1/2). Skipped (no part a cavity)
  // when that would take more than ~1e7 triangle tests.
  std::size_t outward_triangles = 0, inward_parts = 0;
  for (const SolidPart& part : parts) {
    const bool consistent = part.closed && part.same_direction == 0;
    if (consistent && part.volume > 0.0) outward_triangles += part.triangles;
    if (consistent && part.volume < 0.0) ++inward_parts;
  }
  if (inward_parts > 0 && outward_triangles * inward_parts <= 10'000'000) {
    std::vector<const double*> first(parts.size(), nullptr);
    for (std::size_t t = 0; t < tris.size(); ++t)
      if (first[tri_part[t]] == nullptr) first[tri_part[t]] = point[tris[t][0]];
    for (std::size_t q = 0; q < parts.size(); ++q) {
      SolidPart& hole = parts[q];
      if (!(hole.closed && hole.same_direction == 0 && hole.volume < 0.0)) continue;
      std::vector<double> angle(parts.size(), 0.0);  // solid angle of each part seen from the corner
      const double* x = first[q];
      for (std::size_t t = 0; t < tris.size(); ++t) {
        const SolidPart& other = parts[tri_part[t]];
        if (tri_part[t] == q || !(other.closed && other.same_direction == 0 && other.volume > 0.0)) continue;
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k)
          a[k] = point[tris[t][0]][k] - x[k], b[k] = point[tris[t][1]][k] - x[k], c[k] = point[tris[t][2]][k] - x[k];
        const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        const double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                           a[2] * (b[0] * c[1] - b[1] * c[0]);
        const double den = la * lb * lc + (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * lc +
                           (b[0] * c[0] + b[1] * c[1] + b[2] * c[2]) * la + (c[0] * a[0] + c[1] * a[1] + c[2] * a[2]) * lb;
        angle[tri_part[t]] += 2.0 * std::atan2(det, den);  // van Oosterom and Strackee
      }
      for (double w : angle)
        if (w > 2.0 * 3.141592653589793) hole.cavity = true;  // winding number > 1/2
    }
  }
  return parts;
}

}  // namespace b2o
