// Self-crossings of a triangle mesh (clothsim/self_crossings.hpp): weld by position, take each
// welded edge once, pair the leaves of a BVH over the triangles' boxes whose boxes overlap,
// and test their edges and triangles that share no vertex with filtered orientation predicates.
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
  bool overlaps(const Box& b) const {  // (without branches: half the tests fail, unpredictably)
    return static_cast<bool>((lo[0] <= b.hi[0]) & (b.lo[0] <= hi[0]) & (lo[1] <= b.hi[1]) & (b.lo[1] <= hi[1]) &
                             (lo[2] <= b.hi[2]) & (b.lo[2] <= hi[2]));
  }
};

// A BVH over the triangles' boxes: the triangles sorted along a Morton curve through their
// boxes' centres, split in halves of that order down to leaves of up to kLeaf triangles. A leaf has count > 0 and its triangles at order[first ..) (their
// boxes at leaf_box[first ..)); an inner node's children are `first` and `first + 1`.
struct Bvh {
  static constexpr std::uint32_t kLeaf = 4;
  struct Node {
    Box box;
    std::uint32_t first = 0, count = 0;
  };
  std::vector<Node> nodes;
  std::vector<std::uint32_t> order;
  std::vector<Box> leaf_box;

  explicit Bvh(const Welded& w) {
    const auto t = static_cast<std::uint32_t>(w.tris.size());
    std::vector<Box> tri_box(t);
    Box all;
    for (std::uint32_t i = 0; i < t; ++i) {
      for (std::uint32_t v : w.tris[i]) tri_box[i].add(w.pos[v]);
      all.add(tri_box[i]);
    }
    // (Morton code << 32 | triangle), sorted: ties by index, so the order is deterministic
    std::vector<std::uint64_t> keys(t);
    for (std::uint32_t i = 0; i < t; ++i) {
      std::uint64_t code = 0;
      for (int k = 0; k < 3; ++k) {
        const double extent = all.hi[k] - all.lo[k];
        const double centre = 0.5 * (tri_box[i].lo[k] + tri_box[i].hi[k]);
        const double unit = extent > 0.0 ? (centre - all.lo[k]) / extent : 0.0;
        code |= spread(static_cast<std::uint32_t>(std::clamp(unit, 0.0, 1.0) * 1023.0)) << k;
      }
      keys[i] = code << 32 | i;
    }
    std::sort(keys.begin(), keys.end());
    order.resize(t);
    leaf_box.resize(t);
    for (std::uint32_t i = 0; i < t; ++i) {
      order[i] = static_cast<std::uint32_t>(keys[i]);
      leaf_box[i] = tri_box[order[i]];
    }
    nodes.reserve(t == 0 ? 1 : 2 * t);
    nodes.emplace_back();
    build(0, 0, t);
  }

  // 10 bits spread to every third bit.
  static std::uint64_t spread(std::uint32_t v) {
    std::uint64_t x = v & 0x3ffu;
    x = (x | x << 16) & 0x30000ffull;
    x = (x | x << 8) & 0x300f00full;
    x = (x | x << 4) & 0x30c30c3ull;
    x = (x | x << 2) & 0x9249249ull;
    return x;
  }

  void build(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
    if (end - begin <= kLeaf) {
      for (std::uint32_t i = begin; i < end; ++i) nodes[node].box.add(leaf_box[i]);
      nodes[node].first = begin;
      nodes[node].count = end - begin;
      return;
    }
    const std::uint32_t mid = begin + (end - begin) / 2;
    const auto left = static_cast<std::uint32_t>(nodes.size());
    nodes[node].first = left;
    nodes.emplace_back();
    nodes.emplace_back();
    build(left, begin, mid);
    build(left + 1, mid, end);
    nodes[node].box = nodes[left].box;
    nodes[node].box.add(nodes[left + 1].box);
  }
};

// A triangle near a BVH leaf, gathered so that the leaf's edges test it from one place: its
// corners, box, first corner a, n = (b - a) x (c - a) and |b - a|_1 |c - a|_1, which bounds
// n's rounding (a sliver's n can be all rounding).
struct Near {
  std::array<std::uint32_t, 3> corner;
  std::uint32_t t;
  Box box;
  Vec a, n;
  double scale;
};

// How segment pq (welded vertices u, v) meets the triangle (never when they share a vertex).
// Ends on one side of the plane by far more than rounding (1e-9 relative) meet nothing
// without the predicates.
Meet meets(const Welded& w, std::uint32_t u, std::uint32_t v, const Vec& p, const Vec& q, const Near& t) {
  const std::array<std::uint32_t, 3>& c = t.corner;
  if (c[0] == u || c[1] == u || c[2] == u || c[0] == v || c[1] == v || c[2] == v) return Meet::None;
  const Vec pa = p - t.a, qa = q - t.a;
  const double dp = t.n.dot(pa), dq = t.n.dot(qa);
  const double tol = 1e-9 * t.scale * (pa.lpNorm<1>() + qa.lpNorm<1>());
  if ((dp > tol && dq > tol) || (dp < -tol && dq < -tol)) return Meet::None;
  return segment_meets_triangle(p, q, t.a, w.pos[t.corner[1]], w.pos[t.corner[2]]);
}

// The tree against itself: every pair of leaves whose boxes overlap, once, and in it the
// edges of each leaf's triangles (each edge with its lowest triangle) against the other's
// triangles. An edge's box lies in its triangle's, so every (edge, triangle) pair whose boxes
// overlap is met in exactly one leaf pair.
struct SelfQuery {
  const Welded& w;
  const Bvh& bvh;
  CrossingCount& out;
  std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs;  // the triangle pairs, repeated
  std::vector<Near> tri;                                          // by slot (bvh.order)
  std::vector<std::uint32_t> group_first, group;  // node n's edges: group[group_first[n] .. [n + 1])
  std::vector<Box> group_box;

