// Strain limiting (Provot 1995), after each step of dt: a structural spring stretched past the
// model's strain limit is shortened to it, its ends moved by their inverse masses, and its ends
// stop moving apart (an inelastic stop, as a woven cloth's straight yarns);
// the masses first go back within reach of their pins and of the masses the colliders hold
// (long-range attachments, Kim et al. 2012). Passes follow the springs of the masses the last pass moved, until none is
// past the limit or the passes have checked a few times the cloth's springs. Each pass takes
// its springs in spring order: the result does not depend on the thread count.
#include "parallel.hpp"
#include "stages.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace clothsim::detail {

namespace {

constexpr std::uint32_t kNoAnchor = ~std::uint32_t{0};

// The passes stop after checking this many times the structural springs.
constexpr double kWork = 32.0;

// Whether spring k is past the cap (squared lengths: no root).
bool past(const Model& m, std::uint32_t k, double cap, const double* x) {
  const std::size_t a = 3 * std::size_t{m.spring_a[k]}, b = 3 * std::size_t{m.spring_b[k]};
  const double dx = x[a] - x[b], dy = x[a + 1] - x[b + 1], dz = x[a + 2] - x[b + 2];
  const double limit = cap * m.rest_length0[static_cast<Eigen::Index>(k)];
  return dx * dx + dy * dy + dz * dz > limit * limit;
}

// Shortens spring k to the cap, its ends moved by their inverse masses (the centre of mass
// stays); then stops the ends moving further apart (an inelastic stop: momentum kept, energy
// only lost), whatever the step.
void shorten(const Model& m, std::uint32_t k, double cap, double* x, double* v) {
  const std::size_t a = 3 * std::size_t{m.spring_a[k]}, b = 3 * std::size_t{m.spring_b[k]};
  const double wa = m.inv_mass[m.spring_a[k]], wb = m.inv_mass[m.spring_b[k]];
  const double d[3] = {x[a] - x[b], x[a + 1] - x[b + 1], x[a + 2] - x[b + 2]};
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double excess = len - cap * m.rest_length0[static_cast<Eigen::Index>(k)];
  if (!(excess > 0.0) || wa + wb == 0.0) return;
  const double c = excess / ((wa + wb) * len);
  double apart = 0.0;  // the ends' relative speed along the spring, times len
  for (std::size_t r = 0; r < 3; ++r) {
    x[a + r] -= wa * c * d[r], x[b + r] += wb * c * d[r];
    apart += (v[a + r] - v[b + r]) * d[r];
  }
  if (!(apart > 0.0)) return;
  const double u = apart / ((wa + wb) * len * len);
  for (std::size_t r = 0; r < 3; ++r) v[a + r] -= wa * u * d[r], v[b + r] += wb * u * d[r];
}

// The long-range attachments: a free mass farther from one of its pins than cap times its
// distance along the cloth is put back on that sphere (the pins do not move: any order).
void attach(const Model& m, State& s, const Workspace& ws, double cap) {
  constexpr std::size_t K = Model::kAttachments;
  if (m.attach_pin.size() != K * m.mass_count()) return;
  const auto n = static_cast<std::int64_t>(m.mass_count());
  parallel_for(team(ws, m.mass_count()), n, [&](std::int64_t i) {
    for (std::size_t a = 0; a < K; ++a) {
      const std::uint32_t pin = m.attach_pin[static_cast<std::size_t>(i) * K + a];
      if (pin == Model::kNoPin) break;
      const Eigen::Vector3d d = s.x.col(i) - s.x.col(pin);
      const double len = d.norm(), limit = cap * static_cast<double>(m.attach_rest[static_cast<std::size_t>(i) * K + a]);
      if (!(len > limit)) continue;
      s.x.col(i) += d * (limit / len - 1.0);
      const double away = s.v.col(i).dot(d);  // (the pin does not move)
      if (away > 0.0) s.v.col(i) -= (away / (len * len)) * d;
    }
  });
}

// A mass farther from its held anchor than cap times their path is put back on that sphere,
// and (with v) stops moving away from the anchor. The anchors do not move: any order.
void held_reach(const Model& m, Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* v, const Workspace& ws, double cap) {
  const auto n = static_cast<std::int64_t>(ws.anchor.size());
  parallel_for(team(ws, m.mass_count()), n, [&](std::int64_t i) {
    const std::uint32_t a = ws.anchor[static_cast<std::size_t>(i)];
    if (a == kNoAnchor || a == static_cast<std::uint32_t>(i) || m.inv_mass[i] == 0.0) return;
    const Eigen::Vector3d d = x.col(i) - x.col(a);
    const double len = d.norm(), limit = cap * ws.reach[static_cast<std::size_t>(i)];
    if (!(len > limit)) return;
    x.col(i) += d * (limit / len - 1.0);
    if (!v) return;
    const double away = (v->col(i) - v->col(a)).dot(d);
    if (away > 0.0) v->col(i) -= (away / (len * len)) * d;
  });
}

// The attachments to the held masses: every mass's nearest held mass along the structural
// springs (Dijkstra from all of them at once, on rest lengths: a path no shorter than the
// cloth's own), and a mass farther from it than cap times that path is put back on its
// sphere, as on a pin's (the held mass does not move: any order). A hanging part then hangs
// from where the colliders hold the cloth, however long the way. The paths are found again
// only when the held masses change.
void attach_to_held(const Model& m, State& s, Workspace& ws, double cap) {
  if (ws.held.empty()) return;
  if (ws.held == ws.anchored) return held_reach(m, s.x, &s.v, ws, cap);
  ws.anchored = ws.held;
  auto& heap = ws.frontier;
  const auto later = [](const auto& p, const auto& q) { return p.first > q.first; };
  heap.clear();
  for (std::uint32_t i = 0; i < m.mass_count(); ++i) {
    ws.anchor[i] = ws.held[i] ? i : kNoAnchor;
    ws.reach[i] = ws.held[i] ? 0.0 : std::numeric_limits<double>::infinity();
    if (ws.held[i]) heap.emplace_back(0.0, i);
  }
  std::make_heap(heap.begin(), heap.end(), later);
  const SpringAdjacency& adj = *ws.adjacency;
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    const auto [d, i] = heap.back();
    heap.pop_back();
    if (d > ws.reach[i]) continue;  // (a stale entry)
    for (std::uint32_t e = adj.start[i]; e < adj.start[i + 1]; ++e) {
      const std::uint32_t k = adj.entry[e] & ~SpringAdjacency::kB;
      if (m.spring_kind[k] != 0) continue;
      const std::uint32_t j = m.spring_a[k] == i ? m.spring_b[k] : m.spring_a[k];
      const double dj = d + m.rest_length0[static_cast<Eigen::Index>(k)];
      if (!(dj < ws.reach[j])) continue;
      ws.reach[j] = dj, ws.anchor[j] = ws.anchor[i];
      heap.emplace_back(dj, j);
      std::push_heap(heap.begin(), heap.end(), later);
    }
  }
  held_reach(m, s.x, &s.v, ws, cap);
}

