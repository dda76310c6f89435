// Self-contact detection: every mass against the triangles it is not a corner of, every edge
// against the edges it shares no mass with, within the detection radius; each mass's bound is
// kSelfGamma times its distance to the nearest such element (its own, or one of its faces' or
// edges') less the pair's least gap, at most the radius. The pairs come from candidate lists
// (a Verlet list) that hold every pair within `far` and a skin, found again once a mass has
// moved half the skin; a detection measures only the candidates that may have come within
// `far` (their distance in the lists less twice their masses' largest move since).
#include "parallel.hpp"
#include "self_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>

namespace clothsim::detail {

namespace {

// Finds the pairs of one kind on the Workspace's threads; the per-thread lists join in the
// serial order, so the result is the same for any thread count.
template <class Each>
void find_pairs(std::size_t count, std::size_t work, SelfScratch& sc, const Workspace& ws, std::vector<SelfPair>& out,
                Each each) {
  [[maybe_unused]] const int nt = team(ws, work);
  sc.found.resize(static_cast<std::size_t>(std::max(nt, 1)));
  for (auto& f : sc.found) f.clear();
  const auto n = static_cast<std::int64_t>(count);
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) each(static_cast<std::size_t>(i), sc.found[thread_num()]);
  out.clear();
  for (const auto& f : sc.found) out.insert(out.end(), f.begin(), f.end());
}

// A found pair: kept when nearer than r. Its target is found when it is first measured.
void keep(const Eigen::Matrix3Xd& x, double r, std::array<std::uint32_t, 4> masses, bool vertex_triangle,
          std::vector<SelfPair>& out) {
  SelfPair p{{masses[0], masses[1], masses[2], masses[3]}, -1.0, 0.0, 0.0};
  double coef[4];
  p.built = pair_gap(x, p.mass, vertex_triangle, coef).norm();
  if (p.built < r) out.push_back(p);
}

// The measured candidates that can come within their target before the next detection (their
// gap less the bounds of their masses), each with the direction of its gap at x.
void keep_reachable(SelfScratch& sc, const Eigen::Matrix3Xd& x) {
  sc.vt.clear(), sc.ee.clear();
  for (std::uint32_t j : sc.active) {
    const SelfPair& p = candidate(sc, j);
    double reach = 0.0;
    for (std::uint32_t i : p.mass) reach = std::max(reach, std::isinf(sc.bound[i]) ? sc.pin_move[i] : sc.bound[i]);
    if (p.gap - 2.0 * reach >= p.target) continue;
    const bool vertex_triangle = j < sc.cand_vt.size();
    double coef[4];
    const Eigen::Vector3d g = pair_gap(x, p.mass, vertex_triangle, coef);
    const double len = g.norm();
    (vertex_triangle ? sc.vt : sc.ee).push_back({p, len > 0.0 ? Eigen::Vector3d(g / len) : Eigen::Vector3d::Zero()});
  }
}

// Each mass's move since the candidate lists were built, apart from the cloth's common move (a
// gap does not change when everything moves alike). Whether the lists still hold every pair
// within `far`: no mass has moved more than half the skin.
bool candidates_hold(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc) {
  if (sc.xl.cols() != x.cols()) return false;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (sc.in_face[i]) shift += x.col(static_cast<Eigen::Index>(i)) - sc.xl.col(static_cast<Eigen::Index>(i));
  shift /= static_cast<double>(sc.faced);
  bool hold = true;
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    sc.moved[i] = sc.in_face[i] ? (x.col(k) - sc.xl.col(k) - shift).norm() : 0.0;
    hold = hold && sc.moved[i] <= 0.5 * sc.skin;
  }
  return hold;
}

