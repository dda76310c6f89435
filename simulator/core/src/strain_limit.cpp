// Strain limiting (Provot 1995), after a step: a structural spring stretched past the model's
// strain limit is shortened to it, its ends moved by their inverse masses and their
// velocities by the same move over h (an inelastic stop, as a woven cloth's straight yarns);
// a pinned cloth's masses first go back within reach of their pins (long-range attachments,
// Kim et al. 2012). Passes follow the springs of the masses the last pass moved, until none is
// past the limit or the passes have checked a few times the cloth's springs. Each pass takes
// its springs in spring order: the result does not depend on the thread count.
#include "parallel.hpp"
#include "stages.hpp"

#include <algorithm>
#include <cmath>

namespace clothsim::detail {

namespace {

// The passes stop after checking this many times the structural springs.
constexpr double kWork = 4.0;

// Whether spring k is past the cap (squared lengths: no root).
bool past(const Model& m, std::uint32_t k, double cap, const double* x) {
  const std::size_t a = 3 * std::size_t{m.spring_a[k]}, b = 3 * std::size_t{m.spring_b[k]};
  const double dx = x[a] - x[b], dy = x[a + 1] - x[b + 1], dz = x[a + 2] - x[b + 2];
  const double limit = cap * m.rest_length0[static_cast<Eigen::Index>(k)];
  return dx * dx + dy * dy + dz * dz > limit * limit;
}

// Shortens spring k to the cap.
void shorten(const Model& m, std::uint32_t k, double cap, double h, double* x, double* v) {
  const std::size_t a = m.spring_a[k], b = m.spring_b[k];
  const double wa = m.inv_mass[static_cast<Eigen::Index>(a)], wb = m.inv_mass[static_cast<Eigen::Index>(b)];
  double* pa = x + 3 * a;
  double* pb = x + 3 * b;
  const double d[3] = {pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]};
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double excess = len - cap * m.rest_length0[static_cast<Eigen::Index>(k)];
  if (!(excess > 0.0) || wa + wb == 0.0) return;
  const double c = excess / ((wa + wb) * len);
  for (int r = 0; r < 3; ++r) {
    const double move_a = -wa * c * d[r], move_b = wb * c * d[r];
    pa[r] += move_a, v[3 * a + static_cast<std::size_t>(r)] += move_a / h;
    pb[r] += move_b, v[3 * b + static_cast<std::size_t>(r)] += move_b / h;
  }
}

// The long-range attachments: a free mass farther from one of its pins than cap times its
// distance along the cloth is put back on that sphere (the pins do not move: any order).
void attach(const Model& m, State& s, const Workspace& ws, double cap, double h) {
  constexpr std::size_t K = Model::kAttachments;
  if (m.attach_pin.size() != K * m.mass_count()) return;
  const auto n = static_cast<std::int64_t>(m.mass_count());
  [[maybe_unused]] const int nt = team(ws, m.mass_count());
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i)
    for (std::size_t a = 0; a < K; ++a) {
      const std::uint32_t pin = m.attach_pin[static_cast<std::size_t>(i) * K + a];
      if (pin == Model::kNoPin) break;
      const Eigen::Vector3d d = s.x.col(i) - s.x.col(pin);
      const double len = d.norm(), limit = cap * static_cast<double>(m.attach_rest[static_cast<std::size_t>(i) * K + a]);
      if (!(len > limit)) continue;
      const Eigen::Vector3d move = d * (limit / len - 1.0);
      s.x.col(i) += move;
      s.v.col(i) += move / h;
    }
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

void limit_strain(const Model& m, State& s, Workspace& ws, double h) {
  if (!(m.strain_limit > 0.0)) return;
  const double cap = 1.0 + m.strain_limit;
  attach(m, s, ws, cap, h);
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
      shorten(m, k, cap, h, x, v);
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
