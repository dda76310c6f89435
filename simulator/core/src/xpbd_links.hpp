// XPBD's two link updates, one link at a time and a colour's links four at a time in AVX2
// (xpbd_avx2.cpp): the same IEEE operations in the same order (no FMA), so the same bits.
#pragma once

#include "spring_colouring.hpp"

#include <clothsim/cpu.hpp>

#include <cmath>
#include <cstddef>

namespace clothsim::detail {

/// One structural spring as a compliant distance constraint (lambda from 0): alpha~ = 1/(k h^2).
inline void project(const Link& l, const double* w, double inv_h2, double* x) {
  double* pa = x + 3 * std::size_t{l.a};
  double* pb = x + 3 * std::size_t{l.b};
  const double wa = w[l.a], wb = w[l.b];
  const double dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
  const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (len == 0.0) return;  // no direction: no correction (as the force stage)
  const double scale = (l.rest - len) / (wa + wb + inv_h2 / l.k) / len;
  pa[0] += wa * scale * dx, pa[1] += wa * scale * dy, pa[2] += wa * scale * dz;
  pb[0] -= wb * scale * dx, pb[1] -= wb * scale * dy, pb[2] -= wb * scale * dz;
}

/// One bend spring's pull on the velocities over h (report eq. 4).
inline void bend(const Link& l, const double* w, double h, const double* x, double* v) {
  const std::size_t a = 3 * std::size_t{l.a}, b = 3 * std::size_t{l.b};
  const double dx = x[a] - x[b], dy = x[a + 1] - x[b + 1], dz = x[a + 2] - x[b + 2];
  const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
  if (len == 0.0) return;
  const double c = h * l.k * (l.rest - len) / len, ca = c * w[l.a], cb = c * w[l.b];
  v[a] += ca * dx, v[a + 1] += ca * dy, v[a + 2] += ca * dz;
  v[b] -= cb * dx, v[b + 1] -= cb * dy, v[b + 2] -= cb * dz;
}

#ifdef CLOTHSIM_AVX2
/// project() over links [0, n) of one colour (no two share a mass).
void project_links_avx2(const Link* links, std::size_t n, const double* w, double inv_h2, double* x);
/// bend() over links [0, n) of one colour.
void bend_links_avx2(const Link* links, std::size_t n, const double* w, double h, const double* x, double* v);
#endif

}  // namespace clothsim::detail
