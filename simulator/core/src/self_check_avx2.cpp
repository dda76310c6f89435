// The lists' check of a leaf pair in AVX2 (leaf_clears, self_moves.hpp): a primitive of one
// leaf against the four lanes of the other, leaf_clears()'s operations in its order (std::max
// (x, y) is max_pd(y, x), NaN and all), the same answers and least room.
#include "self_moves.hpp"

#ifdef CLOTHSIM_AVX2

#include <limits>

namespace clothsim::detail {

__attribute__((target("avx2"))) std::uint32_t leaf_clears_avx2(const SelfBvh::Lanes& a, std::uint32_t count,
                                                                const SelfBvh::Lanes& b, const LeafCheck& c,
                                                                double& least_room) {
  const __m256d zero = _mm256_setzero_pd(), far = _mm256_set1_pd(c.far), skin = _mm256_set1_pd(c.skin);
  const __m256d moved = _mm256_set1_pd(c.moved), inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
  __m256d least = inf;
  std::uint32_t left = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    // (the lanes that are pairs: those of the other leaf's primitives, past i for a leaf
    // against itself)
    const __m256i lane = _mm256_setr_epi64x(0, 1, 2, 3);
    __m256i pairs = _mm256_cmpgt_epi64(_mm256_set1_epi64x(c.other), lane);
    if (c.one) pairs = _mm256_and_si256(pairs, _mm256_cmpgt_epi64(lane, _mm256_set1_epi64x(i)));
    __m256d s = zero;
    for (int k = 0; k < 3; ++k) {
      const __m256d p = _mm256_sub_pd(_mm256_set1_pd(a.lo[k][i]), _mm256_load_pd(b.hi[k]));
      const __m256d q = _mm256_sub_pd(_mm256_load_pd(b.lo[k]), _mm256_set1_pd(a.hi[k][i]));
      const __m256d d = _mm256_max_pd(zero, _mm256_max_pd(q, p));
      s = _mm256_add_pd(s, _mm256_mul_pd(d, d));
    }
    const __m256d room = _mm256_max_pd(skin, _mm256_sub_pd(_mm256_sqrt_pd(s), far));
    const __m256d clear = _mm256_and_pd(_mm256_cmp_pd(moved, room, _CMP_LE_OQ), _mm256_castsi256_pd(pairs));
    least = _mm256_min_pd(least, _mm256_blendv_pd(inf, room, clear));
    const auto lanes = static_cast<std::uint32_t>(_mm256_movemask_pd(_mm256_castsi256_pd(pairs)));
    left |= (lanes & ~static_cast<std::uint32_t>(_mm256_movemask_pd(clear))) << (4 * i);
  }
  const __m128d half = _mm_min_pd(_mm256_castpd256_pd128(least), _mm256_extractf128_pd(least, 1));
  least_room = std::min(least_room, _mm_cvtsd_f64(_mm_min_sd(half, _mm_unpackhi_pd(half, half))));
  return left;
}

}  // namespace clothsim::detail

#endif
