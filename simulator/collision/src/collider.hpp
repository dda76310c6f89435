// What the ColliderSet's source files share: where a kept triangle's data is (blocks of 4
// slots), the order that picks "the closest", and the float rounding of stored lower bounds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "clothsim/collision/collider_set.hpp"
#include "clothsim/collision/contact_cache.hpp"
#include "kernel.hpp"

namespace clothsim {

namespace detail {

// Triangle slots come in blocks of 4 (one leaf each), component-major inside a block (a
// slot-major layout, 96 contiguous bytes per triangle, makes the searches 4-7 % slower).
constexpr std::uint32_t kBlock = 4;

// Total order for "closest": distance, then lowest input triangle index.
inline bool better(double d2, std::int32_t tri, double best_d2, std::int32_t best_tri) {
  return d2 < best_d2 || (d2 == best_d2 && tri < best_tri);
}

// A float that is <= v (the stored lower bounds of the candidates' distances).
inline float round_down(double v) {
  auto f = static_cast<float>(v);
  if (static_cast<double>(f) > v) {  // one float step down (f is finite here: v is)
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    if (f > 0.0f) --bits;
    else if (f < 0.0f) ++bits;
    else bits = 0x80000001u;  // the negative float nearest 0
    std::memcpy(&f, &bits, sizeof f);
  }
  return f;
}

constexpr std::size_t kMaxCandidates = ContactCache::kMaxCandidates;

}  // namespace detail

inline const double* ColliderSet::tri_ptr(std::uint32_t slot) const {
  return &tri_[12 * std::size_t{slot & ~(detail::kBlock - 1)} + (slot & (detail::kBlock - 1))];
}

inline detail::Tri ColliderSet::tri_at(std::uint32_t slot) const {
  static_assert(sizeof(detail::Tri) == 12 * sizeof(double));
  constexpr std::uint32_t k = detail::kBlock;
  const double* b = tri_ptr(slot);
  return detail::Tri{b[0],     b[k],     b[2 * k], b[3 * k], b[4 * k],  b[5 * k],
                     b[6 * k], b[7 * k], b[8 * k], b[9 * k], b[10 * k], b[11 * k]};
}

}  // namespace clothsim
