// Self-contact detection: every mass against the triangles it is not a corner of, every edge
// against the edges it shares no mass with, within the detection radius; each mass's bound is
// kSelfGamma times its distance to the nearest such element (its own, or one of its faces' or
// edges'), at most the radius.
#include "parallel.hpp"
#include "self_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <cstdio>
#include <cstdlib>

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

// A found pair: kept when nearer than the radius.
void keep(const Eigen::Matrix3Xd& x, const SelfScratch& sc, std::uint32_t a, std::uint32_t b, std::uint32_t c,
          std::uint32_t d, bool vertex_triangle, std::vector<SelfPair>& out) {
  SelfPair p{{a, b, c, d}, 0.0, 0.0};
  double coef[4];
  p.gap = pair_gap(x, p.mass, vertex_triangle, coef).norm();
  if (p.gap < sc.radius) out.push_back(p);
}

// Whether the boxes of masses a..(a + k) and of [lo, hi] meet.
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

// Keeps the pairs that can come within their target before the next detection (their gap
// less the bounds of their masses), each with its target: the contact distance, or its
// distance at rest when that is less.
void keep_reachable(const Model& m, SelfScratch& sc, std::vector<SelfPair>& pairs, bool vertex_triangle) {
  std::size_t kept = 0;
  for (SelfPair& p : pairs) {
    double reach = 0.0, coef[4];
    for (std::uint32_t i : p.mass) reach = std::max(reach, sc.bound[i]);
    if (p.gap - 2.0 * reach >= sc.distance) continue;
    p.target = std::min(sc.distance, pair_gap(m.x0, p.mass, vertex_triangle, coef).norm());
    pairs[kept++] = p;
  }
  pairs.resize(kept);
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
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  sc->xd = sc->xs = sc->xpre = Eigen::Matrix3Xd::Zero(3, n);
  sc->bound.assign(model.mass_count(), std::numeric_limits<double>::infinity());
  return sc;
}

// Detects at positions x: the pairs near each other and every mass's bound.
void detect_self(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws) {
  if (sc.refits++ % 16 == 0) {  // the trees follow the cloth's shape: rebuilt now and then, else refitted
    sc.triangle_tree.build(x.data(), sc.triangles, 3);
    sc.edge_tree.build(x.data(), sc.edges, 2);
  } else {
    sc.triangle_tree.refit(x.data());
    sc.edge_tree.refit(x.data());
  }
  const double r = sc.radius;
  find_pairs(m.mass_count(), sc, ws, sc.vt, [&](std::size_t i, std::vector<SelfPair>& out) {
    if (!sc.in_face[i]) return;
    const auto v = static_cast<std::uint32_t>(i);
    const double* p = x.data() + 3 * i;
    const double lo[3] = {p[0] - r, p[1] - r, p[2] - r}, hi[3] = {p[0] + r, p[1] + r, p[2] + r};
    sc.triangle_tree.query(lo, hi, [&](std::uint32_t t) {
      const std::uint32_t* c = &sc.triangles[3 * std::size_t{t}];
      if (c[0] != v && c[1] != v && c[2] != v && box_meets(x.data(), c, 3, lo, hi))
        keep(x, sc, v, c[0], c[1], c[2], true, out);
    });
  });
  find_pairs(sc.edges.size() / 2, sc, ws, sc.ee, [&](std::size_t e, std::vector<SelfPair>& out) {
    const std::uint32_t a = sc.edges[2 * e], b = sc.edges[2 * e + 1];
    const double *pa = x.data() + 3 * std::size_t{a}, *pb = x.data() + 3 * std::size_t{b};
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::min(pa[k], pb[k]) - r, hi[k] = std::max(pa[k], pb[k]) + r;
    sc.edge_tree.query(lo, hi, [&](std::uint32_t f) {
      if (f <= e) return;  // (each pair once)
      const std::uint32_t* cd = &sc.edges[2 * std::size_t{f}];
      const std::uint32_t c = cd[0], d = cd[1];
      if (c != a && c != b && d != a && d != b && box_meets(x.data(), cd, 2, lo, hi))
        keep(x, sc, a, b, c, d, false, out);
    });
  });
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    sc.bound[i] = sc.in_face[i] ? r : std::numeric_limits<double>::infinity();
  for (const auto* list : {&sc.vt, &sc.ee})
    for (const SelfPair& p : *list)
      for (std::uint32_t i : p.mass) sc.bound[i] = std::min(sc.bound[i], p.gap);
  for (std::size_t i = 0; i < m.mass_count(); ++i) sc.bound[i] *= kSelfGamma;
  keep_reachable(m, sc, sc.vt, true);
  keep_reachable(m, sc, sc.ee, false);
  sc.xd = x;
  sc.detect = false;
  ++sc.detections;
  if (std::getenv("SELFDBG") && sc.detections % 500 == 0) { std::size_t small=0; double mn=1e9; std::size_t at=0; for (std::size_t i=0;i<m.mass_count();++i){ if (sc.bound[i]<0.1*kSelfGamma*r) ++small; if (sc.bound[i]<mn) mn=sc.bound[i], at=i;} std::fprintf(stderr, "det %llu vt %zu ee %zu r %g small %zu min %g at %zu\n", static_cast<unsigned long long>(sc.detections), sc.vt.size(), sc.ee.size(), sc.radius, small, mn, at);}
}

}  // namespace clothsim::detail
