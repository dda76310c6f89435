// The self-contact BVH: splits along the longest axis of the centroids at half the count
// rounded up to whole leaves, so that leaves fill their four lanes; nodes in depth-first
// order, so that a pass from the last node back meets children before parents (on threads,
// subtree by subtree).
#include "self_bvh.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <limits>

namespace clothsim::detail {

namespace {

constexpr std::uint32_t kLeaf = 4;
static_assert(kLeaf <= 4, "a leaf's boxes fill one set of four lanes (SelfBvh::Lanes)");

/// The build splits the top this many levels on one thread, then builds the subtrees below
/// on the threads, each into its own nodes, and joins them in depth-first order.
constexpr int kBuildSplitDepth = 3;

struct Builder {
  SelfBvh& t;
  std::vector<std::array<double, 3>> centre;
  /// The top levels in depth-first order: a node split there (job -1) or a subtree to build.
  struct Item {
    std::uint32_t first, count;
    int job;
  };
  std::vector<Item> items;
  std::vector<std::vector<SelfBvh::Node>> jobs;

  // Orders order[first .. first + count) about its split along the longest axis of the
  // centroids and returns the left part's count: half the count rounded up to whole leaves,
  // at most kLeaf more than half (every leaf holds at most kLeaf primitives, and the depth
  // stays under 40).
  std::uint32_t split(std::uint32_t first, std::uint32_t count) {
    std::array<double, 3> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity()), hi.fill(-std::numeric_limits<double>::infinity());
    for (std::uint32_t i = first; i < first + count; ++i)
      for (int a = 0; a < 3; ++a)
        lo[a] = std::min(lo[a], centre[t.order[i]][a]), hi[a] = std::max(hi[a], centre[t.order[i]][a]);
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    const std::uint32_t half = kLeaf * ((count + 2 * kLeaf - 1) / (2 * kLeaf));
    auto* b = t.order.data() + first;
    std::nth_element(b, b + half, b + count, [&](std::uint32_t p, std::uint32_t q) {
      return centre[p][axis] < centre[q][axis] || (centre[p][axis] == centre[q][axis] && p < q);
    });
    return half;
  }

  // The subtree over order[first .. first + count) into `out`, its nodes' `next` counted from
  // out's start; returns its root.
  std::uint32_t node(std::vector<SelfBvh::Node>& out, std::uint32_t first, std::uint32_t count) {
    const auto self = static_cast<std::uint32_t>(out.size());
    out.push_back({});
    if (count <= kLeaf) {
      out[self].first = first, out[self].count = count;
      return self;
    }
    const std::uint32_t half = split(first, count);
    node(out, first, half);
    const std::uint32_t right = node(out, first + half, count - half);
    out[self].next = right;
    return self;
  }

  // Splits the top levels (items), leaving the subtrees below kBuildSplitDepth as jobs.
  void plan(std::uint32_t first, std::uint32_t count, int depth) {
    if (depth == kBuildSplitDepth || count <= kLeaf) {
      items.push_back({first, count, static_cast<int>(jobs.size())});
      jobs.emplace_back();
      return;
    }
    items.push_back({first, count, -1});
    const std::uint32_t half = split(first, count);
    plan(first, half, depth + 1);
    plan(first + half, count - half, depth + 1);
  }

  // Appends items[k ..]'s subtree to the tree's nodes; returns its root.
  std::uint32_t join(std::size_t& k) {
    const Item it = items[k++];
    const auto self = static_cast<std::uint32_t>(t.nodes.size());
    if (it.job >= 0) {
      for (SelfBvh::Node nd : jobs[static_cast<std::size_t>(it.job)]) {
        if (nd.count == 0) nd.next += self;
        t.nodes.push_back(nd);
      }
      return self;
    }
    t.nodes.push_back({});
    join(k);
    const std::uint32_t right = join(k);
    t.nodes[self].next = right;
    return self;
  }
};

}  // namespace

void SelfBvh::build(const double* x, std::span<const std::uint32_t> prim_corners, int corners_per_prim, int nt) {
  corners = prim_corners;
  k = corners_per_prim;
  const std::size_t n = corners.size() / static_cast<std::size_t>(k);
  nodes.clear();
  order.resize(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
  Builder b{*this, std::vector<std::array<double, 3>>(n), {}, {}};
  parallel_for(nt, static_cast<std::int64_t>(n), [&](std::int64_t i) {
    const auto p = static_cast<std::size_t>(i);
    for (std::size_t a = 0; a < 3; ++a) {
      double s = 0.0;
      for (std::size_t c = 0; c < static_cast<std::size_t>(k); ++c) s += x[3 * std::size_t{corners[p * static_cast<std::size_t>(k) + c]} + a];
      b.centre[p][a] = s / k;
    }
  });
  nodes.reserve(2 * n / kLeaf + 2);
  if (n > 0) {
    b.plan(0, static_cast<std::uint32_t>(n), 0);
    parallel_for_dynamic(nt, static_cast<std::int64_t>(b.items.size()), [&](std::int64_t i) {
      const Builder::Item& it = b.items[static_cast<std::size_t>(i)];
      if (it.job >= 0) b.node(b.jobs[static_cast<std::size_t>(it.job)], it.first, it.count);
    });
    std::size_t at = 0;
    b.join(at);
  }
  index_leaves();
  refit(x, nt);
}

void SelfBvh::index_leaves() {
  const auto kk = static_cast<std::size_t>(k);
  mass_start.assign(1, 0);
  leaf_masses.clear();
  lane_slot.assign(nodes.size(), 0);
  right.assign(nodes.size(), 0);
  std::uint32_t leaves = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Node& nd = nodes[i];
    if (nd.count > 0) lane_slot[i] = leaves++;
    else right[i] = nd.next;
    const auto begin = static_cast<std::ptrdiff_t>(leaf_masses.size());
    for (std::uint32_t j = nd.first; j < nd.first + nd.count; ++j)
      for (std::size_t c = 0; c < kk; ++c) leaf_masses.push_back(corners[order[j] * kk + c]);
    std::sort(leaf_masses.begin() + begin, leaf_masses.end());
    leaf_masses.erase(std::unique(leaf_masses.begin() + begin, leaf_masses.end()), leaf_masses.end());
    mass_start.push_back(static_cast<std::uint32_t>(leaf_masses.size()));
  }
  lanes.resize(leaves);
  find_parts();
}

