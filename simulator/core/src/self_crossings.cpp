// Self-crossings of a triangle mesh (clothsim/self_crossings.hpp): weld by position, take each
// welded edge once, find the triangles near each edge with a BVH over the triangles' boxes,
// and test the pairs that share no vertex with filtered orientation predicates.
#include <clothsim/self_crossings.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {

namespace {

using Vec = Eigen::Vector3d;

// Signed volume (times 6) of the tetrahedron abcd, (a - d) . ((b - d) x (c - d)), or 0 when
// its rounding could hide the sign: Shewchuk's first error bound (Adaptive Precision
// Floating-Point Arithmetic, 1997: orient3d's errboundA) makes every nonzero answer's sign
// exact, so points coplanar in the doubles (a tilted flat sheet) are never on opposite sides.
double orient(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  constexpr double eps = 0x1p-53;  // half a unit in the last place of 1
  constexpr double bound = (7.0 + 56.0 * eps) * eps;
  const Vec ad = a - d, bd = b - d, cd = c - d;
  const double bxcy = bd.x() * cd.y(), cxby = cd.x() * bd.y();
  const double cxay = cd.x() * ad.y(), axcy = ad.x() * cd.y();
  const double axby = ad.x() * bd.y(), bxay = bd.x() * ad.y();
  const double det = ad.z() * (bxcy - cxby) + bd.z() * (cxay - axcy) + cd.z() * (axby - bxay);
  const double permanent = (std::abs(bxcy) + std::abs(cxby)) * std::abs(ad.z()) +
                           (std::abs(cxay) + std::abs(axcy)) * std::abs(bd.z()) +
                           (std::abs(axby) + std::abs(bxay)) * std::abs(cd.z());
  return std::abs(det) > bound * permanent ? det : 0.0;
}

// A strict order on positions, so that a predicate on two points gives the same answer
// whichever order they come in (the line through an edge shared by two triangles is on one
// side of it for both).
bool before(const Vec& u, const Vec& v) {
  return std::lexicographical_compare(u.data(), u.data() + 3, v.data(), v.data() + 3);
}

// The orientation of line pq against the triangle edge uv, the same up to sign for vu.
double line_side(const Vec& p, const Vec& q, const Vec& u, const Vec& v) {
  return before(v, u) ? -orient(p, q, v, u) : orient(p, q, u, v);
}

// Welding key: a position's bits, -0.0 as 0.0.
using Key = std::array<std::uint64_t, 3>;
Key key_of(const Vec& p) {
  Key k{};
  for (int i = 0; i < 3; ++i) k[static_cast<std::size_t>(i)] = std::bit_cast<std::uint64_t>(p[i] + 0.0);
  return k;
}
std::uint64_t hash_of(const Key& k) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (std::uint64_t b : k) h = (h ^ b ^ (h >> 31)) * 0xff51afd7ed558ccdull;
  return h ^ (h >> 29);
}

// The mesh over welded vertices: positions, non-degenerate triangles, unique edges, the
// triangles each edge belongs to (edge e's are tri_of_edge[edge_first[e] .. edge_first[e+1]),
// lowest first) and each triangle's edges (triangle t's at tri_edges[3 t ..]).
struct Welded {
  std::vector<Vec> pos;
  std::vector<std::array<std::uint32_t, 3>> tris;
  std::vector<std::array<std::uint32_t, 2>> edges;
  std::vector<std::uint32_t> edge_first, tri_of_edge, tri_edges;
};

constexpr std::uint32_t kNone = 0xffffffffu;