// Each mass's candidates (an index over both lists, vt first) and its least distance among them.
void index_candidates(SelfScratch& sc, std::size_t n) {
  const auto pairs = static_cast<std::uint32_t>(sc.cand_vt.size() + sc.cand_ee.size());
  sc.nearest.assign(n, std::numeric_limits<double>::infinity());
  sc.first.assign(n + 1, 0);
  for (std::uint32_t j = 0; j < pairs; ++j)
    for (std::uint32_t i : candidate(sc, j).mass) ++sc.first[i + 1], sc.nearest[i] = std::min(sc.nearest[i], candidate(sc, j).built);
  for (std::size_t i = 0; i < n; ++i) sc.first[i + 1] += sc.first[i];
  sc.incident.resize(4 * pairs);
  std::vector<std::uint32_t>& fill = sc.active;  // (a cursor per mass, reused)
  fill.assign(sc.first.begin(), sc.first.end() - 1);
  for (std::uint32_t j = 0; j < pairs; ++j)
    for (std::uint32_t i : candidate(sc, j).mass) sc.incident[fill[i]++] = j;
  sc.stamp.assign(pairs, 0);
  std::fill(sc.moved.begin(), sc.moved.end(), 0.0);
}

// The candidate lists at positions x: every pair within `far` and the skin.
void build_candidates(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws) {
  if (sc.builds++ % 8 == 0) {  // the trees follow the cloth's shape: rebuilt now and then, else refitted
    sc.triangle_tree.build(x.data(), sc.triangles, 3);
    sc.edge_tree.build(x.data(), sc.edges, 2);
  } else {
    sc.triangle_tree.refit(x.data());
    sc.edge_tree.refit(x.data());
  }
  const double r = sc.far + sc.skin;
  find_pairs(m.mass_count(), 4 * m.mass_count(), sc, ws, sc.cand_vt, [&](std::size_t i, std::vector<SelfPair>& out) {
    if (!sc.in_face[i]) return;
    const auto v = static_cast<std::uint32_t>(i);
    const double* p = x.data() + 3 * i;
    const double lo[3] = {p[0] - r, p[1] - r, p[2] - r}, hi[3] = {p[0] + r, p[1] + r, p[2] + r};
    sc.triangle_tree.query(lo, hi, [&](std::uint32_t t) {
      const std::uint32_t* c = &sc.triangles[3 * std::size_t{t}];
      if (c[0] != v && c[1] != v && c[2] != v) keep(x, r, {v, c[0], c[1], c[2]}, true, out);
    });
  });
  find_pairs(sc.edges.size() / 2, 2 * sc.edges.size(), sc, ws, sc.cand_ee, [&](std::size_t e, std::vector<SelfPair>& out) {
    const std::uint32_t a = sc.edges[2 * e], b = sc.edges[2 * e + 1];
    const double *pa = x.data() + 3 * std::size_t{a}, *pb = x.data() + 3 * std::size_t{b};
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::min(pa[k], pb[k]) - r, hi[k] = std::max(pa[k], pb[k]) + r;
    sc.edge_tree.query(lo, hi, [&](std::uint32_t f) {
      if (f <= e) return;  // (each pair once)
      const std::uint32_t* cd = &sc.edges[2 * std::size_t{f}];
      if (cd[0] != a && cd[0] != b && cd[1] != a && cd[1] != b) keep(x, r, {a, b, cd[0], cd[1]}, false, out);
    });
  });
  sc.xl = x;
  index_candidates(sc, m.mass_count());
}

// The candidates to measure: among those of every mass that may be nearer than `far` to one
// of its candidates (its least distance at xl less twice its move), those whose distance at xl
// less twice their masses' largest move is below `far`; all those of a pin that moves. The
// others are farther than `far` apart.
void choose_active(const Model& m, SelfScratch& sc, double far) {
  ++sc.detections;
  sc.active.clear();
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    if (sc.pin_move[i] == 0.0 && sc.nearest[i] - 2.0 * sc.moved[i] >= far) continue;
    for (std::uint32_t k = sc.first[i]; k < sc.first[i + 1]; ++k) {
      const std::uint32_t j = sc.incident[k];
      if (sc.stamp[j] == sc.detections) continue;
      sc.stamp[j] = sc.detections;  // (each pair decided once, on its own masses: any visiting order)
      double moved = 0.0, pin = 0.0;
      for (std::uint32_t q : candidate(sc, j).mass) moved = std::max(moved, sc.moved[q]), pin = std::max(pin, sc.pin_move[q]);
      if (pin > 0.0 || candidate(sc, j).built - 2.0 * moved < far) sc.active.push_back(j);
    }
  }
}

