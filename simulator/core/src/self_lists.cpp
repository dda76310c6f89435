// The self-contact candidate lists (a Verlet list): every pair of elements within `far` and a
// skin at the positions xl where they were found, and the pairs found late. A pair's gap
// changes by at most the largest relative move of two of its masses since xl, so a pair the
// lists lack may be within `far` only when two of its masses have moved apart by more than the
// skin, or by more than their distance at xl allows when farther; the check finds those pairs
// and lists them (self_check.cpp).
#include "parallel.hpp"
#include "self_moves.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace clothsim::detail {

namespace {

// Finds the pairs of one kind, a task of `tasks` at a time on the Workspace's threads; the
// tasks' lists join in task order, so the result is the same for any thread count. Counts the
// node pairs and pairs tested into build_work.
template <class Each>
void find_pairs(const std::vector<SelfBvh::NodePair>& tasks, std::size_t work, SelfScratch& sc, const Workspace& ws,
                std::vector<SelfPair>& out, Each each) {
  sc.found.resize(std::max(sc.found.size(), tasks.size()));
  parallel_for_dynamic(team(ws, work), static_cast<std::int64_t>(tasks.size()), [&](std::int64_t i) {
    auto& found = sc.found[static_cast<std::size_t>(i)];
    found.pairs.clear(), found.meeting.clear(), found.tested = 0;
    each(tasks[static_cast<std::size_t>(i)], found);
  });
  out.clear();
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    out.insert(out.end(), sc.found[i].pairs.begin(), sc.found[i].pairs.end());
    sc.build_work += sc.found[i].tested;
  }
}

// A found pair: kept when nearer than r. Its target is found when it is first measured.
void keep(const Eigen::Matrix3Xd& x, double r, std::array<std::uint32_t, 4> masses, bool vertex_triangle,
          SelfScratch::Found& out) {
  SelfPair p{{masses[0], masses[1], masses[2], masses[3]}, -1.0, 0.0, 0.0};
  double coef[4];
  p.built = pair_gap(x, p.mass, vertex_triangle, coef).norm();
  if (p.built < r) out.pairs.push_back(p);
}

// keep() for the pairs found whose boxes meet (in their order), four at a time ruling out
// those surely r or more apart in AVX2 lanes.
void keep_meeting(const Eigen::Matrix3Xd& x, double r, bool vertex_triangle, SelfScratch::Found& out) {
  const auto& e = out.meeting;
  std::size_t k = 0;
#ifdef CLOTHSIM_AVX2
  if (use_avx2()) {
    const auto apart_of = vertex_triangle ? masses_apart_avx2 : edges_apart_avx2;
    for (; k + 4 <= e.size(); k += 4) {
      const std::uint32_t apart = apart_of(x.data(), &e[k], r);
      for (std::size_t j = 0; j < 4; ++j)
        if (!(apart >> j & 1u)) keep(x, r, e[k + j], vertex_triangle, out);
    }
  }
#endif
  for (; k < e.size(); ++k) keep(x, r, e[k], vertex_triangle, out);
}

// The masses' clusters: the highest nodes of the masses' tree with at most kSelfCluster masses
// under them (a subtree's masses are a range of the tree's order).
void find_clusters(SelfScratch& sc) {
  const SelfBvh& t = sc.mass_tree;
  std::vector<std::array<std::uint32_t, 2>> range(t.nodes.size());  // [first, end) in t.order
  for (std::size_t i = t.nodes.size(); i-- > 0;) {
    const auto& nd = t.nodes[i];
    range[i] = nd.count > 0 ? std::array{nd.first, nd.first + nd.count}
                            : std::array{range[i + 1][0], range[nd.next][1]};
  }
  sc.cluster_node.clear();
  sc.cluster_at.assign(t.nodes.size(), kNoCluster);
  std::vector<std::uint32_t> stack{0};
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    if (range[i][1] - range[i][0] <= kSelfCluster || t.nodes[i].count > 0) {
      const auto c = static_cast<std::uint32_t>(sc.cluster_node.size());
      for (std::uint32_t k = range[i][0]; k < range[i][1]; ++k) sc.cluster_of[sc.faced_masses[t.order[k]]] = c;
      sc.cluster_at[i] = c;
      sc.cluster_node.push_back(i);
    } else {
      stack.push_back(t.nodes[i].next), stack.push_back(i + 1);
    }
  }
}

