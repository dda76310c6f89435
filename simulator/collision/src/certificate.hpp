// What the certificate checks share: their tuning constants, rounding margin and distance
// moved, the plane records' storage and pacing, and where the foot of a point is on a face.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "clothsim/collision/contact_cache.hpp"
#include "collider.hpp"

namespace clothsim::detail {

// A list that survives fewer certified calls than this does not pay for its K-nearest search
// (which costs 3-5 plain searches); after kRetry 1-nearest searches (times 2^backoff), a list
// is tried again.
constexpr std::uint16_t kMinAge = 8;
constexpr std::uint8_t kRetry = 8;
// Objects with more triangles than this keep a copy of each entry's first candidate in the
// cache (a small collider stays in cache; the copy would only add memory traffic).
constexpr std::size_t kCopyAbove = 4096;

// A certificate's rounding margin at p (far below any useful gap) and how far p is from where
// the certificate was made: every check of it computes both this way, so that they all make
// the same decisions.
inline double certificate_margin(const double p[3], double scale) {
  return 1e-12 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + scale);
}
inline double moved_from(const double p[3], const double x0[3]) {
  const double dx = p[0] - x0[0], dy = p[1] - x0[1], dz = p[2] - x0[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Stores the plane certificate "within r of p the answer stays" (see ContactCache::Plane)
// and returns true, if r > 0 survives the roundings: x0 is kept in float (r shrinks by how
// far that moved it) and r^2 in the upper half of a float, both rounded towards 0.
inline bool store_plane(ContactCache::Plane& pl, std::uint16_t epoch, const double p[3],
                        double r, bool face) {
  const float x0[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                       static_cast<float>(p[2])};
  const double ex = p[0] - x0[0], ey = p[1] - x0[1], ez = p[2] - x0[2];
  r -= std::sqrt(ex * ex + ey * ey + ez * ez) * (1.0 + 1e-6) + 1e-6 * r;
  if (!(r > 0.0)) return false;
  const float r2 = round_down(r * r * (1.0 - 1e-6));
  std::uint32_t bits;
  std::memcpy(&bits, &r2, sizeof bits);
  bits >>= 16;  // a positive float cut to its upper half: rounded down
  if (!(r2 > 0.0f) || bits == 0) return false;
  pl.x0[0] = x0[0], pl.x0[1] = x0[1], pl.x0[2] = x0[2];
  pl.r2 = static_cast<std::uint16_t>(face ? bits : (bits | 0x8000u));
  pl.born = epoch;
  return true;
}

// Whether entry e may make a plane certificate now (called where the plane check failed or
// there was none): a certificate that lived fewer than 4 calls (or could not be made) makes
// the next attempts wait 1, 3, 7 .. 63 calls.
constexpr std::uint16_t kPlaneMinLife = 4;
inline bool plane_due(ContactCache& cache, ContactCache::Entry& e, ContactCache::Plane& pl) {
  if (pl.r2 != 0) {  // the last one no longer holds: judge how long it lived, once
    if (static_cast<std::uint16_t>(cache.epoch - pl.born) < kPlaneMinLife) {
      if (e.plane_backoff < 6) ++e.plane_backoff;
      e.plane_wait = static_cast<std::uint8_t>((1u << e.plane_backoff) - 1u);
    } else {
      e.plane_backoff = 0;
    }
    pl.r2 = 0;
  }
  if (e.plane_wait > 0) {
    --e.plane_wait;
    return false;
  }
  return true;
}
inline void plane_failed(ContactCache::Entry& e) {
  if (e.plane_backoff < 6) ++e.plane_backoff;
  e.plane_wait = static_cast<std::uint8_t>((1u << e.plane_backoff) - 1u);
}

// How far the foot of p (plane distance s) is inside each edge of triangle t (component k at
// t[k * stride]; edge 0: A-B, 1: B-C, 2: C-A), in `in`, and `margin` (1e-6 of the
// coordinates), far beyond the kernel's rounding: every point within in[k] - margin (> 0) of p
// takes the kernel's face branch, whose distance is |n.(p - a)|; the foot of a point with
// in[k] < -margin is beyond edge k. False on a sliver (sine of the smallest angle < 1e-2).
bool face_insides(const double p[3], const double* t, std::size_t stride, double s, double in[3],
                  double& margin);
// The edge whose in[] is least.
inline int least_edge(const double in[3]) {
  return in[0] <= in[1] ? (in[0] <= in[2] ? 0 : 2) : (in[1] <= in[2] ? 1 : 2);
}

}  // namespace clothsim::detail
