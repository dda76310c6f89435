// Self-contact detection: every mass against the triangles it is not a corner of, every edge
// against the edges it shares no mass with, within the detection radius; each mass's bound is
// kSelfGamma times its distance to the nearest such element (its own, or one of its faces' or
// edges'), at most the radius. The pairs come from candidate lists (a Verlet list) that hold
// every pair within the radius and a skin, found again once a mass has moved half the skin.
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
void find_pairs(std::size_t count, SelfScratch& sc, const Workspace& ws, std::vector<SelfPair>& out, Each each) {
  [[maybe_unused]] const int nt = team(ws, 4 * count);
  sc.found.resize(static_cast<std::size_t>(std::max(nt, 1)));
  for (auto& f : sc.found) f.clear();
  const auto n = static_cast<std::int64_t>(count);
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) each(static_cast<std::size_t>(i), sc.found[thread_num()]);
  out.clear();
  for (const auto& f : sc.found) out.insert(out.end(), f.begin(), f.end());
}

// A found pair: kept when nearer than r, with its target: the contact distance, or its
// distance at rest when that is less.
void keep(const Model& m, const Eigen::Matrix3Xd& x, double r, std::array<std::uint32_t, 4> masses,
          bool vertex_triangle, double distance, std::vector<SelfPair>& out) {
  SelfPair p{{masses[0], masses[1], masses[2], masses[3]}, 0.0, 0.0};
  double coef[4];
  p.gap = pair_gap(x, p.mass, vertex_triangle, coef).norm();
  if (!(p.gap < r)) return;
  p.target = std::min(distance, pair_gap(m.x0, p.mass, vertex_triangle, coef).norm());
  out.push_back(p);
}

// Whether the box of masses m[0 .. k) meets [lo, hi].
bool box_meets(const double* x, const std::uint32_t* m, int k, const double lo[3], const double hi[3]) {
  for (int axis = 0; axis < 3; ++axis) {
    double mn = x[3 * std::size_t{m[0]} + static_cast<std::size_t>(axis)], mx = mn;
    for (int j = 1; j < k; ++j) {
      const double v = x[3 * std::size_t{m[j]} + static_cast<std::size_t>(axis)];
      mn = std::min(mn, v), mx = std::max(mx, v);
    }
    if (mn > hi[axis] || mx < lo[axis]) return false;
  }
  return true;
}

// The candidates that can come within their target before the next detection (their gap
// less the bounds of their masses).
void keep_reachable(const SelfScratch& sc, const std::vector<SelfPair>& candidates, std::vector<SelfPair>& out) {
  out.clear();
  for (const SelfPair& p : candidates) {
    double reach = 0.0;
    for (std::uint32_t i : p.mass) reach = std::max(reach, std::isinf(sc.bound[i]) ? sc.pin_move[i] : sc.bound[i]);
    if (p.gap - 2.0 * reach < p.target) out.push_back(p);
  }
}

// The candidate lists at positions x: every pair within the radius and the skin.
void build_candidates(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws) {
  if (sc.builds++ % 8 == 0) {  // the trees follow the cloth's shape: rebuilt now and then, else refitted
    sc.triangle_tree.build(x.data(), sc.triangles, 3);
    sc.edge_tree.build(x.data(), sc.edges, 2);
  } else {
    sc.triangle_tree.refit(x.data());
    sc.edge_tree.refit(x.data());
  }
  const double r = sc.radius + sc.skin;
  find_pairs(m.mass_count(), sc, ws, sc.cand_vt, [&](std::size_t i, std::vector<SelfPair>& out) {
    if (!sc.in_face[i]) return;
    const auto v = static_cast<std::uint32_t>(i);
    const double* p = x.data() + 3 * i;
    const double lo[3] = {p[0] - r, p[1] - r, p[2] - r}, hi[3] = {p[0] + r, p[1] + r, p[2] + r};
    sc.triangle_tree.query(lo, hi, [&](std::uint32_t t) {
      const std::uint32_t* c = &sc.triangles[3 * std::size_t{t}];
      if (c[0] != v && c[1] != v && c[2] != v && box_meets(x.data(), c, 3, lo, hi))
        keep(m, x, r, {v, c[0], c[1], c[2]}, true, sc.distance, out);
    });
  });
  find_pairs(sc.edges.size() / 2, sc, ws, sc.cand_ee, [&](std::size_t e, std::vector<SelfPair>& out) {
    const std::uint32_t a = sc.edges[2 * e], b = sc.edges[2 * e + 1];
    const double *pa = x.data() + 3 * std::size_t{a}, *pb = x.data() + 3 * std::size_t{b};
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::min(pa[k], pb[k]) - r, hi[k] = std::max(pa[k], pb[k]) + r;
    sc.edge_tree.query(lo, hi, [&](std::uint32_t f) {
      if (f <= e) return;  // (each pair once)
      const std::uint32_t* cd = &sc.edges[2 * std::size_t{f}];
      if (cd[0] != a && cd[0] != b && cd[1] != a && cd[1] != b && box_meets(x.data(), cd, 2, lo, hi))
        keep(m, x, r, {a, b, cd[0], cd[1]}, false, sc.distance, out);
    });
  });
  sc.xl = x;
}

