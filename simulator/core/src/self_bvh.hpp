// A bounding-volume hierarchy over the cloth's masses, triangles or edges, for the self-contact
// stage's candidate lists: built where the lists are found, refitted there at the next builds
// (the topology never changes), built again every few; and its dual-tree descents.
#pragma once

#include <clothsim/cpu.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>
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
  /// Each leaf's masses once each: leaf_masses[mass_start[i] .. mass_start[i + 1]) for node i
  /// (empty for an inner node). A leaf's primitives share masses, so a bound over its masses
  /// reads about half as many as one over its primitives' corners.
  std::vector<std::uint32_t> mass_start, leaf_masses;
  /// (nodes) each inner node's right child, 0 for a leaf: the passes that need only the
  /// tree's shape read these and mass_start, not the nodes' boxes.
  std::vector<std::uint32_t> right;
  /// A leaf's primitive boxes as lanes, axis by axis (empty lanes never meet a box): a leaf
  /// pair's tests run four at a time.
  struct Lanes {
    alignas(32) double lo[3][4], hi[3][4];
  };
  std::vector<Lanes> lanes;               ///< per leaf, at lane_slot[node]
  std::vector<std::uint32_t> lane_slot;  ///< (nodes) each leaf's place in `lanes`
  /// The subtrees kPartDepth levels down (or leaves above that), each its nodes' range
  /// [begin, end), and the inner nodes above them (`tops`, ascending): bottom_up's shares.
  static constexpr int kPartDepth = 5;
  std::vector<std::array<std::uint32_t, 2>> parts;
  std::vector<std::uint32_t> tops;

  /// Builds the tree over primitives of k corners (3: triangles, 2: edges) at positions x (3 n),
  /// the subtrees below the top levels and the refit on nt threads: the same tree on any count.
  void build(const double* x, std::span<const std::uint32_t> prim_corners, int corners_per_prim, int nt = 1);
  /// Lists each leaf's masses (mass_start, leaf_masses), places its lanes (lane_slot) and
  /// finds bottom_up's shares.
  void index_leaves();
  /// Finds bottom_up's shares (parts, tops).
  void find_parts();
  /// Refits every box to positions x, on nt threads.
  void refit(const double* x, int nt = 1);
  /// Runs node(i) for every node, children before parents: the subtrees of `parts` on nt
  /// threads, each from its last node back, then the nodes above them. A pass whose node
  /// reads only its children and its own primitives gives the same bits on any thread count.
  template <class F>
  void bottom_up(int nt, F&& node) const {
    if (nt <= 1) {  // (every node from the last: children follow their parents)
      for (auto i = static_cast<std::uint32_t>(nodes.size()); i-- > 0;) node(i);
      return;
    }
    run_parts(nt, &node, [](void* f, std::uint32_t begin, std::uint32_t end) {
      auto each = *static_cast<std::remove_reference_t<F>*>(f);
      for (std::uint32_t i = end; i-- > begin;) each(i);
    });
    for (std::size_t j = tops.size(); j-- > 0;) node(tops[j]);
  }
  /// Runs run(f, begin, end) for every part on nt threads (self_bvh.cpp: the threads are the core's).
  void run_parts(int nt, void* f, void (*run)(void*, std::uint32_t, std::uint32_t)) const;
  /// Copies a leaf's primitive boxes into its lanes.
  void fill_lanes(Lanes& l, const Node& leaf) const;

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
#ifdef CLOTHSIM_AVX2
    const auto meets = use_avx2() ? leaf_meets_avx2 : leaf_meets;
#else
    const auto meets = leaf_meets;
#endif
    std::uint64_t tested = 0;
    std::vector<NodePair> stack{np};
    while (!stack.empty()) {
      const auto [a, b] = stack.back();
      stack.pop_back();
      ++tested;
      const Node &na = nodes[a], &nb = other.nodes[b];
      if (!(self && a == b) && !near(na.lo, na.hi, nb.lo, nb.hi, r)) continue;
      if (na.count > 0 && nb.count > 0) {
        const bool one = self && a == b;
        tested += one ? na.count * (na.count - 1) / 2 : na.count * nb.count;
        std::uint32_t hits = meets(lanes[lane_slot[a]], na.count, other.lanes[other.lane_slot[b]], r);
        if (one) hits &= kAbove;
        for (; hits != 0; hits &= hits - 1) {  // (in the order of i, then j)
          const auto bit = static_cast<std::uint32_t>(__builtin_ctz(hits));
          f(order[na.first + bit / 4], other.order[nb.first + bit % 4]);
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
  /// Which primitives of two leaves' lanes meet, the first's boxes grown by r: bit 4 i + j
  /// for the first's i-th (i < count) and the second's j-th; near()'s tests.
  static std::uint32_t leaf_meets(const Lanes& a, std::uint32_t count, const Lanes& b, double r);
#ifdef CLOTHSIM_AVX2
  static std::uint32_t leaf_meets_avx2(const Lanes& a, std::uint32_t count, const Lanes& b, double r);
#endif
  /// The bits 4 i + j with j > i: a leaf's pairs with itself, each once.
  static constexpr std::uint32_t kAbove = 0x8ce;
  static double extent(const Node& n) { return std::max({n.hi[0] - n.lo[0], n.hi[1] - n.lo[1], n.hi[2] - n.lo[2]}); }
};

}  // namespace clothsim::detail