// Welded positions and the triangles over them (those with three distinct corners), by an
// open-addressing table of the positions' bits.
void weld_vertices(const Eigen::Matrix3Xd& x, std::span<const std::uint32_t> triangles, Welded& w) {
  const auto n = static_cast<std::uint64_t>(x.cols());
  if (triangles.size() % 3 != 0)
    throw std::invalid_argument("count_self_crossings: " + std::to_string(triangles.size()) +
                                " triangle indices, no multiple of 3");
  std::vector<std::uint32_t> id(static_cast<std::size_t>(n), kNone);
  std::vector<Key> keys;
  const std::size_t cap = std::bit_ceil(2 * std::min<std::size_t>(static_cast<std::size_t>(n), triangles.size()) + 2);
  std::vector<std::uint32_t> table(cap, kNone);
  for (std::size_t i = 0; i < triangles.size(); i += 3) {
    std::array<std::uint32_t, 3> t{};
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = triangles[i + k];
      if (v >= n)
        throw std::invalid_argument("count_self_crossings: index " + std::to_string(v) + " of triangle " +
                                    std::to_string(i / 3) + " is out of range (" + std::to_string(n) + " positions)");
      if (id[v] == kNone) {
        const Vec p = x.col(static_cast<Eigen::Index>(v));
        const Key key = key_of(p);
        std::size_t slot = static_cast<std::size_t>(hash_of(key)) & (cap - 1);
        while (table[slot] != kNone && keys[table[slot]] != key) slot = (slot + 1) & (cap - 1);
        if (table[slot] == kNone) {
          table[slot] = static_cast<std::uint32_t>(w.pos.size());
          w.pos.push_back(p);
          keys.push_back(key);
        }
        id[v] = table[slot];
      }
      t[k] = id[v];
    }
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) w.tris.push_back(t);
  }
}

Welded weld(const Eigen::Matrix3Xd& x, std::span<const std::uint32_t> triangles) {
  Welded w;
  weld_vertices(x, triangles, w);
  // Unique edges: the half edges (hi, 3 triangle + corner) bucketed by their lower vertex,
  // each bucket sorted. Welded corners of a kept triangle differ in position, so no edge has
  // zero length.
  const std::size_t halves = 3 * w.tris.size();
  std::vector<std::uint32_t> first(w.pos.size() + 1, 0);
  for (const auto& t : w.tris)
    for (std::size_t k = 0; k < 3; ++k) ++first[std::min(t[k], t[(k + 1) % 3]) + 1];
  for (std::size_t v = 0; v < w.pos.size(); ++v) first[v + 1] += first[v];
  std::vector<std::pair<std::uint32_t, std::uint32_t>> half(halves);
  std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
  for (std::uint32_t t = 0; t < w.tris.size(); ++t)
    for (std::uint32_t k = 0; k < 3; ++k) {
      const std::uint32_t a = w.tris[t][k], b = w.tris[t][(k + 1) % 3];
      half[fill[std::min(a, b)]++] = {std::max(a, b), 3 * t + k};
    }
  w.tri_of_edge.reserve(halves);
  w.tri_edges.resize(halves);
  for (std::uint32_t v = 0; v < w.pos.size(); ++v) {
    std::sort(half.begin() + first[v], half.begin() + first[v + 1]);
    for (std::uint32_t i = first[v]; i < first[v + 1]; ++i) {
      if (i == first[v] || half[i].first != half[i - 1].first) {
        w.edges.push_back({v, half[i].first});
        w.edge_first.push_back(i);
      }
      w.tri_of_edge.push_back(half[i].second / 3);
      w.tri_edges[half[i].second] = static_cast<std::uint32_t>(w.edges.size() - 1);
    }
  }
  w.edge_first.push_back(static_cast<std::uint32_t>(halves));
  return w;
}

// An axis-aligned box; touching boxes overlap.
struct Box {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
  void add(const Vec& p) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], p[i]);
      hi[i] = std::max(hi[i], p[i]);
    }
  }
  void add(const Box& b) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], b.lo[i]);
      hi[i] = std::max(hi[i], b.hi[i]);
    }
  }
  bool overlaps(const Box& b) const {
    return lo[0] <= b.hi[0] && b.lo[0] <= hi[0] && lo[1] <= b.hi[1] && b.lo[1] <= hi[1] && lo[2] <= b.hi[2] &&
           b.lo[2] <= hi[2];
  }
};