// The next pass's springs: those of the masses in ws.moved_list past the cap, each once, in
// spring order; returns how many springs it checked.
std::size_t next_pass(const Model& m, Workspace& ws, double cap, const double* x) {
  const SpringAdjacency& adj = *ws.adjacency;
  std::size_t checked = 0;
  ws.stretched.clear();
  for (const std::uint32_t i : ws.moved_list) {
    ws.moved[i] = 0;
    for (std::uint32_t e = adj.start[i]; e < adj.start[i + 1]; ++e) {
      const std::uint32_t k = adj.entry[e] & ~SpringAdjacency::kB;
      ++checked;
      if (m.spring_kind[k] == 0 && !ws.listed[k] && past(m, k, cap, x)) ws.listed[k] = 1, ws.stretched.push_back(k);
    }
  }
  ws.moved_list.clear();
  for (const std::uint32_t k : ws.stretched) ws.listed[k] = 0;
  std::sort(ws.stretched.begin(), ws.stretched.end());
  return checked;
}

}  // namespace

void keep_in_reach(const Model& m, Eigen::Matrix3Xd& x, const Workspace& ws) {
  if (m.strain_limit > 0.0 && !ws.anchor.empty()) held_reach(m, x, nullptr, ws, 1.0 + m.strain_limit);
}

void limit_strain(const Model& m, State& s, Workspace& ws) {
  if (!(m.strain_limit > 0.0)) return;
  const double cap = 1.0 + m.strain_limit;
  attach(m, s, ws, cap);
  attach_to_held(m, s, ws, cap);
  double* x = s.x.data();
  double* v = s.v.data();
  ws.stretched.clear();
  std::size_t structural = 0;
  for (std::size_t k = 0; k < m.spring_count(); ++k)
    if (m.spring_kind[k] == 0 && (++structural, past(m, static_cast<std::uint32_t>(k), cap, x)))
      ws.stretched.push_back(static_cast<std::uint32_t>(k));
  const double budget = kWork * static_cast<double>(structural);
  double work = static_cast<double>(structural);
  while (!ws.stretched.empty()) {
    for (const std::uint32_t k : ws.stretched) {
      shorten(m, k, cap, x, v);
      for (const std::uint32_t i : {m.spring_a[k], m.spring_b[k]})
        if (!ws.moved[i]) ws.moved[i] = 1, ws.moved_list.push_back(i);
    }
    if (!ws.adjacency || work > budget) break;
    work += static_cast<double>(next_pass(m, ws, cap, x));
  }
  for (const std::uint32_t i : ws.moved_list) ws.moved[i] = 0;
  ws.moved_list.clear();
}

}  // namespace clothsim::detail
