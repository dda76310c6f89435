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

// A found pair: kept when nearer than the radius, its target no more than its rest distance.
void keep(const Model& m, const Eigen::Matrix3Xd& x, const SelfScratch& sc, std::uint32_t a, std::uint32_t b,
          std::uint32_t c, std::uint32_t d, bool vertex_triangle, std::vector<SelfPair>& out) {
  SelfPair p{{a, b, c, d}, 0.0, 0.0};
  double coef[4];
  p.gap = pair_gap(x, p.mass, vertex_triangle, coef).norm();
  if (!(p.gap < sc.radius)) return;
  p.target = std::min(sc.distance, pair_gap(m.x0, p.mass, vertex_triangle, coef).norm());
  out.push_back(p);
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
  if (sc.refits++ % 64 == 0) {  // the trees follow the cloth's shape: rebuilt now and then, else refitted
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
      if (c[0] != v && c[1] != v && c[2] != v) keep(m, x, sc, v, c[0], c[1], c[2], true, out);
    });
  });
  find_pairs(sc.edges.size() / 2, sc, ws, sc.ee, [&](std::size_t e, std::vector<SelfPair>& out) {
    const std::uint32_t a = sc.edges[2 * e], b = sc.edges[2 * e + 1];
    const double *pa = x.data() + 3 * std::size_t{a}, *pb = x.data() + 3 * std::size_t{b};
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::min(pa[k], pb[k]) - r, hi[k] = std::max(pa[k], pb[k]) + r;
    sc.edge_tree.query(lo, hi, [&](std::uint32_t f) {
      if (f <= e) return;  // (each pair once)
      const std::uint32_t c = sc.edges[2 * std::size_t{f}], d = sc.edges[2 * std::size_t{f} + 1];
      if (c != a && c != b && d != a && d != b) keep(m, x, sc, a, b, c, d, false, out);
    });
  });
  for (std::size_t i = 0; i < m.mass_count(); ++i)
    sc.bound[i] = sc.in_face[i] ? r : std::numeric_limits<double>::infinity();
  for (const auto* list : {&sc.vt, &sc.ee})
    for (const SelfPair& p : *list)
      for (std::uint32_t i : p.mass) sc.bound[i] = std::min(sc.bound[i], p.gap);
  for (std::size_t i = 0; i < m.mass_count(); ++i) sc.bound[i] *= kSelfGamma;
  sc.xd = x;
  sc.detect = false;
  ++sc.detections;
}

}  // namespace clothsim::detail