// A BVH over the triangles' boxes: median split of the centroids on the widest axis, leaves
// of up to kLeaf triangles. A leaf has count > 0 and its triangles at order[first ..) (their
// boxes at leaf_box[first ..)); an inner node's children are `first` and `first + 1`.
struct Bvh {
  static constexpr std::uint32_t kLeaf = 4;
  struct Node {
    Box box;
    std::uint32_t first = 0, count = 0;
  };
  // A triangle while the tree is built: its box's centre (float: only the split uses it) and
  // index, moved as one so that the splits read memory in order.
  struct Item {
    float c[3];
    std::uint32_t t;
  };
  std::vector<Node> nodes;
  std::vector<std::uint32_t> order;
  std::vector<Box> tri_box, leaf_box;
  std::vector<Item> items;

  explicit Bvh(const Welded& w) {
    const auto t = static_cast<std::uint32_t>(w.tris.size());
    tri_box.resize(t);
    items.resize(t);
    for (std::uint32_t i = 0; i < t; ++i) {
      for (std::uint32_t v : w.tris[i]) tri_box[i].add(w.pos[v]);
      const Box& b = tri_box[i];
      for (int k = 0; k < 3; ++k) items[i].c[k] = static_cast<float>(0.5 * (b.lo[k] + b.hi[k]));
      items[i].t = i;
    }
    nodes.reserve(t == 0 ? 1 : 2 * t);
    nodes.emplace_back();
    build(0, 0, t);
    order.resize(t);
    leaf_box.resize(t);
    for (std::uint32_t i = 0; i < t; ++i) {
      order[i] = items[i].t;
      leaf_box[i] = tri_box[order[i]];
    }
  }

  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
    if (end - begin <= kLeaf) {
      for (std::uint32_t i = begin; i < end; ++i) nodes[node].box.add(tri_box[items[i].t]);
      nodes[node].first = begin;
      nodes[node].count = end - begin;
      return;
    }
    float lo[3] = {items[begin].c[0], items[begin].c[1], items[begin].c[2]}, hi[3] = {lo[0], lo[1], lo[2]};
    for (std::uint32_t i = begin + 1; i < end; ++i)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], items[i].c[k]);
        hi[k] = std::max(hi[k], items[i].c[k]);
      }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                     [axis](const Item& a, const Item& b) {
                       const float ca = a.c[axis], cb = b.c[axis];
                       return ca < cb || (ca == cb && a.t < b.t);  // (ties by index: deterministic)
                     });
    const auto left = static_cast<std::uint32_t>(nodes.size());
    nodes[node].first = left;
    nodes.emplace_back();
    nodes.emplace_back();
    build(left, begin, mid);
    build(left + 1, mid, end);
    nodes[node].box = nodes[left].box;
    nodes[node].box.add(nodes[left + 1].box);
  }

  /// The slots (indices into order and leaf_box) of the triangles whose boxes overlap `b`,
  /// appended to `out`.
  void overlapping(const Box& b, std::vector<std::uint32_t>& stack, std::vector<std::uint32_t>& out) const {
    if (!nodes[0].box.overlaps(b)) return;
    stack.assign(1, 0);
    while (!stack.empty()) {  // (nodes on the stack overlap b)
      const Node& node = nodes[stack.back()];
      stack.pop_back();
      if (node.count == 0) {
        for (std::uint32_t child = node.first; child < node.first + 2; ++child)
          if (nodes[child].box.overlaps(b)) stack.push_back(child);
        continue;
      }
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
        if (leaf_box[i].overlaps(b)) out.push_back(i);
    }
  }
};

// A triangle's plane for the quick test: n = (b - a) x (c - a) and |b - a|_1 |c - a|_1, which
// bounds n's rounding (a sliver's n can be all rounding).
struct Plane {
  Vec n;
  double scale = 0.0;
};

