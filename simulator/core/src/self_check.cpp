// The candidate lists' check (docs/collision.md, "Self-contact"): whether the lists still hold
// every pair within `far`, a descent of the trees at xl whose nodes bound their masses' moves.
// Each check keeps where its descent stopped (the front, as in front tracking of bounding
// volume test trees) and the next starts there. The front splits into runs on the threads; they
// join in order, so the answer, the slack and the pairs found late are the same on any thread count.
#include "parallel.hpp"
#include "self_moves.hpp"

#include <array>
#include <atomic>
#include <limits>

namespace clothsim::detail {

void bound_moves(const SelfScratch& sc, const SelfBvh& t, std::vector<Box>& moves, int nt) {
  moves.resize(t.nodes.size());
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double* dl = sc.dl.data();
  t.bottom_up(nt, [&](std::uint32_t i) {
    Box& b = moves[i];
    if (t.right[i] != 0) {
      const Box &l = moves[i + 1], &r = moves[t.right[i]];
      for (int a = 0; a < 3; ++a) b[a] = std::min(l[a], r[a]), b[a + 3] = std::max(l[a + 3], r[a + 3]);
      return;
    }
    double lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    for (std::uint32_t j = t.mass_start[i]; j < t.mass_start[i + 1]; ++j) {
      const double* d = dl + 3 * std::size_t{t.leaf_masses[j]};
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], d[a]), hi[a] = std::max(hi[a], d[a]);
    }
    b = {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]};
  });
}

void bound_moves(SelfScratch& sc, const Eigen::Matrix3Xd& x, int nt) {
  constexpr Eigen::Index kBlocks = 16;  // (on threads: blocks of columns, each a vectorised difference)
  const Eigen::Index n = x.cols();
  sc.dl.resize(3, n);
  if (nt <= 1) sc.dl = x - sc.xl;
  else
    parallel_for(nt, kBlocks, [&](std::int64_t b) {
      const Eigen::Index begin = n * b / kBlocks, count = n * (b + 1) / kBlocks - begin;
      sc.dl.middleCols(begin, count) = x.middleCols(begin, count) - sc.xl.middleCols(begin, count);
    });
  bound_moves(sc, sc.mass_tree, sc.node_moved, nt);
}

std::uint32_t leaf_clears(const SelfBvh::Lanes& a, std::uint32_t count, const SelfBvh::Lanes& b, const LeafCheck& c,
                          double& least_room) {
  std::uint32_t left = 0;
  for (std::uint32_t i = 0; i < count; ++i)
    for (std::uint32_t j = c.one ? i + 1 : 0; j < c.other; ++j) {
      double s = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = std::max(std::max(a.lo[k][i] - b.hi[k][j], b.lo[k][j] - a.hi[k][i]), 0.0);
        s += d * d;
      }
      const double room = std::max(std::sqrt(s) - c.far, c.skin);
      if (c.moved <= room) least_room = std::min(least_room, room);
      else left |= std::uint32_t{1} << (4 * i + j);
    }
  return left;
}

namespace {

/// The check's first descent after a build hands the node pairs this deep to tasks.
constexpr int kCheckSplitDepth = 8;
/// A task tells the check's shared count of tests what it has added in batches of this many.
constexpr std::uint64_t kCheckTell = 4096;
/// The check splits the front into about this many runs for the threads.
constexpr std::size_t kCheckParts = 64;
/// Testing this many entries of the front counts as one test against the budget: an entry's
/// test is one box distance, a build's test of a pair its boxes and often their gap.
constexpr std::uint64_t kFrontWeight = 4;

using FrontEntry = SelfScratch::FrontEntry;
constexpr double kToDescend = -std::numeric_limits<double>::infinity();

// One descent of tree ta against tb (one tree: each pair once), with their nodes' move boxes.
struct Descent {
  const SelfScratch& sc;
  const SelfBvh &ta, &tb;
  const std::vector<Box>&ma, &mb;
#ifdef CLOTHSIM_AVX2
  decltype(&leaf_clears) clears_leaves = use_avx2() ? leaf_clears_avx2 : leaf_clears;
#else
  decltype(&leaf_clears) clears_leaves = leaf_clears;
#endif