// Each cluster's neighbours at xl: the clusters (itself among them) within far + skin and
// their masses' longest edges, which hold every mass of a candidate with one of its own.
void link_clusters(SelfScratch& sc) {
  const SelfBvh& t = sc.mass_tree;
  const double r = sc.far + sc.skin;
  std::vector<std::array<std::uint32_t, 2>> links;
  auto& stack = sc.node_pairs;
  stack.assign(1, {0, 0});
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    const auto &na = t.nodes[a], &nb = t.nodes[b];
    const std::uint32_t ca = sc.cluster_at[a], cb = sc.cluster_at[b];
    if (a != b && node_distance(na, nb) > r + sc.node_reach[a] + sc.node_reach[b]) continue;
    if (ca != kNoCluster && cb != kNoCluster) {
      links.push_back({ca, cb});
      if (a != b) links.push_back({cb, ca});
    } else {
      t.descend(t, {a, b}, ca != kNoCluster, cb != kNoCluster, stack);
    }
  }
  // (grouped by their first cluster, a counting sort: only each cluster's set matters)
  sc.near_first.assign(sc.cluster_node.size() + 1, 0);
  for (const auto& l : links) ++sc.near_first[l[0] + 1];
  for (std::size_t c = 0; c + 1 < sc.near_first.size(); ++c) sc.near_first[c + 1] += sc.near_first[c];
  sc.near.resize(links.size());
  std::vector<std::uint32_t> at(sc.near_first.begin(), sc.near_first.end() - 1);
  for (const auto& l : links) sc.near[at[l[0]]++] = l[1];
}

// Each mass's longest edge at xl, and each node's of the masses' tree: no point of an element
// is farther from one of its masses than that mass's longest edge.
void measure_reach(SelfScratch& sc) {
  std::fill(sc.reach.begin(), sc.reach.end(), 0.0);
  for (std::size_t e = 0; e < sc.edges.size(); e += 2) {
    const std::uint32_t a = sc.edges[e], b = sc.edges[e + 1];
    const double len = (sc.xl.col(a) - sc.xl.col(b)).norm();
    sc.reach[a] = std::max(sc.reach[a], len), sc.reach[b] = std::max(sc.reach[b], len);
  }
  const SelfBvh& t = sc.mass_tree;
  sc.node_reach.resize(t.nodes.size());
  for (std::size_t i = t.nodes.size(); i-- > 0;) {
    const auto& nd = t.nodes[i];
    double most = nd.count > 0 ? 0.0 : std::max(sc.node_reach[i + 1], sc.node_reach[nd.next]);
    for (std::uint32_t j = nd.first; j < nd.first + nd.count; ++j)
      most = std::max(most, sc.reach[sc.faced_masses[t.order[j]]]);
    sc.node_reach[i] = most;
  }
}