void SelfBvh::run_parts(int nt, void* f, void (*run)(void*, std::uint32_t, std::uint32_t)) const {
  parallel_for_dynamic(nt, static_cast<std::int64_t>(parts.size()), [&](std::int64_t p) {
    run(f, parts[static_cast<std::size_t>(p)][0], parts[static_cast<std::size_t>(p)][1]);
  });
}

void SelfBvh::find_parts() {
  parts.clear(), tops.clear();
  if (nodes.empty()) return;
  std::vector<std::array<std::uint32_t, 2>> stack{{0, 0}};  // (node, depth)
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    if (right[i] == 0 || depth == kPartDepth) {
      std::uint32_t last = i;  // (a subtree's last node is its rightmost leaf)
      while (right[last] != 0) last = right[last];
      parts.push_back({i, last + 1});
    } else {
      tops.push_back(i);
      stack.push_back({right[i], depth + 1}), stack.push_back({i + 1, depth + 1});
    }
  }
  std::sort(tops.begin(), tops.end());
}

void SelfBvh::fill_lanes(Lanes& l, const Node& leaf) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (std::uint32_t j = 0; j < 4; ++j)
    for (std::size_t a = 0; a < 3; ++a) {
      l.lo[a][j] = j < leaf.count ? box[leaf.first + j][a] : inf;
      l.hi[a][j] = j < leaf.count ? box[leaf.first + j][a + 3] : -inf;
    }
}

std::uint32_t SelfBvh::leaf_meets(const Lanes& a, std::uint32_t count, const Lanes& b, double r) {
  std::uint32_t hits = 0;
  for (std::uint32_t i = 0; i < count; ++i)
    for (std::uint32_t j = 0; j < 4; ++j) {
      bool meet = true;
      for (std::size_t k = 0; k < 3; ++k) meet = meet && a.lo[k][i] - r <= b.hi[k][j] && a.hi[k][i] + r >= b.lo[k][j];
      hits |= std::uint32_t{meet} << (4 * i + j);
    }
  return hits;
}

void SelfBvh::refit(const double* x, int nt) {
  const auto kk = static_cast<std::size_t>(k);
  box.resize(order.size());
  bottom_up(nt, [&](std::uint32_t i) {
    Node& nd = nodes[i];
    if (nd.count > 0) {
      nd.lo.fill(std::numeric_limits<double>::infinity()), nd.hi.fill(-std::numeric_limits<double>::infinity());
      for (std::uint32_t j = nd.first; j < nd.first + nd.count; ++j) {
        auto& b = box[j];
        constexpr double inf = std::numeric_limits<double>::infinity();
        b = {inf, inf, inf, -inf, -inf, -inf};
        for (std::size_t c = 0; c < kk; ++c) {
          const double* p = x + 3 * std::size_t{corners[order[j] * kk + c]};
          for (std::size_t a = 0; a < 3; ++a) b[a] = std::min(b[a], p[a]), b[a + 3] = std::max(b[a + 3], p[a]);
        }
        for (std::size_t a = 0; a < 3; ++a) nd.lo[a] = std::min(nd.lo[a], b[a]), nd.hi[a] = std::max(nd.hi[a], b[a + 3]);
      }
      fill_lanes(lanes[lane_slot[i]], nd);
    } else {
      const Node& l = nodes[i + 1];
      const Node& r = nodes[nd.next];
      for (int a = 0; a < 3; ++a) nd.lo[a] = std::min(l.lo[a], r.lo[a]), nd.hi[a] = std::max(l.hi[a], r.hi[a]);
    }
  });
}

std::vector<SelfBvh::NodePair> SelfBvh::join_tasks(const SelfBvh& other, double r, std::size_t want) const {
  std::vector<NodePair> tasks, next;
  if (nodes.empty() || other.nodes.empty()) return tasks;
  const bool self = &other == this;
  tasks.push_back({0, 0});
  // Each round splits every pair that has children, as join() would, until there are enough.
  for (bool split = true; split && tasks.size() < want;) {
    split = false;
    next.clear();
    for (const NodePair np : tasks) {
      const Node &na = nodes[np.a], &nb = other.nodes[np.b];
      if (!(self && np.a == np.b) && !near(na.lo, na.hi, nb.lo, nb.hi, r)) continue;
      if (na.count > 0 && nb.count > 0) {
        next.push_back(np);
      } else {  // (in the order a join pops them: the lists come out as from one join of the roots)
        const auto at = static_cast<std::ptrdiff_t>(next.size());
        descend(other, np, na.count > 0, nb.count > 0, next);
        std::reverse(next.begin() + at, next.end());
        split = true;
      }
    }
    tasks.swap(next);
  }
  return tasks;
}

}  // namespace clothsim::detail