  // How far apart node pair np's masses may move since xl with its masses not within `far`
  // unlisted, whatever they are: its boxes' distance at xl less `far`, at least the skin.
  double allowed(SelfBvh::NodePair np) const {
    return std::max(sc.skin, node_distance(ta.nodes[np.a], tb.nodes[np.b]) - sc.far);
  }
  double moved(SelfBvh::NodePair np) const { return apart(ma[np.a], mb[np.b]); }

  bool leaves(SelfBvh::NodePair np) const { return ta.nodes[np.a].count > 0 && tb.nodes[np.b].count > 0; }

  // Checks primitive pair (i of ta, j of tb, places in their trees' order), one its leaves'
  // move does not clear (leaf_clears): one that shares no mass, was at least far + skin apart
  // at xl and whose masses have moved apart by more than that distance less `far` may now be
  // within `far`, and is found late if it is not listed yet. Any other bounds the slack (how
  // much more its masses may move apart) and the limit of its leaf pair's entry.
  void check_pair(std::uint32_t i, std::uint32_t j, SelfScratch::CheckTask& out, double& limit) const {
    const auto ka = static_cast<std::size_t>(ta.k), kb = static_cast<std::size_t>(tb.k);
    const std::uint32_t *pa = &ta.corners[ta.order[i] * ka], *pb = &tb.corners[tb.order[j] * kb];
    double most2 = 0.0;  // (one square root for the largest: the same as the largest root)
    for (std::size_t a = 0; a < ka; ++a)
      for (std::size_t b = 0; b < kb; ++b) {
        if (pa[a] == pb[b]) return;
        most2 = std::max(most2, (move_of(sc, pa[a]) - move_of(sc, pb[b])).squaredNorm());
      }
    const double most = std::sqrt(most2);
    const Box &ba = ta.box[i], &bb = tb.box[j];
    const double allowed = std::max(sc.skin, box_distance(ba.data(), ba.data() + 3, bb.data(), bb.data() + 3) - sc.far);
    if (most <= allowed) {
      out.slack = std::min(out.slack, allowed - most), limit = std::min(limit, allowed);
      return;
    }
    const bool vt = ka == 1;
    const std::uint32_t lo = vt ? ta.order[i] : std::min(ta.order[i], tb.order[j]);
    const std::uint32_t hi = vt ? tb.order[j] : std::max(ta.order[i], tb.order[j]);
    const std::uint32_t* first = vt ? pa : &sc.edges[2 * std::size_t{lo}];
    const std::uint32_t* second = vt ? pb : &sc.edges[2 * std::size_t{hi}];
    const std::uint32_t q[4] = {first[0], vt ? second[0] : first[1], vt ? second[1] : second[0], vt ? second[2] : second[1]};
    double coef[4];
    const double at_xl = pair_gap(sc.xl, q, vt, coef).norm();
    if (at_xl < sc.far + sc.skin) return;  // (listed)
    if (most <= at_xl - sc.far) {
      out.slack = std::min(out.slack, at_xl - sc.far - most), limit = std::min(limit, at_xl - sc.far);
      return;
    }
    const std::uint64_t key = std::uint64_t{vt ? 0u : 1u} << 63 | std::uint64_t{lo} << 32 | hi;
    if (sc.late.count(key) > 0) return;  // (found late already)
    out.late.push_back({key, {{q[0], q[1], q[2], q[3]}, -1.0, 0.0, at_xl}});
  }

  // A leaf pair's primitive pairs; returns its entry's limit: the least room of the pairs
  // that are not listed.
  double check_leaves(SelfBvh::NodePair np, double moved, SelfScratch::CheckTask& t) const {
    const auto &na = ta.nodes[np.a], &nb = tb.nodes[np.b];
    const LeafCheck c{moved, sc.skin, sc.far, nb.count, &ta == &tb && np.a == np.b};
    t.work += c.one ? na.count * (na.count - 1) / 2 : na.count * nb.count;
    double limit = std::numeric_limits<double>::infinity();
    std::uint32_t left = clears_leaves(ta.lanes[ta.lane_slot[np.a]], na.count, tb.lanes[tb.lane_slot[np.b]], c, limit);
    t.slack = std::min(t.slack, limit - moved);
    for (; left != 0; left &= left - 1) {
      const auto bit = static_cast<std::uint32_t>(__builtin_ctz(left));
      check_pair(na.first + bit / 4, nb.first + bit % 4, t, limit);
    }
    return limit;
  }