// Whether edge e crosses triangle t (never when they share a vertex). Ends on one side of the
// plane by far more than rounding (1e-9 relative) are no crossing without the predicates.
bool crosses(const Welded& w, std::uint32_t e, const std::array<std::uint32_t, 3>& t, const Plane& plane) {
  const std::uint32_t u = w.edges[e][0], v = w.edges[e][1];
  for (std::uint32_t c : t)
    if (c == u || c == v) return false;
  const Vec &p = w.pos[u], &q = w.pos[v], &a = w.pos[t[0]];
  const double dp = plane.n.dot(p - a), dq = plane.n.dot(q - a);
  const double tol = 1e-9 * plane.scale * ((p - a).lpNorm<1>() + (q - a).lpNorm<1>());
  if ((dp > tol && dq > tol) || (dp < -tol && dq < -tol)) return false;
  return segment_crosses_triangle(p, q, a, w.pos[t[1]], w.pos[t[2]]);
}

}  // namespace

bool segment_crosses_triangle(const Vec& p0, const Vec& q0, const Vec& a, const Vec& b, const Vec& c) {
  const bool swap = before(q0, p0);  // (pq and qp alike)
  const Vec& p = swap ? q0 : p0;
  const Vec& q = swap ? p0 : q0;
  const double dp = orient(a, b, c, p), dq = orient(a, b, c, q);
  if (!((dp > 0.0 && dq < 0.0) || (dp < 0.0 && dq > 0.0))) return false;
  const double s1 = line_side(p, q, a, b), s2 = line_side(p, q, b, c), s3 = line_side(p, q, c, a);
  return (s1 > 0.0 && s2 > 0.0 && s3 > 0.0) || (s1 < 0.0 && s2 < 0.0 && s3 < 0.0);
}

CrossingCount count_self_crossings(const Eigen::Matrix3Xd& x, std::span<const std::uint32_t> triangles) {
  const Welded w = weld(x, triangles);
  CrossingCount out;
  if (w.tris.empty()) return out;
  const Bvh bvh(w);
  std::vector<Plane> plane(w.tris.size());
  for (std::size_t t = 0; t < w.tris.size(); ++t) {
    const Vec &a = w.pos[w.tris[t][0]], &b = w.pos[w.tris[t][1]], &c = w.pos[w.tris[t][2]];
    plane[t] = {(b - a).cross(c - a), (b - a).lpNorm<1>() * (c - a).lpNorm<1>()};
  }
  // Leaf by leaf: the edges of its triangles (each edge with its lowest triangle) against the
  // triangles near the leaf, one tree walk for them all.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  std::vector<std::uint32_t> stack, near, group;
  std::vector<Box> group_box;
  for (const Bvh::Node& leaf : bvh.nodes) {
    if (leaf.count == 0) continue;
    group.clear();
    group_box.clear();
    Box all;
    for (std::uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i)
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::uint32_t t = bvh.order[i], e = w.tri_edges[3 * t + k];
        if (w.tri_of_edge[w.edge_first[e]] != t) continue;
        group.push_back(e);
        group_box.emplace_back();
        group_box.back().add(w.pos[w.edges[e][0]]);
        group_box.back().add(w.pos[w.edges[e][1]]);
        all.add(group_box.back());
      }
    near.clear();
    bvh.overlapping(all, stack, near);
    for (std::size_t g = 0; g < group.size(); ++g)
      for (std::uint32_t i : near) {
        const std::uint32_t e = group[g], t = bvh.order[i];
        if (!bvh.leaf_box[i].overlaps(group_box[g]) || !crosses(w, e, w.tris[t], plane[t])) continue;
        ++out.crossings;
        for (std::uint32_t k = w.edge_first[e]; k < w.edge_first[e + 1]; ++k) {
          const std::uint32_t own = w.tri_of_edge[k];  // (never t: t shares no vertex with the edge)
          pairs.emplace_back(std::min(own, t), std::max(own, t));
        }
      }
  }
  std::sort(pairs.begin(), pairs.end());
  out.triangle_pairs = static_cast<std::size_t>(std::unique(pairs.begin(), pairs.end()) - pairs.begin());
  return out;
}

CrossingCount count_self_crossings(const Model& m, const Eigen::Matrix3Xd& x) {
  return count_self_crossings(x, std::span<const std::uint32_t>(m.triangles));
}

}  // namespace clothsim
