// A collider's topology and what it tells: the triangles across each edge (corners matched
// by position), whether the object is closed, and, behind a face of a closed object beside
// an edge or corner, whether a point is outside after all (the angle-weighted pseudonormal).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::kBlock;
using detail::kMaxCandidates;

void ColliderSet::compute_adjacency(std::size_t o) {
  const Object& ob = objects_[o];
  // Vertices by position: equal coordinates get one id.
  const auto nv = static_cast<std::size_t>(ob.vertices.cols());
  std::vector<std::uint32_t> order(nv), id(nv);
  for (std::size_t i = 0; i < nv; ++i) order[i] = static_cast<std::uint32_t>(i);
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    const auto va = ob.vertices.col(a), vb = ob.vertices.col(b);
    return std::lexicographical_compare(va.data(), va.data() + 3, vb.data(), vb.data() + 3);
  };
  std::sort(order.begin(), order.end(), less);
  for (std::size_t i = 0, next = 0; i < nv; ++i) {
    if (i > 0 && less(order[i - 1], order[i])) ++next;
    id[order[i]] = static_cast<std::uint32_t>(next);
  }
  objects_[o].weld = id;  // (corners of a closed object's sharp features: outside_at_feature())
  // Every edge of every kept triangle, keyed by its two corner ids; an edge of exactly two
  // triangles joins them.
  struct Half {
    std::uint32_t lo, hi, slot, edge;
  };
  std::vector<Half> halves;
  halves.reserve(3 * ob.kept);
  for (std::uint32_t slot = ob.tri_begin; slot < ob.tri_end; ++slot) {
    if (orig_[slot] < 0) continue;
    const auto t = static_cast<std::size_t>(orig_[slot]);
    for (std::uint32_t e = 0; e < 3; ++e) {
      const std::uint32_t a = id[ob.indices[3 * t + e]], b = id[ob.indices[3 * t + (e + 1) % 3]];
      halves.push_back(Half{std::min(a, b), std::max(a, b), slot, e});
    }
  }
  std::sort(halves.begin(), halves.end(), [](const Half& x, const Half& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.slot < y.slot);
  });
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i + 1;
    while (j < halves.size() && halves[j].lo == halves[i].lo && halves[j].hi == halves[i].hi) ++j;
    if (j - i != 2) objects_[o].open = true;  // a rim (or a non-manifold edge)
    if (j - i == 2 && halves[i].slot != halves[i + 1].slot) {
      adj_[3 * halves[i].slot + halves[i].edge] = static_cast<std::int32_t>(halves[i + 1].slot);
      adj_[3 * halves[i + 1].slot + halves[i + 1].edge] = static_cast<std::int32_t>(halves[i].slot);
    }
    i = j;
  }
}

double ColliderSet::contact_distance(const Eigen::Vector3d& p, const ColliderHit& h) const {
  if (!h.valid() || h.object < 0 || static_cast<std::size_t>(h.object) >= objects_.size())
    return std::numeric_limits<double>::quiet_NaN();
  const auto o = static_cast<std::size_t>(h.object);
  const Object& ob = objects_[o];
  if (!(h.signed_distance < 0.0) || ob.open) return h.signed_distance;
  const std::int32_t slot = ob.input_to_kept.at(static_cast<std::size_t>(h.triangle));
  if (slot < 0) return h.signed_distance;
  // as accumulate_penalty()'s respond_at() decides it
  const double* t = tri_ptr(static_cast<std::uint32_t>(slot));
  double d = 0.0, dir[3];
  TriangleRegion region;
  if (detail::edge_contact(p.data(), t, kBlock, false, d, dir, region) == 2 &&
      outside_at_feature(o, p.data(), t, kBlock, region, dir))
    return d;
  return h.signed_distance;
}

