// Self-contact detection: every mass against the triangles it is not a corner of, every edge
// against the edges it shares no mass with, within the detection radius; each mass's bound is
// kSelfGamma times its distance to the nearest such element (its own, or one of its faces' or
// edges') less the pair's least gap, at most the radius. The pairs come from the candidate
// lists (self_lists.cpp).
#include "parallel.hpp"
#include "self_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>

namespace clothsim::detail {

namespace {

// The measured candidates that can come within their target before the next detection (their
// gap less the bounds of their masses), each with the direction of its gap (active_gap).
void keep_reachable(SelfScratch& sc) {
  sc.vt.clear(), sc.ee.clear();
  for (std::size_t k = 0; k < sc.active.size(); ++k) {
    const std::uint32_t j = sc.active[k];
    const SelfPair& p = candidate(sc, j);
    double reach = 0.0;
    for (std::uint32_t i : p.mass) reach = std::max(reach, std::isinf(sc.bound[i]) ? sc.pin_move[i] : sc.bound[i]);
    if (p.gap - 2.0 * reach >= p.target) continue;
    const bool vertex_triangle = j < sc.cand_vt.size();
    const Eigen::Vector3d& g = sc.active_gap[k];
    const double len = g.norm();
    (vertex_triangle ? sc.vt : sc.ee).push_back({p, len > 0.0 ? Eigen::Vector3d(g / len) : Eigen::Vector3d::Zero()});
  }
  sc.pair_masses.clear(), ++sc.stamp;  // (each mass once: the stamp marks those listed)
  for (const auto* list : {&sc.vt, &sc.ee})
    for (const SelfContact& c : *list)
      for (const std::uint32_t i : c.pair.mass)
        if (sc.listed[i] != sc.stamp) sc.listed[i] = sc.stamp, sc.pair_masses.push_back(i);
}

// The gaps of the active candidates at x, their vectors in active_gap (threads split them;
// each pair writes its own); a pair measured for the first time takes its target: the
// contact distance, or its distance at rest when that is less.
void measure(const Model& m, SelfScratch& sc, const Eigen::Matrix3Xd& x, const Workspace& ws) {
  const auto n = static_cast<std::int64_t>(sc.active.size());
  sc.active_gap.resize(sc.active.size());
  parallel_for(team(ws, sc.active.size()), n, [&](std::int64_t i) {
    double coef[4];
    const std::uint32_t j = sc.active[static_cast<std::size_t>(i)];
    SelfPair& p = candidate(sc, j);
    const bool vertex_triangle = j < sc.cand_vt.size();
    const Eigen::Vector3d& g = sc.active_gap[static_cast<std::size_t>(i)] = pair_gap(x, p.mass, vertex_triangle, coef);
    p.gap = g.norm();
    if (p.target < 0.0) p.target = std::min(sc.distance, pair_gap(m.x0, p.mass, vertex_triangle, coef).norm());
  });
}

// The median over the triangles of each one's shortest edge, in the rest shape.
double median_shortest_edge(const Model& m) {
  std::vector<double> shortest;
  for (std::size_t t = 0; t + 2 < m.triangles.size(); t += 3) {
    double s = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < 3; ++k)
      s = std::min(s, (m.x0.col(m.triangles[t + k]) - m.x0.col(m.triangles[t + (k + 1) % 3])).norm());
    shortest.push_back(s);
  }
  if (shortest.empty()) return 0.0;
  auto mid = shortest.begin() + static_cast<std::ptrdiff_t>(shortest.size() / 2);
  std::nth_element(shortest.begin(), mid, shortest.end());
  return *mid;
}

// The detection radius, `far` and the skin, as large as the mesh's typical shortest edge
// allows within their ranges (kSelfRadiusReach, kSelfListReach).
void choose_reach(double shortest_edge, SelfScratch& sc) {
  const double d = sc.distance, budget = kSelfRadiusReach * shortest_edge;
  const double r = std::clamp((budget / d - 1.0) / (1.0 + 2.0 * kSelfGamma), kSelfRadiusLeast, kSelfRadiusMost);
  sc.radius = r * d;
  // A pair farther than the radius bounds no mass below it; bounds of at most kSelfGamma times
  // the radius keep a pair this far beyond the contact distance until the next detection.
  sc.far = std::max(sc.radius, d + 2.0 * kSelfGamma * sc.radius);
  sc.skin = std::clamp(kSelfListReach * shortest_edge - sc.far, sc.radius, kSelfSkinMost * d);
}

}  // namespace

