// The candidate lists' check (docs/collision.md, "Self-contact"): whether the lists still hold
// every pair within `far`, a descent of the trees at xl whose nodes bound their masses' moves.
// The descent splits into tasks on the threads; they join in the order one descent would take
// them, so the answer, the slack and the pairs found late are the same on any thread count.
#include "parallel.hpp"
#include "self_moves.hpp"

#include <atomic>
#include <limits>

namespace clothsim::detail {

void bound_moves(const SelfScratch& sc, const SelfBvh& t, std::vector<Box>& moves) {
  moves.resize(t.nodes.size());
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double* dl = sc.dl.data();
  for (std::size_t i = t.nodes.size(); i-- > 0;) {
    const auto& nd = t.nodes[i];
    Box& b = moves[i];
    if (nd.count == 0) {
      const Box &l = moves[i + 1], &r = moves[nd.next];
      for (int a = 0; a < 3; ++a) b[a] = std::min(l[a], r[a]), b[a + 3] = std::max(l[a + 3], r[a + 3]);
      continue;
    }
    double lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    for (std::uint32_t j = t.mass_start[i]; j < t.mass_start[i + 1]; ++j) {
      const double* d = dl + 3 * std::size_t{t.leaf_masses[j]};
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], d[a]), hi[a] = std::max(hi[a], d[a]);
    }
    b = {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]};
  }
}

void bound_moves(SelfScratch& sc, const Eigen::Matrix3Xd& x) {
  sc.dl = x - sc.xl;
  bound_moves(sc, sc.mass_tree, sc.node_moved);
}

std::uint32_t leaf_clears(const SelfBvh::Lanes& a, std::uint32_t count, const SelfBvh::Lanes& b, const LeafCheck& c,
                          double& slack) {
  std::uint32_t left = 0;
  for (std::uint32_t i = 0; i < count; ++i)
    for (std::uint32_t j = c.one ? i + 1 : 0; j < c.other; ++j) {
      double s = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = std::max(std::max(a.lo[k][i] - b.hi[k][j], b.lo[k][j] - a.hi[k][i]), 0.0);
        s += d * d;
      }
      const double room = std::max(std::sqrt(s) - c.far, c.skin);
      if (c.moved <= room) slack = std::min(slack, room - c.moved);
      else left |= std::uint32_t{1} << (4 * i + j);
    }
  return left;
}

namespace {

/// The check's descent hands the node pairs this deep to tasks.
constexpr int kCheckSplitDepth = 8;
/// A task tells the check's shared count of tests what it has added in batches of this many.
constexpr std::uint64_t kCheckTell = 4096;

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

  // Whether node pair np's masses cannot have come within `far` unlisted; the slack takes its room.
  bool clears(SelfBvh::NodePair np, double& slack) const {
    const double allowed = std::max(sc.skin, node_distance(ta.nodes[np.a], tb.nodes[np.b]) - sc.far);
    const double moved = apart(ma[np.a], mb[np.b]);
    if (moved > allowed) return false;
    slack = std::min(slack, allowed - moved);
    return true;
  }

  bool leaves(SelfBvh::NodePair np) const { return ta.nodes[np.a].count > 0 && tb.nodes[np.b].count > 0; }