  // The descent under node pair np; its entries go to t.front in the order it pops them.
  void descend(SelfBvh::NodePair start, SelfScratch::CheckTask& t, std::vector<SelfBvh::NodePair>& stack) const {
    stack.assign(1, start);
    while (!stack.empty()) {
      const SelfBvh::NodePair np = stack.back();
      stack.pop_back();
      ++t.work;
      const double room = allowed(np), move = moved(np);
      if (move <= room) {
        t.slack = std::min(t.slack, room - move);
        t.front.push_back({np, room});
      } else if (!leaves(np)) {
        ta.descend(tb, np, ta.nodes[np.a].count > 0, tb.nodes[np.b].count > 0, stack);
      } else {
        t.front.push_back({np, check_leaves(np, move, t)});
      }
    }
  }

  // Task t's run of the front: an entry whose nodes have not moved apart past its limit stays,
  // any other is descended again. It gives up once the whole check (`spent`, shared with the
  // other tasks) has tested more than `cap`: the lists are built again then.
  void run(const std::vector<FrontEntry>& front, SelfScratch::CheckTask& t, std::vector<SelfBvh::NodePair>& stack,
           std::atomic<std::uint64_t>& spent, std::uint64_t cap) const {
    t.work = 0, t.slack = std::numeric_limits<double>::infinity();
    t.front.clear(), t.late.clear();
    std::uint64_t told = 0, entries = 0;
    for (std::size_t k = t.begin; k < t.end; ++k) {
      const FrontEntry& e = front[k];
      const double move = moved(e.np);
      ++entries;
      if (move <= e.limit) {
        t.slack = std::min(t.slack, e.limit - move);
        t.front.push_back(e);
        continue;
      }
      descend(e.np, t, stack);
      if (t.work - told < kCheckTell) continue;  // (the shared count is told in batches: it is contended)
      if (spent.fetch_add(t.work - told, std::memory_order_relaxed) + (t.work - told) > cap) return;
      told = t.work;
    }
    t.work += entries / kFrontWeight;
    spent.fetch_add(t.work - told, std::memory_order_relaxed);
  }