std::shared_ptr<SelfScratch> make_self_scratch(const Model& model) {
  if (model.options.self_collision != Switch::On || model.triangles.empty()) return nullptr;
  auto sc = std::make_shared<SelfScratch>();
  sc->triangles = model.triangles;
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  sc->in_face.assign(model.mass_count(), 0);
  for (std::size_t t = 0; t + 2 < model.triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = model.triangles[t + static_cast<std::size_t>(k)];
      const std::uint32_t b = model.triangles[t + static_cast<std::size_t>((k + 1) % 3)];
      sc->in_face[a] = 1;
      if (a != b) edges.emplace(std::min(a, b), std::max(a, b));
    }
  for (std::size_t i = 0; i < model.mass_count(); ++i)
    if (sc->in_face[i]) sc->faced_masses.push_back(static_cast<std::uint32_t>(i));
  for (const auto& [a, b] : edges) sc->edges.push_back(a), sc->edges.push_back(b);
  sc->common = std::none_of(sc->faced_masses.begin(), sc->faced_masses.end(), [&](std::uint32_t i) { return model.pinned[i] != 0; });
  sc->distance = model.contact.distance;
  choose_reach(median_shortest_edge(model), *sc);
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  sc->xd = sc->xs = sc->xpre = sc->xlim = Eigen::Matrix3Xd::Zero(3, n);
  sc->bound.assign(model.mass_count(), std::numeric_limits<double>::infinity());
  sc->pin_move.assign(model.mass_count(), 0.0);
  sc->weight.assign(model.mass_count(), 0.0);
  sc->held.assign(model.mass_count(), 0);
  sc->kept.assign(model.mass_count(), 0);
  sc->moved.assign(model.mass_count(), 0.0);
  sc->cluster_of.assign(model.mass_count(), 0);
  sc->reach.assign(model.mass_count(), 0.0);
  sc->away.assign(model.mass_count(), 0.0);
  sc->listed.assign(model.mass_count(), 0);
  return sc;
}

// Detects at the state's positions: every mass's bound, and the pairs that can reach their
// target before the next detection.
void detect_self(const Model& m, const State& state, double h, SelfScratch& sc, const Workspace& ws) {
  const Eigen::Matrix3Xd& x = state.x;
  // A pinned mass moves as its pin does (its speed over the step: a pin that turns); the free
  // masses of its pairs take what is left of the gap. A moving pin asks for a detection every step.
  const int nt = team(ws, m.mass_count());
  const auto n = static_cast<std::int64_t>(m.mass_count());
  sc.pins_move = parallel_any(nt, n, [&](std::int64_t i) {
    const auto k = static_cast<std::size_t>(i);
    const double move = m.pinned[k] ? kSelfLookAhead * h * state.v.col(i).norm() : 0.0;
    sc.pin_move[k] = move;
    sc.bound[k] = sc.in_face[k] && !m.pinned[k] ? sc.radius : std::numeric_limits<double>::infinity();
    return move > 0.0;
  });
  find_candidates(m, x, sc, ws);
  measure(m, sc, x, ws);
  sc.pin_room = std::numeric_limits<double>::infinity(), sc.overrun_pairs = 0;
  for (std::uint32_t j : sc.active) {
    const SelfPair& p = candidate(sc, j);
    double pinned = 0.0;
    for (std::uint32_t i : p.mass) pinned = std::max(pinned, sc.pin_move[i]);
    if (pinned > 0.0) {  // (a pin that moves past its gap in one step is outside the guarantee)
      sc.pin_room = std::min(sc.pin_room, p.gap / (pinned / kSelfLookAhead));
      sc.overrun_pairs += p.gap < pinned / kSelfLookAhead;
    }
    const double room = p.gap - pinned - (pinned > 0.0 ? 0.0 : kSelfLeastGap * p.target);
    for (std::uint32_t i : p.mass)
      if (!m.pinned[i]) sc.bound[i] = std::min(sc.bound[i], std::max(0.0, room));
  }
  parallel_for(nt, n, [&](std::int64_t i) {
    sc.bound[static_cast<std::size_t>(i)] *= kSelfGamma;
    sc.xd.col(i) = x.col(i);
  });
  keep_reachable(sc);
  sc.shift.setZero(), sc.drift.setZero();
  sc.follow = sc.common && ws.last_contacts == 0;
  sc.detect = false;
  ++sc.detections;
}

}  // namespace clothsim::detail

namespace clothsim {

std::optional<SelfContactCounts> self_contact_counts(const Workspace& ws) {
  if (!ws.self) return std::nullopt;
  const detail::SelfScratch& sc = *ws.self;
  return SelfContactCounts{sc.detections, sc.builds, sc.pin_overruns, sc.first_pin_overrun, sc.split_steps};
}

}  // namespace clothsim
