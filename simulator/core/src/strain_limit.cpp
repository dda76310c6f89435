// Strain limiting (Provot 1995): after a step, a structural spring stretched past the model's
// strain limit is shortened to it, its ends moved by their inverse masses, and their
// velocities by the same move over h (an inelastic stop, as a woven cloth's straight yarns).
// A few passes over the springs still past it; each pass takes them in spring order, so the
// result does not depend on the thread count.
#include "stages.hpp"

#include <algorithm>
#include <cmath>

namespace clothsim::detail {

namespace {

constexpr int kPasses = 8;

// Whether spring k is past the cap (squared lengths: no root).
bool past(const Model& m, std::uint32_t k, double cap, const double* x) {
  const std::size_t a = 3 * std::size_t{m.spring_a[k]}, b = 3 * std::size_t{m.spring_b[k]};
  const double dx = x[a] - x[b], dy = x[a + 1] - x[b + 1], dz = x[a + 2] - x[b + 2];
  const double limit = cap * m.rest_length0[static_cast<Eigen::Index>(k)];
  return dx * dx + dy * dy + dz * dz > limit * limit;
}

// Shortens spring k to the cap when it is past it; whether it was.
bool shorten(const Model& m, std::uint32_t k, double cap, double h, double* x, double* v) {
  const std::size_t a = m.spring_a[k], b = m.spring_b[k];
  const double wa = m.inv_mass[static_cast<Eigen::Index>(a)], wb = m.inv_mass[static_cast<Eigen::Index>(b)];
  double* pa = x + 3 * a;
  double* pb = x + 3 * b;
  const double d[3] = {pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]};
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double excess = len - cap * m.rest_length0[static_cast<Eigen::Index>(k)];
  if (!(excess > 0.0) || wa + wb == 0.0) return false;
  const double c = excess / ((wa + wb) * len);
  for (int r = 0; r < 3; ++r) {
    const double move_a = -wa * c * d[r], move_b = wb * c * d[r];
    pa[r] += move_a, v[3 * a + static_cast<std::size_t>(r)] += move_a / h;
    pb[r] += move_b, v[3 * b + static_cast<std::size_t>(r)] += move_b / h;
  }
  return true;
}

}  // namespace

void limit_strain(const Model& m, State& s, Workspace& ws, double h) {
  if (!(m.strain_limit > 0.0)) return;
  const double cap = 1.0 + m.strain_limit;
  double* x = s.x.data();
  double* v = s.v.data();
  // First every structural spring; then only those of a mass the last pass moved (ws.moved):
  // a pass changes nothing elsewhere.
  ws.stretched.clear();
  for (std::size_t k = 0; k < m.spring_count(); ++k)
    if (m.spring_kind[k] == 0 && past(m, static_cast<std::uint32_t>(k), cap, x))
      ws.stretched.push_back(static_cast<std::uint32_t>(k));
  const SpringAdjacency* adj = ws.adjacency.get();
  for (int pass = 0; pass < kPasses && !ws.stretched.empty(); ++pass) {
    for (const std::uint32_t k : ws.stretched) {
      shorten(m, k, cap, h, x, v);
      ws.moved[m.spring_a[k]] = ws.moved[m.spring_b[k]] = 1;
    }
    if (!adj || pass + 1 == kPasses) break;
    // the springs of the moved masses, each once, in spring order
    ws.stretched.clear();
    for (std::size_t i = 0; i < m.mass_count(); ++i) {
      if (!ws.moved[i]) continue;
      ws.moved[i] = 0;
      for (std::uint32_t e = adj->start[i]; e < adj->start[i + 1]; ++e) {
        const std::uint32_t k = adj->entry[e] & ~SpringAdjacency::kB;
        if (m.spring_kind[k] == 0 && past(m, k, cap, x)) ws.stretched.push_back(k);
      }
    }
    std::sort(ws.stretched.begin(), ws.stretched.end());
    ws.stretched.erase(std::unique(ws.stretched.begin(), ws.stretched.end()), ws.stretched.end());
  }
  std::fill(ws.moved.begin(), ws.moved.end(), std::uint8_t{0});
}

}  // namespace clothsim::detail
