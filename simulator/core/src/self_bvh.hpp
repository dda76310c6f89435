// A bounding-volume hierarchy over the cloth's triangles or edges, for the self-contact
// stage: built once from the rest shape, refitted to the current positions before each
// detection (the topology never changes), rebuilt when the shape has changed much.
#pragma once

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

  /// Calls f(primitive) for every primitive whose box meets [lo, hi].
  template <class F>
  void query(const double lo[3], const double hi[3], F&& f) const {
    if (nodes.empty()) return;
    std::uint32_t stack[64];
    int top = 0;
    std::uint32_t n = 0;
    for (;;) {
      const Node& nd = nodes[n];
      const bool meets = nd.lo[0] <= hi[0] && nd.hi[0] >= lo[0] && nd.lo[1] <= hi[1] && nd.hi[1] >= lo[1] &&
                         nd.lo[2] <= hi[2] && nd.hi[2] >= lo[2];
      if (meets && nd.count > 0) {
        for (std::uint32_t i = nd.first; i < nd.first + nd.count; ++i) {
          const auto& b = box[i];
          if (b[0] <= hi[0] && b[3] >= lo[0] && b[1] <= hi[1] && b[4] >= lo[1] && b[2] <= hi[2] && b[5] >= lo[2]) f(order[i]);
        }
      } else if (meets) {
        stack[top++] = nd.next;
        n = n + 1;
        continue;
      }
      if (top == 0) return;
      n = stack[--top];
    }
  }
};

}  // namespace clothsim::detail