// The candidate lists at positions x: every pair within `far` and the skin, from joins of the
// masses' tree with the triangles' and of the edges' tree with itself.
void build_candidates(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws) {
  const bool rebuild = sc.builds++ % 8 == 0;  // the trees follow the cloth's shape: rebuilt now and then
  if (rebuild) {
    sc.mass_tree.build(x.data(), sc.faced_masses, 1, team(ws, sc.faced_masses.size()));
    sc.triangle_tree.build(x.data(), sc.triangles, 3, team(ws, sc.triangles.size() / 3));
    sc.edge_tree.build(x.data(), sc.edges, 2, team(ws, sc.edges.size() / 2));
  } else {
    sc.mass_tree.refit(x.data(), team(ws, sc.faced_masses.size()));
    sc.triangle_tree.refit(x.data(), team(ws, sc.triangles.size() / 3));
    sc.edge_tree.refit(x.data(), team(ws, sc.edges.size() / 2));
  }
  const double r = sc.far + sc.skin;
  const std::size_t work = 4 * m.mass_count();
  sc.build_work = 0, sc.check_work = 0;
  sc.front_vt.clear(), sc.front_ee.clear();
  find_pairs(sc.mass_tree.join_tasks(sc.triangle_tree, r, kSelfJoinTasks), work, sc, ws, sc.cand_vt,
             [&](SelfBvh::NodePair np, SelfScratch::Found& out) {
               out.tested += sc.mass_tree.join(sc.triangle_tree, np, r, [&](std::uint32_t i, std::uint32_t t) {
                 const std::uint32_t v = sc.faced_masses[i], *c = &sc.triangles[3 * std::size_t{t}];
                 if (c[0] != v && c[1] != v && c[2] != v) out.meeting.push_back({v, c[0], c[1], c[2]});
               });
               keep_meeting(x, r, true, out);
             });
  find_pairs(sc.edge_tree.join_tasks(sc.edge_tree, r, kSelfJoinTasks), work, sc, ws, sc.cand_ee,
             [&](SelfBvh::NodePair np, SelfScratch::Found& out) {
               out.tested += sc.edge_tree.join(sc.edge_tree, np, r, [&](std::uint32_t e, std::uint32_t f) {
                 const std::uint32_t* ab = &sc.edges[2 * std::size_t{std::min(e, f)}];
                 const std::uint32_t* cd = &sc.edges[2 * std::size_t{std::max(e, f)}];
                 if (cd[0] != ab[0] && cd[0] != ab[1] && cd[1] != ab[0] && cd[1] != ab[1])
                   out.meeting.push_back({ab[0], ab[1], cd[0], cd[1]});
               });
               keep_meeting(x, r, false, out);
             });
  sc.built_vt = sc.cand_vt.size(), sc.built_ee = sc.cand_ee.size();
  sc.late.clear();
  sc.xl = x;
  measure_reach(sc);
  if (rebuild) find_clusters(sc);
  link_clusters(sc);
}

// Each mass's bound on how much the gaps of its candidates have changed since xl: the most
// the masses of its cluster and of its cluster's neighbours have moved apart.
void bound_gap_changes(SelfScratch& sc, const Workspace& ws) {
  sc.cluster_moved.resize(sc.cluster_node.size());
  parallel_for(team(ws, sc.near.size()), static_cast<std::int64_t>(sc.cluster_node.size()), [&](std::int64_t c) {
    double most = 0.0;
    for (std::uint32_t k = sc.near_first[c]; k < sc.near_first[c + 1]; ++k)
      most = std::max(most, apart(sc.node_moved[sc.cluster_node[c]], sc.node_moved[sc.cluster_node[sc.near[k]]]));
    sc.cluster_moved[static_cast<std::size_t>(c)] = most;
  });
  parallel_for(team(ws, sc.faced_masses.size()), static_cast<std::int64_t>(sc.faced_masses.size()), [&](std::int64_t k) {
    const std::uint32_t i = sc.faced_masses[static_cast<std::size_t>(k)];
    sc.moved[i] = sc.cluster_moved[sc.cluster_of[i]];
  });
}

// How much a candidate's gap can have changed since xl: the most two of its masses, one of
// each element, have moved apart.
double gap_change(const SelfScratch& sc, std::uint32_t j) {
  const std::uint32_t* q = candidate(sc, j).mass;
  const int split = j < sc.cand_vt.size() ? 1 : 2;
  double most2 = 0.0;
  for (int a = 0; a < split; ++a)
    for (int b = split; b < 4; ++b) most2 = std::max(most2, (move_of(sc, q[a]) - move_of(sc, q[b])).squaredNorm());
  return std::sqrt(most2);
}

// Whether candidate j may now be within `far` (its masses' bounds, then its own), or has a
// pin that moves.
bool may_be_near(const SelfScratch& sc, std::uint32_t j) {
  const SelfPair& p = candidate(sc, j);
  double pin = 0.0, most = 0.0;
  for (std::uint32_t q : p.mass) most = std::max(most, sc.moved[q]);
  if (sc.pins_move)
    for (std::uint32_t q : p.mass) pin = std::max(pin, sc.pin_move[q]);
  const std::size_t nvt = sc.cand_vt.size();
  const bool late = j < nvt ? j >= sc.built_vt : j - nvt >= sc.built_ee;  // (its clusters may not be linked)
  return pin > 0.0 || ((late || p.built - most < sc.far) && p.built - gap_change(sc, j) < sc.far);
}