  // The front of a first check after a build: the descent down to kCheckSplitDepth, the node
  // pairs it clears with their limits and those it leaves to descend, in the order one descent
  // pops them. Returns how many node pairs it tested.
  std::uint64_t split(SelfScratch& s, std::vector<FrontEntry>& front, double& slack) const {
    auto& stack = s.node_pairs;
    auto& depth = s.node_pair_depth;
    stack.assign(1, {0, 0}), depth.assign(1, 0);
    front.clear();
    std::uint64_t tested = 0;
    while (!stack.empty()) {
      const SelfBvh::NodePair np = stack.back();
      const std::uint8_t d = depth.back();
      stack.pop_back(), depth.pop_back();
      if (d >= kCheckSplitDepth || leaves(np)) {
        front.push_back({np, kToDescend});
        continue;
      }
      ++tested;
      const double room = allowed(np), move = moved(np);
      if (move <= room) {
        slack = std::min(slack, room - move);
        front.push_back({np, room});
        continue;
      }
      ta.descend(tb, np, ta.nodes[np.a].count > 0, tb.nodes[np.b].count > 0, stack);
      depth.resize(stack.size(), static_cast<std::uint8_t>(d + 1));
    }
    return tested;
  }
};

// Whether the lists hold every pair of primitives under trees ta and tb that is within `far` at
// x, with the pairs found late listed: a pair's gap changes by at most the most two of its
// masses, one of each element, have moved apart since xl. The check tests the front its last
// run left (the first after a build starts one). Not once the checks since the build have
// tested more than the budget (kSelfCheckWeight): the lists are built again then.
bool pairs_hold(SelfScratch& sc, std::vector<FrontEntry>& front, const SelfBvh& ta, const std::vector<Box>& ma,
                const SelfBvh& tb, const std::vector<Box>& mb, const Workspace& ws) {
  const Descent descent{sc, ta, tb, ma, mb};
  double slack = sc.slack;
  std::uint64_t work = front.empty() ? descent.split(sc, front, slack) : 0;
  const std::uint64_t budget = sc.build_work / kSelfCheckWeight;
  if (sc.check_work + work > budget) return false;
  const std::uint64_t cap = budget - sc.check_work - work;
  std::atomic<std::uint64_t> spent{0};
  const std::size_t parts = std::min(kCheckParts, front.size()), size = front.size();
  sc.check_tasks.resize(parts);
  for (std::size_t p = 0; p < parts; ++p) sc.check_tasks[p].begin = p * size / parts, sc.check_tasks[p].end = (p + 1) * size / parts;
  const int nt = team(ws, 4 * sc.faced_masses.size());
  sc.check_stacks.resize(static_cast<std::size_t>(std::max(1, nt)));
  parallel_for_dynamic(nt, static_cast<std::int64_t>(parts), [&](std::int64_t i) {
    auto& stack = sc.check_stacks[nt > 1 ? thread_num() : 0];
    descent.run(front, sc.check_tasks[static_cast<std::size_t>(i)], stack, spent, cap);
  });
  if (spent.load() > cap) return false;
  front.clear();
  for (const auto& t : sc.check_tasks) {
    work += t.work, slack = std::min(slack, t.slack);
    front.insert(front.end(), t.front.begin(), t.front.end());
  }
  sc.check_work += work, sc.slack = slack;
  for (const auto& t : sc.check_tasks)
    for (const auto& [key, pair] : t.late)
      if (sc.late.insert(key).second) (key >> 63 ? sc.cand_ee : sc.cand_vt).push_back(pair);
  return true;
}

}  // namespace

// When the lists hold, the masses may move apart by the slack more and they still hold: no
// check while no two masses have moved apart by the last check's slack since it.
bool candidates_hold(const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const int nt = team(ws, sc.faced_masses.size());
  // The box of the masses' moves since the last check: the union of kShares shares' boxes.
  constexpr std::size_t kShares = 16;
  std::array<Box, kShares> shares;
  const std::size_t masses = sc.faced_masses.size();
  parallel_for(nt, std::int64_t{kShares}, [&](std::int64_t s) {
    const auto share = static_cast<std::size_t>(s);
    Box& b = shares[share] = {inf, inf, inf, -inf, -inf, -inf};
    for (std::size_t k = masses * share / kShares; k < masses * (share + 1) / kShares; ++k) {
      const auto i = static_cast<Eigen::Index>(sc.faced_masses[k]);
      const Eigen::Vector3d d = x.col(i) - sc.xc.col(i);
      for (int a = 0; a < 3; ++a) b[a] = std::min(b[a], d[a]), b[a + 3] = std::max(b[a + 3], d[a]);
    }
  });
  Box since = {inf, inf, inf, -inf, -inf, -inf};
  for (const Box& b : shares)
    for (int a = 0; a < 3; ++a) since[a] = std::min(since[a], b[a]), since[a + 3] = std::max(since[a + 3], b[a + 3]);
  bound_moves(sc, x, nt);
  if (apart(since, since) < sc.slack) return true;
  sc.xc = x;
  sc.slack = sc.skin - apart(sc.node_moved[0], sc.node_moved[0]);
  if (sc.slack >= 0.0) return true;  // (no two masses moved apart by more than the skin)
  sc.slack = inf;
  bound_moves(sc, sc.triangle_tree, sc.triangle_moved, team(ws, sc.triangles.size() / 3));
  if (!pairs_hold(sc, sc.front_vt, sc.mass_tree, sc.node_moved, sc.triangle_tree, sc.triangle_moved, ws)) return false;
  bound_moves(sc, sc.edge_tree, sc.edge_moved, team(ws, sc.edges.size() / 2));
  return pairs_hold(sc, sc.front_ee, sc.edge_tree, sc.edge_moved, sc.edge_tree, sc.edge_moved, ws);
}

}  // namespace clothsim::detail