// The gaps of the active candidates at x (threads split them; each pair writes its own); a
// pair measured for the first time takes its target: the contact distance, or its distance
// at rest when that is less.
void measure(const Model& m, SelfScratch& sc, const Eigen::Matrix3Xd& x, const Workspace& ws) {
  const auto n = static_cast<std::int64_t>(sc.active.size());
  [[maybe_unused]] const int nt = team(ws, sc.active.size());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) {
    double coef[4];
    const std::uint32_t j = sc.active[static_cast<std::size_t>(i)];
    SelfPair& p = candidate(sc, j);
    const bool vertex_triangle = j < sc.cand_vt.size();
    p.gap = pair_gap(x, p.mass, vertex_triangle, coef).norm();
    if (p.target < 0.0) p.target = std::min(sc.distance, pair_gap(m.x0, p.mass, vertex_triangle, coef).norm());
  }
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
  sc->faced = static_cast<std::size_t>(std::count(sc->in_face.begin(), sc->in_face.end(), 1));
  for (const auto& [a, b] : edges) sc->edges.push_back(a), sc->edges.push_back(b);
  sc->distance = model.contact.distance;
  sc->radius = kSelfRadius * sc->distance;
  // A pair farther than the radius bounds no mass below it; bounds of at most kSelfGamma times
  // the radius keep a pair this far beyond the contact distance until the next detection.
  sc->far = std::max(sc->radius, sc->distance + 2.0 * kSelfGamma * sc->radius);
  sc->skin = std::clamp(kSelfSkinReach * median_shortest_edge(model) - sc->far, kSelfSkinLeast * sc->distance,
                        kSelfSkinMost * sc->distance);
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  sc->xd = sc->xs = sc->xpre = sc->vpre = sc->xlim = Eigen::Matrix3Xd::Zero(3, n);
  sc->bound.assign(model.mass_count(), std::numeric_limits<double>::infinity());
  sc->pin_move.assign(model.mass_count(), 0.0);
  sc->weight.assign(model.mass_count(), 0.0);
  sc->held.assign(model.mass_count(), 0);
  sc->moved.assign(model.mass_count(), 0.0);
  sc->away.assign(model.mass_count(), 0.0);
  return sc;
}

// Detects at the state's positions: every mass's bound, and the pairs that can reach their
// target before the next detection.
void detect_self(const Model& m, const State& state, double h, SelfScratch& sc, const Workspace& ws) {
  const Eigen::Matrix3Xd& x = state.x;
  // A pinned mass moves as its pin does (its speed over the step: a pin that turns); the free
  // masses of its pairs take what is left of the gap. A moving pin asks for a detection every step.
  sc.pins_move = false;
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    const double move = m.pinned[i] ? kSelfLookAhead * h * state.v.col(static_cast<Eigen::Index>(i)).norm() : 0.0;
    sc.pin_move[i] = move;
    sc.pins_move = sc.pins_move || move > 0.0;
    sc.bound[i] = sc.in_face[i] && !m.pinned[i] ? sc.radius : std::numeric_limits<double>::infinity();
  }
  if (!candidates_hold(m, x, sc)) build_candidates(m, x, sc, ws);
  choose_active(m, sc, sc.far);
  measure(m, sc, x, ws);
  for (std::uint32_t j : sc.active) {
    const SelfPair& p = candidate(sc, j);
    double pinned = 0.0;
    for (std::uint32_t i : p.mass) pinned = std::max(pinned, sc.pin_move[i]);
    const double room = p.gap - pinned - (pinned > 0.0 ? 0.0 : kSelfLeastGap * p.target);
    for (std::uint32_t i : p.mass)
      if (!m.pinned[i]) sc.bound[i] = std::min(sc.bound[i], std::max(0.0, room));
  }
  for (std::size_t i = 0; i < m.mass_count(); ++i) sc.bound[i] *= kSelfGamma;
  keep_reachable(sc, x);
  sc.xd = x;
  sc.detect = false;
}

}  // namespace clothsim::detail