bool ColliderSet::outside_at_feature(std::size_t o, const double p[3], const double* t, std::size_t stride,
                                     TriangleRegion region, const double dir[3]) const {
  const Object& ob = objects_[o];
  if (ob.open || ob.weld.empty() || region == TriangleRegion::Face) return false;
  // The answer's slot: from where its data is, or (a cache's copy) among the nearest
  // triangles, the one with the same 12 numbers.
  std::uint32_t slot = std::numeric_limits<std::uint32_t>::max();
  const auto same = [&](std::uint32_t sl) {
    const double* u = tri_ptr(sl);
    for (std::size_t k = 0; k < 12; ++k)
      if (!(u[k * kBlock] == t[k * stride])) return false;
    return true;
  };
  if (stride == kBlock && t >= tri_.data() && t < tri_.data() + tri_.size()) {
    const auto off = static_cast<std::size_t>(t - tri_.data());
    if (off % (12 * kBlock) < kBlock)
      slot = static_cast<std::uint32_t>(off / (12 * kBlock) * kBlock + off % (12 * kBlock));
  } else {
    double s;
    const double d2 = detail::closest_sq<1>(p, t, s);
    std::uint32_t slots[kMaxCandidates];
    double d2s[kMaxCandidates], others = 0.0;
    const std::size_t n =
        query_nearest(o, p, d2 * (1.0 + 1e-9) + 1e-300, QueryMethod::Bvh, kMaxCandidates, {}, slots, d2s, others);
    for (std::size_t j = 0; j < n; ++j)
      if (same(slots[j])) slot = slots[j];
  }
  if (slot < ob.tri_begin || slot >= ob.tri_end || orig_[slot] < 0) return false;
  const auto normal = [&](std::uint32_t sl, double n[3]) {
    const double* u = tri_ptr(sl);
    for (std::size_t k = 0; k < 3; ++k) n[k] = u[(9 + k) * kBlock];
  };
  // The angle-weighted pseudonormal N at the closest point Q (Baerentzen and Aanaes, 2005): on
  // an edge the sum of its two faces' normals, at a corner the sum over the faces around it of
  // each face's angle there times its normal. P is outside the closed mesh iff (P - Q).N > 0.
  double N[3] = {0.0, 0.0, 0.0}, n[3];
  const auto add = [&](std::uint32_t sl, double weight) {
    normal(sl, n);
    for (std::size_t k = 0; k < 3; ++k) N[k] += weight * n[k];
  };
  const auto corner_id = [&](std::uint32_t sl, std::uint32_t c) {
    return ob.weld[ob.indices[3 * static_cast<std::size_t>(orig_[sl]) + c]];
  };
  const auto angle = [&](std::uint32_t sl, std::uint32_t c) {
    const detail::Tri tr = tri_at(sl);
    const Eigen::Vector3d a(tr.ax, tr.ay, tr.az), ab(tr.bx, tr.by, tr.bz), ac(tr.cx, tr.cy, tr.cz);
    const Eigen::Vector3d corners[3] = {a, a + ab, a + ac};
    const Eigen::Vector3d u = corners[(c + 1) % 3] - corners[c], w = corners[(c + 2) % 3] - corners[c];
    return std::atan2(u.cross(w).norm(), u.dot(w));
  };
  if (region == TriangleRegion::EdgeAB || region == TriangleRegion::EdgeBC || region == TriangleRegion::EdgeCA) {
    const std::uint32_t k = region == TriangleRegion::EdgeAB ? 0u : region == TriangleRegion::EdgeBC ? 1u : 2u;
    const std::int32_t nb = adj_[3 * std::size_t{slot} + k];
    if (nb < 0) return false;
    add(slot, 1.0);
    add(static_cast<std::uint32_t>(nb), 1.0);
  } else {
    // Around the corner: across the edge leaving it, into the neighbour, and on across that
    // neighbour's other edge at the corner, until back at the start.
    const std::uint32_t c0 = region == TriangleRegion::VertexA ? 0u : region == TriangleRegion::VertexB ? 1u : 2u;
    const std::uint32_t v = corner_id(slot, c0);
    std::uint32_t sl = slot, c = c0, edge = c0;  // edge c joins corners c and c + 1
    for (int steps = 0;; ++steps) {
      if (steps > 4096) return false;
      add(sl, angle(sl, c));
      const std::uint32_t w = corner_id(sl, edge == c ? (c + 1) % 3 : (c + 2) % 3);  // the edge's other end
      const std::int32_t nb = adj_[3 * std::size_t{sl} + edge];
      if (nb < 0) return false;
      sl = static_cast<std::uint32_t>(nb);
      if (sl == slot) break;
      c = 3;
      for (std::uint32_t j = 0; j < 3; ++j)
        if (corner_id(sl, j) == v) c = j;
      if (c == 3) return false;
      // the shared edge is edge c (c -> c + 1) when its other end is w; leave by the other one
      edge = corner_id(sl, (c + 1) % 3) == w ? (c + 2) % 3 : c;
    }
  }
  const double dot = dir[0] * N[0] + dir[1] * N[1] + dir[2] * N[2];
  return dot > 1e-12 * std::sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
}

}  // namespace clothsim
