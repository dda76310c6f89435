// The tolerances of the clearances and of the certificates built on them (clear faces, edge
// answers), and clear_at(), a triangle's clearance computed when first needed (inlined into
// clear_radius()).
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>

#include "clothsim/collision/collider_set.hpp"

namespace clothsim {

namespace detail {

// Edge answers: only over the edge's middle (all but kEdgeEnds of its length at either end),
// and every other triangle at least kEdgeZeta of its length from there. (A fan triangle at an
// end that leaves it at an angle phi is kEdgeEnds sin(phi) of the length from the middle part:
// any phi above 14.5 degrees.)
constexpr double kEdgeEnds = 0.02, kEdgeZeta = 0.005;
// Clearances: the looser depth (of the coordinates) allowed far from a face or an edge, so that
// boxes of a plane's own triangles (a floor, a roof's slope: float boxes cannot tell tau) need
// not be opened; and the largest reach or distance (of the coordinates' scale, 2) it holds for.
constexpr double kLooseDepth = 2e-5;
// tau, of the coordinates' scale: how far behind a plane a triangle out of the way must be, and
// the gap by which clear faces and edge answers win. The certificates' rounding margin m (1e-12
// of the coordinates) must not exceed it; both are far above the kernel's rounding (~1e-15 of
// the coordinates). An edge answer needs zeta^2 >= 6 d tau: on a 5 mm mesh it holds for
// points within ~10 m (with tau = 1e-9, only within ~10 cm).
constexpr double kTau = 1e-11;

}  // namespace detail

inline float ColliderSet::clear_at(std::size_t o, std::uint32_t slot) const {
  std::atomic_ref<float> c(clear_[slot]);
  float v = c.load(std::memory_order_relaxed);
  if (std::isnan(v)) {  // first use: compute (two threads may both; they store the same)
    v = clearance_of(o, slot);
    c.store(v, std::memory_order_relaxed);
  }
  return v;
}

}  // namespace clothsim