// Orders `active` as the response pushes them: by their lowest mass (pushed in the trees'
// order, region by region, the twist scene's strain runs away after 4 s: measured), then by
// their masses, an order that does not depend on when the lists were built. A counting sort by
// lowest mass, then each mass's few pairs sorted, each with its masses at hand.
void order_active(SelfScratch& sc, const Workspace& ws) {
  auto& keyed = sc.keyed;
  keyed.resize(sc.active.size());
  const int nt = team(ws, sc.active.size());
  parallel_for(nt, static_cast<std::int64_t>(sc.active.size()), [&](std::int64_t i) {
    const auto k = static_cast<std::size_t>(i);
    const std::uint32_t* q = candidate(sc, sc.active[k]).mass;
    keyed[k] = {{q[0], q[1], q[2], q[3]}, sc.active[k]};
  });
  const auto lowest = [](const SelfScratch::Keyed& e) { return std::min({e.mass[0], e.mass[1], e.mass[2], e.mass[3]}); };
  auto& at = sc.order_at;
  at.assign(sc.in_face.size() + 1, 0);  // (one place per mass, and the end)
  for (const auto& e : keyed) ++at[lowest(e) + 1];
  for (std::size_t i = 1; i < at.size(); ++i) at[i] += at[i - 1];
  auto& ordered = sc.keyed_ordered;
  ordered.resize(keyed.size());
  for (const auto& e : keyed) ordered[at[lowest(e)]++] = e;  // (then at[i] ends mass i's pairs)
  const auto by_masses = [](const SelfScratch::Keyed& a, const SelfScratch::Keyed& b) { return a.mass < b.mass; };
  const auto place = [&](std::size_t k) { return ordered.begin() + static_cast<std::ptrdiff_t>(k); };
  parallel_for(nt, static_cast<std::int64_t>(at.size() - 1), [&](std::int64_t i) {
    const std::size_t begin = i == 0 ? 0 : at[static_cast<std::size_t>(i) - 1], end = at[static_cast<std::size_t>(i)];
    if (end - begin > 1) std::sort(place(begin), place(end), by_masses);
  });
  parallel_for(nt, static_cast<std::int64_t>(ordered.size()), [&](std::int64_t k) {
    sc.active[static_cast<std::size_t>(k)] = ordered[static_cast<std::size_t>(k)].j;
  });
}

}  // namespace

void find_candidates(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws) {
  if (sc.xl.cols() != x.cols() || !candidates_hold(x, sc, ws)) {  // (the check bounds the moves)
    build_candidates(m, x, sc, ws);
    bound_moves(sc, x, team(ws, sc.faced_masses.size()));
    sc.xc = x;
    sc.slack = sc.skin;
  }
  bound_gap_changes(sc, ws);
  // The candidates that may now be within `far`, all those of a pin that moves: a few runs of
  // the lists, each on a thread; their parts join in order.
  const auto pairs = static_cast<std::uint32_t>(sc.cand_vt.size() + sc.cand_ee.size());
  const std::uint32_t part = pairs / kSelfJoinTasks + 1;
  sc.chosen.resize(kSelfJoinTasks);
  parallel_for_dynamic(team(ws, pairs), std::int64_t{kSelfJoinTasks}, [&](std::int64_t t) {
    auto& out = sc.chosen[static_cast<std::size_t>(t)];
    out.clear();
    const auto begin = static_cast<std::uint32_t>(t) * part, end = std::min(pairs, begin + part);
    for (std::uint32_t j = begin; j < end; ++j)
      if (may_be_near(sc, j)) out.push_back(j);
  });
  sc.active.clear();
  for (const auto& c : sc.chosen) sc.active.insert(sc.active.end(), c.begin(), c.end());
  order_active(sc, ws);
}

}  // namespace clothsim::detail