// Whether the candidate lists still hold every pair within the detection radius: no mass has
// moved more than half the skin since they were built, apart from the cloth's common move (a
// gap does not change when everything moves alike).
bool candidates_hold(const Model& m, const Eigen::Matrix3Xd& x, const SelfScratch& sc) {
  if (sc.xl.cols() != x.cols()) return false;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    if (sc.in_face[i]) shift += x.col(static_cast<Eigen::Index>(i)) - sc.xl.col(static_cast<Eigen::Index>(i));
  shift /= static_cast<double>(sc.faced);
  const double limit = 0.25 * sc.skin * sc.skin;
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    if (sc.in_face[i] && (x.col(k) - sc.xl.col(k) - shift).squaredNorm() > limit) return false;
  }
  return true;
}

// The gaps of one candidate list at x (threads split it; each pair writes its own).
void measure(std::vector<SelfPair>& pairs, bool vertex_triangle, const Eigen::Matrix3Xd& x, const Workspace& ws) {
  const auto n = static_cast<std::int64_t>(pairs.size());
  [[maybe_unused]] const int nt = team(ws, pairs.size());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i) {
    double coef[4];
    SelfPair& p = pairs[static_cast<std::size_t>(i)];
    p.gap = pair_gap(x, p.mass, vertex_triangle, coef).norm();
  }
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
  sc->skin = kSelfSkin * sc->distance;
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  sc->xd = sc->xs = sc->xpre = sc->vpre = Eigen::Matrix3Xd::Zero(3, n);
  sc->bound.assign(model.mass_count(), std::numeric_limits<double>::infinity());
  sc->pin_move.assign(model.mass_count(), 0.0);
  sc->weight.assign(model.mass_count(), 0.0);
  sc->held.assign(model.mass_count(), 0);
  return sc;
}

// Detects at the state's positions: every mass's bound, and the pairs that can reach their
// target before the next detection.
void detect_self(const Model& m, const State& state, double h, SelfScratch& sc, const Workspace& ws) {
  const Eigen::Matrix3Xd& x = state.x;
  if (!candidates_hold(m, x, sc)) build_candidates(m, x, sc, ws);
  measure(sc.cand_vt, true, x, ws);
  measure(sc.cand_ee, false, x, ws);
  // A pinned mass moves as its pin does (its speed over the step: a pin that turns); the free
  // masses of its pairs take what is left of the gap. A moving pin asks for a detection every step.
  sc.pins_move = false;
  for (std::size_t i = 0; i < m.mass_count(); ++i) {
    const double move = m.pinned[i] ? kSelfLookAhead * h * state.v.col(static_cast<Eigen::Index>(i)).norm() : 0.0;
    sc.pin_move[i] = move;
    sc.pins_move = sc.pins_move || move > 0.0;
    sc.bound[i] = sc.in_face[i] && !m.pinned[i] ? sc.radius : std::numeric_limits<double>::infinity();
  }
  for (const auto* list : {&sc.cand_vt, &sc.cand_ee})
    for (const SelfPair& p : *list) {
      double pinned = 0.0;
      for (std::uint32_t i : p.mass) pinned = std::max(pinned, sc.pin_move[i]);
      for (std::uint32_t i : p.mass)
        if (!m.pinned[i]) sc.bound[i] = std::min(sc.bound[i], std::max(0.0, p.gap - pinned));
    }
  for (std::size_t i = 0; i < m.mass_count(); ++i) sc.bound[i] *= kSelfGamma;
  keep_reachable(sc, sc.cand_vt, sc.vt);
  keep_reachable(sc, sc.cand_ee, sc.ee);
  sc.xd = x;
  sc.detect = false;
}

}  // namespace clothsim::detail
