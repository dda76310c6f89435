// triangulate: the converter's own triangulation of polygons (faces with more than 3 corners),
// in place of assimp's aiProcess_Triangulate. assimp 5.2.5's ear clipper tests "no other
// corner in the ear" strictly, so a corner on the ear's diagonal does not block the ear: it
// cuts an L-shaped hexagon whose reflex corner lies on a diagonal into 4 triangles of area 4
// (the L has 3), two of them facing down. Here that test is inclusive; convex polygons and quads
// (assimp's rule, the reflex corner found by a cross product's sign instead of acos) get
// assimp's triangles, so their output is unchanged.
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "converter.hpp"

namespace b2o::conv {
namespace {

struct P2 {
  double x, y;
};

// > 0: a, b, c turn left (counter-clockwise); 0: collinear. The coordinates are floats, so
// the differences are exact in double and the products nearly so.
double orient(const P2& a, const P2& b, const P2& c) { return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x); }

bool same(const P2& a, const P2& b) { return a.x == b.x && a.y == b.y; }

}  // namespace

bool triangulate_polygon(std::span<const float> xyz, std::vector<std::uint32_t>& triangles) {
  const std::size_t n = xyz.size() / 3;
  if (n < 3) return true;
  if (n == 3) {
    triangles.insert(triangles.end(), {0u, 1u, 2u});
    return true;
  }
  // Newell's normal, then the projection that drops its largest axis (ties as assimp's),
  // the two remaining axes swapped when that component is negative: counter-clockwise.
  double nx = 0.0, ny = 0.0, nz = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const float* a = &xyz[3 * i];
    const float* b = &xyz[3 * ((i + 1) % n)];
    nx += (double(a[1]) - b[1]) * (double(a[2]) + b[2]);
    ny += (double(a[2]) - b[2]) * (double(a[0]) + b[0]);
    nz += (double(a[0]) - b[0]) * (double(a[1]) + b[1]);
  }
  const double ax = std::fabs(nx), ay = std::fabs(ny), az = std::fabs(nz);
  std::size_t u = 0, v = 1;  // drop z
  double facing = nz;
  if (ax > ay) {
    if (ax > az) u = 1, v = 2, facing = nx;  // drop x
  } else if (ay > az) {
    u = 2, v = 0, facing = ny;  // drop y
  }
  if (facing < 0.0) std::swap(u, v);
  std::vector<P2> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = {xyz[3 * i + u], xyz[3 * i + v]};

  if (n == 4) {
    // assimp's rule: a fan from the reflex corner (a simple quad has at most one), else from
    // corner 0.
    std::uint32_t s = 0;
    int reflex = 0;
    for (std::uint32_t i = 4; i-- > 0;)
      if (orient(p[(i + 3) % 4], p[i], p[(i + 1) % 4]) < 0.0) s = i, ++reflex;
    triangles.insert(triangles.end(), {s, (s + 1) % 4, (s + 2) % 4, s, (s + 2) % 4, (s + 3) % 4});
    return reflex < 2;  // two reflex corners: a bow-tie (a simple quad has at most one)
  }

  // Ear clipping in assimp 5.2's order: the first candidate is corner 0 (its predecessor
  // n - 1); after an ear is cut the next candidate is the corner after it (the predecessor
  // stays), after a failure the one after that. A convex polygon thus gives assimp's
  // triangles: (n-1, 0, 1), (n-1, 1, 2), ..., and the last three corners in index order.
  // An ear is strictly convex and no other remaining corner (at a position other than the
  // ear's three) lies in it or on its boundary. Only corners that are not strictly convex
  // can be in an ear of a simple polygon, so only those are tested.
  std::vector<std::uint32_t> next(n), prev(n);
  for (std::size_t i = 0; i < n; ++i) {
    next[i] = static_cast<std::uint32_t>((i + 1) % n);
    prev[i] = static_cast<std::uint32_t>((i + n - 1) % n);
  }
  std::vector<char> done(n, 0), listed(n, 0);
  std::vector<std::uint32_t> concave;  // corners that were not strictly convex (some may be now)
  auto convex = [&](std::uint32_t i) { return orient(p[prev[i]], p[i], p[next[i]]) > 0.0; };
  for (std::uint32_t i = 0; i < n; ++i)
    if (!convex(i)) concave.push_back(i), listed[i] = 1;

  // Corner tests spent: an adversarial face (a thin ring of thousands of corners) makes the
  // search cubic; past ~1 s of tests it stops and the rest becomes a fan, reported.
  constexpr std::size_t kBudget = 200'000'000;
  std::size_t work = 0;
  auto is_ear = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const P2 &pa = p[a], &pb = p[b], &pc = p[c];
    if (!(orient(pa, pb, pc) > 0.0)) return false;
    work += concave.size();
    for (std::size_t k = 0; k < concave.size();) {
      const std::uint32_t r = concave[k];
      if (done[r] || convex(r)) {  // cut, or convex now: drop from the list
        listed[r] = 0;
        concave[k] = concave.back();
        concave.pop_back();
        continue;
      }
      ++k;
      const P2& q = p[r];
      if (same(q, pa) || same(q, pb) || same(q, pc)) continue;
      if (orient(pa, pb, q) >= 0.0 && orient(pb, pc, q) >= 0.0 && orient(pc, pa, q) >= 0.0) return false;
    }
    return true;
  };

  std::size_t remaining = n, failures = 0;
  bool simple = true;
  std::uint32_t before = static_cast<std::uint32_t>(n - 1), ear = 0;
  while (remaining > 3) {
    const std::uint32_t after = next[ear];
    if (work > kBudget) {
      simple = false;
      break;
    }
    if (!is_ear(before, ear, after)) {
      if (++failures >= remaining) {  // every remaining corner tried: no ear
        simple = false;
        break;
      }
      before = ear;
      ear = after;
      continue;
    }
    triangles.insert(triangles.end(), {before, ear, after});
    done[ear] = 1;
    next[before] = after;
    prev[after] = before;
    --remaining;
    failures = 0;
    for (std::uint32_t k : {before, after})
      if (!listed[k] && !convex(k)) concave.push_back(k), listed[k] = 1;
    ear = after;
  }
  // The last three corners in index order (assimp's), or, when no ear was found, a fan of
  // the remaining corners from the first of them.
  std::uint32_t first = 0;
  while (done[first]) ++first;
  for (std::uint32_t b = next[first], c = next[b]; c != first; b = c, c = next[c])
    triangles.insert(triangles.end(), {first, b, c});
  return simple;
}

}  // namespace b2o::conv
