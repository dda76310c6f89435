// A bounding-volume hierarchy over the cloth's masses, triangles or edges, for the self-contact
// stage's candidate lists: built where the lists are found, refitted there at the next builds
// (the topology never changes), built again every few; and its dual-tree descents.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace clothsim::detail {

struct SelfBvh {
  /// A node's box; an inner node's left child follows it, `next` is its right child; a leaf
  /// holds order[first .. first + count).
  struct Node {
    std::array<double, 3> lo, hi;
    std::uint32_t next = 0, first = 0, count = 0;
  };
  std::vector<Node> nodes;
  std::vector<std::uint32_t> order;  ///< the primitives, leaf by leaf
  std::vector<std::array<double, 6>> box;  ///< each primitive's box (lo, hi), in `order`
  std::span<const std::uint32_t> corners;  ///< k mass indices per primitive
  int k = 3;

  /// Builds the tree over primitives of k corners (3: triangles, 2: edges) at positions x (3 n).
  void build(const double* x, std::span<const std::uint32_t> prim_corners, int corners_per_prim);
  /// Refits every box to positions x.
  void refit(const double* x);

  /// Two subtrees to join: a node of this tree and one of the other (or of this tree again).
  struct NodePair {
    std::uint32_t a, b;
  };

  /// Splits the join of this tree with `other` (the same object: a self-join) into node pairs,
  /// about `want` of them, whose joins together give every pair once; independent of threads.
  std::vector<NodePair> join_tasks(const SelfBvh& other, double r, std::size_t want) const;

  /// Replaces node pair np in a descent of this tree against `other` by the pairs under it:
  /// for a self pair (a, a), its children's three; else the children of the larger node that
  /// is not whole (a leaf, or a node not to be split) against the other node.
  void descend(const SelfBvh& other, NodePair np, bool a_whole, bool b_whole, std::vector<NodePair>& stack) const {
    const auto [a, b] = np;
    const Node &na = nodes[a], &nb = other.nodes[b];
    if (&other == this && a == b) {
      stack.push_back({a + 1, na.next}), stack.push_back({na.next, na.next}), stack.push_back({a + 1, a + 1});
    } else if (b_whole || (!a_whole && extent(na) >= extent(nb))) {
      stack.push_back({na.next, b}), stack.push_back({a + 1, b});
    } else {
      stack.push_back({a, nb.next}), stack.push_back({a, b + 1});
    }
  }

  /// Calls f(p, q) for every primitive p under node pair np.a and q under np.b whose boxes,
  /// p's grown by r, meet. A self-join gives each unordered pair p != q once. Returns how many
  /// node pairs and primitive pairs it tested.
  template <class F>
  std::uint64_t join(const SelfBvh& other, NodePair np, double r, F&& f) const {
    const bool self = &other == this;
    std::uint64_t tested = 0;
    std::vector<NodePair> stack{np};
    while (!stack.empty()) {
      const auto [a, b] = stack.back();
      stack.pop_back();
      ++tested;
      const Node &na = nodes[a], &nb = other.nodes[b];
      if (!(self && a == b) && !near(na.lo, na.hi, nb.lo, nb.hi, r)) continue;
      if (na.count > 0 && nb.count > 0) {
        for (std::uint32_t i = na.first; i < na.first + na.count; ++i) {
          const std::uint32_t from = self && a == b ? i + 1 : nb.first;
          tested += nb.first + nb.count - from;
          for (std::uint32_t j = from; j < nb.first + nb.count; ++j)
            if (near(box[i], other.box[j], r)) f(order[i], other.order[j]);
        }
      } else {
        descend(other, {a, b}, na.count > 0, nb.count > 0, stack);
      }
    }
    return tested;
  }

  /// Whether two boxes, the first grown by r, meet.
  static bool near(const std::array<double, 3>& alo, const std::array<double, 3>& ahi,
                   const std::array<double, 3>& blo, const std::array<double, 3>& bhi, double r) {
    return alo[0] - r <= bhi[0] && ahi[0] + r >= blo[0] && alo[1] - r <= bhi[1] && ahi[1] + r >= blo[1] &&
           alo[2] - r <= bhi[2] && ahi[2] + r >= blo[2];
  }
  static bool near(const std::array<double, 6>& p, const std::array<double, 6>& q, double r) {
    return p[0] - r <= q[3] && p[3] + r >= q[0] && p[1] - r <= q[4] && p[4] + r >= q[1] && p[2] - r <= q[5] &&
           p[5] + r >= q[2];
  }
  static double extent(const Node& n) { return std::max({n.hi[0] - n.lo[0], n.hi[1] - n.lo[1], n.hi[2] - n.lo[2]}); }
};

}  // namespace clothsim::detail