  SelfQuery(const Welded& w_, const Bvh& bvh_, CrossingCount& out_,
            std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs_)
      : w(w_), bvh(bvh_), out(out_), pairs(pairs_) {
    tri.reserve(bvh.order.size());
    for (std::size_t i = 0; i < bvh.order.size(); ++i) {
      const std::uint32_t t = bvh.order[i];
      const auto& c = w.tris[t];
      const Vec &a = w.pos[c[0]], &b = w.pos[c[1]], &d = w.pos[c[2]];
      tri.push_back({c, t, bvh.leaf_box[i], a, (b - a).cross(d - a), (b - a).lpNorm<1>() * (d - a).lpNorm<1>()});
    }
    group_first.reserve(bvh.nodes.size() + 1);
    group.reserve(w.edges.size());
    group_box.reserve(w.edges.size());
    for (const Bvh::Node& node : bvh.nodes) {
      group_first.push_back(static_cast<std::uint32_t>(group.size()));
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i)  // (a leaf's slots)
        for (std::uint32_t k = 0; k < 3; ++k) {
          const std::uint32_t t = bvh.order[i], e = w.tri_edges[3 * t + k];
          if (w.tri_of_edge[w.edge_first[e]] != t) continue;
          group.push_back(e);
          group_box.emplace_back();
          group_box.back().add(w.pos[w.edges[e][0]]);
          group_box.back().add(w.pos[w.edges[e][1]]);
        }
    }
    group_first.push_back(static_cast<std::uint32_t>(group.size()));
  }

  // The edges of leaf a against the triangles of leaf b.
  void edges_against(std::uint32_t a, std::uint32_t b) {
    const Bvh::Node& leaf = bvh.nodes[b];
    for (std::uint32_t g = group_first[a]; g < group_first[a + 1]; ++g) {
      if (!group_box[g].overlaps(leaf.box)) continue;
      const std::uint32_t e = group[g], u = w.edges[e][0], v = w.edges[e][1];
      const Vec &p = w.pos[u], &q = w.pos[v];
      for (std::uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i) {
        const Near& t = tri[i];
        if (!t.box.overlaps(group_box[g])) continue;
        const Meet m = meets(w, u, v, p, q, t);
        out.touches += m == Meet::Touches;
        if (m != Meet::Crosses) continue;
        ++out.crossings;
        for (std::uint32_t k = w.edge_first[e]; k < w.edge_first[e + 1]; ++k) {
          const std::uint32_t own = w.tri_of_edge[k];  // (never t: t shares no vertex with the edge)
          pairs.emplace_back(std::min(own, t.t), std::max(own, t.t));
        }
      }
    }
  }

  void self(std::uint32_t n) {
    const Bvh::Node& node = bvh.nodes[n];
    if (node.count > 0) return edges_against(n, n);
    self(node.first);
    self(node.first + 1);
    between(node.first, node.first + 1);
  }

  // Two distinct subtrees: split the inner one (both inner: the one with the larger box).
  void between(std::uint32_t a, std::uint32_t b) {
    const Bvh::Node &na = bvh.nodes[a], &nb = bvh.nodes[b];
    if (!na.box.overlaps(nb.box)) return;
    if (na.count > 0 && nb.count > 0) {
      edges_against(a, b);
      edges_against(b, a);
      return;
    }
    const auto size = [](const Box& x) { return x.hi[0] - x.lo[0] + x.hi[1] - x.lo[1] + x.hi[2] - x.lo[2]; };
    if (nb.count > 0 || (na.count == 0 && size(na.box) >= size(nb.box))) {
      between(na.first, b);
      between(na.first + 1, b);
    } else {
      between(a, nb.first);
      between(a, nb.first + 1);
    }
  }
};

}  // namespace

Meet segment_meets_triangle(const Vec& p0, const Vec& q0, const Vec& a, const Vec& b, const Vec& c) {
  const bool swap = before(q0, p0);  // (pq and qp alike)
  const Vec& p = swap ? q0 : p0;
  const Vec& q = swap ? p0 : q0;
  const double dp = orient(a, b, c, p), dq = orient(a, b, c, q);
  if ((dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || (dp == 0.0 && dq == 0.0)) return Meet::None;
  const double s1 = line_side(p, q, a, b), s2 = line_side(p, q, b, c), s3 = line_side(p, q, c, a);
  const bool inside = (s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) || (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0);
  if (!inside) return Meet::None;
  const bool strict = dp != 0.0 && dq != 0.0 && s1 != 0.0 && s2 != 0.0 && s3 != 0.0;
  return strict ? Meet::Crosses : Meet::Touches;
}

bool segment_crosses_triangle(const Vec& p, const Vec& q, const Vec& a, const Vec& b, const Vec& c) {
  return segment_meets_triangle(p, q, a, b, c) == Meet::Crosses;
}

CrossingCount count_self_crossings(const Eigen::Matrix3Xd& x, std::span<const std::uint32_t> triangles) {
  const Welded w = weld(x, triangles);
  CrossingCount out;
  if (w.tris.empty()) return out;
  const Bvh bvh(w);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  SelfQuery(w, bvh, out, pairs).self(0);
  std::sort(pairs.begin(), pairs.end());
  out.triangle_pairs = static_cast<std::size_t>(std::unique(pairs.begin(), pairs.end()) - pairs.begin());
  return out;
}

CrossingCount count_self_crossings(const Model& m, const Eigen::Matrix3Xd& x) {
  return count_self_crossings(x, std::span<const std::uint32_t>(m.triangles));
}

}  // namespace clothsim
