// The self-contact BVH's leaf pair tests in AVX2 (self_bvh.hpp): a primitive of one leaf
// against the four lanes of the other, near()'s comparisons in its order, the same answers.
#include "self_bvh.hpp"

#ifdef CLOTHSIM_AVX2

namespace clothsim::detail {

__attribute__((target("avx2"))) std::uint32_t SelfBvh::leaf_meets_avx2(const Lanes& a, std::uint32_t count,
                                                                        const Lanes& b, double r) {
  __m256d lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = _mm256_load_pd(b.lo[k]), hi[k] = _mm256_load_pd(b.hi[k]);
  std::uint32_t hits = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    __m256d meet = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    for (int k = 0; k < 3; ++k) {
      const __m256d below = _mm256_set1_pd(a.lo[k][i] - r), above = _mm256_set1_pd(a.hi[k][i] + r);
      meet = _mm256_and_pd(meet, _mm256_cmp_pd(below, hi[k], _CMP_LE_OQ));
      meet = _mm256_and_pd(meet, _mm256_cmp_pd(above, lo[k], _CMP_GE_OQ));
    }
    hits |= static_cast<std::uint32_t>(_mm256_movemask_pd(meet)) << (4 * i);
  }
  return hits;
}

}  // namespace clothsim::detail

#endif