  // Checks primitive pair (i of ta, j of tb, places in their trees' order), one its leaves'
  // move does not clear (leaf_clears): one that shares no mass, was at least far + skin apart
  // at xl and whose masses have moved apart by more than that distance less `far` may now be
  // within `far`, and is found late if it is not listed yet. Any other bounds the slack: how
  // much more its masses may move apart.
  void check_pair(std::uint32_t i, std::uint32_t j, SelfScratch::CheckTask& out) const {
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
      out.slack = std::min(out.slack, allowed - most);
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
      out.slack = std::min(out.slack, at_xl - sc.far - most);
      return;
    }
    const std::uint64_t key = std::uint64_t{vt ? 0u : 1u} << 63 | std::uint64_t{lo} << 32 | hi;
    if (sc.late.count(key) > 0) return;  // (found late already)
    out.late.push_back({key, {{q[0], q[1], q[2], q[3]}, -1.0, 0.0, at_xl}});
  }

  // The descent under task t's node pair. It gives up once the whole check (`spent`, shared
  // with the other tasks) has tested more than `cap`: the lists are built again then.
  void run(SelfScratch::CheckTask& t, std::vector<SelfBvh::NodePair>& stack, std::atomic<std::uint64_t>& spent,
           std::uint64_t cap) const {
    const bool self = &ta == &tb;
    t.work = 0, t.at_last_leaf = 0, t.slack = std::numeric_limits<double>::infinity();
    t.late.clear();
    std::uint64_t told = 0;
    stack.assign(1, t.start);
    while (!stack.empty()) {
      const SelfBvh::NodePair np = stack.back();
      stack.pop_back();
      ++t.work;
      if (clears(np, t.slack)) continue;
      if (!leaves(np)) {
        ta.descend(tb, np, ta.nodes[np.a].count > 0, tb.nodes[np.b].count > 0, stack);
        continue;
      }
      const auto &na = ta.nodes[np.a], &nb = tb.nodes[np.b];
      const LeafCheck c{apart(ma[np.a], mb[np.b]), sc.skin, sc.far, nb.count, self && np.a == np.b};
      t.work += c.one ? na.count * (na.count - 1) / 2 : na.count * nb.count;
      for (std::uint32_t left = clears_leaves(ta.lanes[ta.lane_slot[np.a]], na.count, tb.lanes[tb.lane_slot[np.b]], c, t.slack);
           left != 0; left &= left - 1) {
        const auto bit = static_cast<std::uint32_t>(__builtin_ctz(left));
        check_pair(na.first + bit / 4, nb.first + bit % 4, t);
      }
      t.at_last_leaf = t.work;
      if (t.work - told < kCheckTell) continue;  // (the shared count is told in batches: it is contended)
      if (spent.fetch_add(t.work - told, std::memory_order_relaxed) + (t.work - told) > cap) return;
      told = t.work;
    }
    spent.fetch_add(t.at_last_leaf - told, std::memory_order_relaxed);
  }

  // The descent down to kCheckSplitDepth, in the order one descent pops node pairs: the node
  // pairs it leaves for tasks, each with the node pairs it tested before it. Returns how many
  // it tested.
  std::uint64_t split(SelfScratch& s, double& slack) const {
    auto& stack = s.node_pairs;
    auto& depth = s.node_pair_depth;
    stack.assign(1, {0, 0}), depth.assign(1, 0);
    std::size_t tasks = 0;
    std::uint64_t tested = 0;
    while (!stack.empty()) {
      const SelfBvh::NodePair np = stack.back();
      const std::uint8_t d = depth.back();
      stack.pop_back(), depth.pop_back();
      if (d >= kCheckSplitDepth || leaves(np)) {
        if (s.check_tasks.size() <= tasks) s.check_tasks.emplace_back();
        s.check_tasks[tasks].start = np, s.check_tasks[tasks++].before = tested;
        continue;
      }
      ++tested;
      if (clears(np, slack)) continue;
      ta.descend(tb, np, ta.nodes[np.a].count > 0, tb.nodes[np.b].count > 0, stack);
      depth.resize(stack.size(), static_cast<std::uint8_t>(d + 1));
    }
    s.check_tasks.resize(tasks);
    return tested;
  }
};

// Whether the lists hold every pair of primitives under trees ta and tb that is within `far` at
// x, with the pairs found late listed: a pair's gap changes by at most the most two of its
// masses, one of each element, have moved apart since xl. Not once the checks since the build
// have tested more node pairs and pairs than the budget (kSelfCheckWeight), counted up to the
// last leaf pair: the lists are built again then.
bool pairs_hold(SelfScratch& sc, const SelfBvh& ta, const std::vector<Box>& ma, const SelfBvh& tb,
                const std::vector<Box>& mb, const Workspace& ws) {
  const Descent descent{sc, ta, tb, ma, mb};
  double slack = sc.slack;
  const std::uint64_t split_work = descent.split(sc, slack);
  // (a check past twice the budget fails whatever its last leaf pair's count is)
  const std::uint64_t budget = sc.build_work / kSelfCheckWeight;
  const std::uint64_t cap = 2 * budget - std::min(budget, sc.check_work);
  std::atomic<std::uint64_t> spent{split_work};
  const int nt = team(ws, 4 * sc.faced_masses.size());
  sc.check_stacks.resize(static_cast<std::size_t>(std::max(1, nt)));
  parallel_for_dynamic(nt, static_cast<std::int64_t>(sc.check_tasks.size()), [&](std::int64_t i) {
    auto& stack = sc.check_stacks[nt > 1 ? thread_num() : 0];
    descent.run(sc.check_tasks[static_cast<std::size_t>(i)], stack, spent, cap);
  });
  if (spent.load() > cap) return false;
  std::uint64_t work = sc.check_work, last_leaf = 0, before = 0;
  for (const auto& t : sc.check_tasks) {
    work += t.before - before, before = t.before;
    if (t.at_last_leaf > 0) last_leaf = work + t.at_last_leaf;
    work += t.work;
    slack = std::min(slack, t.slack);
  }
  if (last_leaf > budget) return false;
  sc.check_work = work + split_work - before, sc.slack = slack;
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
  Box since = {inf, inf, inf, -inf, -inf, -inf};
  for (std::uint32_t i : sc.faced_masses) {
    const Eigen::Vector3d d = x.col(i) - sc.xc.col(i);
    for (int a = 0; a < 3; ++a) since[a] = std::min(since[a], d[a]), since[a + 3] = std::max(since[a + 3], d[a]);
  }
  bound_moves(sc, x);
  if (apart(since, since) < sc.slack) return true;
  sc.xc = x;
  sc.slack = sc.skin - apart(sc.node_moved[0], sc.node_moved[0]);
  if (sc.slack >= 0.0) return true;  // (no two masses moved apart by more than the skin)
  sc.slack = inf;
  bound_moves(sc, sc.triangle_tree, sc.triangle_moved);
  if (!pairs_hold(sc, sc.mass_tree, sc.node_moved, sc.triangle_tree, sc.triangle_moved, ws)) return false;
  bound_moves(sc, sc.edge_tree, sc.edge_moved);
  return pairs_hold(sc, sc.edge_tree, sc.edge_moved, sc.edge_tree, sc.edge_moved, ws);
}

}  // namespace clothsim::detail
