// The two updates of report eqs. 1 and 6-7 in AVX2 for one thread: the same operations per
// element as the plain loops (h * v, then +; f * (1/m), then h *, then +), so the same bits.
#include "symplectic_euler.hpp"

#ifdef CLOTHSIM_AVX2

#include <cstring>

namespace clothsim::detail {

namespace {

// Four masses' values (lanes 0-3) spread over their 12 elements: m0 m0 m0 m1 | m1 m1 m2 m2 |
// m2 m3 m3 m3.
__attribute__((target("avx2"), always_inline)) inline void spread3(__m256d m, __m256d out[3]) {
  out[0] = _mm256_permute4x64_pd(m, 0b01000000), out[1] = _mm256_permute4x64_pd(m, 0b10100101);
  out[2] = _mm256_permute4x64_pd(m, 0b11111110);
}

// Masses i .. i + 3 pinned (pinned[] != 0), all-ones lanes, spread over their 12 elements.
__attribute__((target("avx2"), always_inline)) inline void pinned_lanes(const std::uint8_t* pinned, std::size_t i,
                                                                        __m256d out[3]) {
  std::uint32_t four;
  std::memcpy(&four, pinned + i, sizeof four);
  spread3(_mm256_castsi256_pd(_mm256_xor_si256(
              _mm256_cmpeq_epi64(_mm256_cvtepu8_epi64(_mm_cvtsi32_si128(static_cast<int>(four))), _mm256_setzero_si256()),
              _mm256_set1_epi64x(-1))),
          out);
}

}  // namespace

__attribute__((target("avx2"))) bool drift_avx2(double* x, const double* v, const std::uint8_t* pinned, double h,
                                                std::size_t n) {
  // ... and whether every new x of a free mass is finite (a pinned one's is put back after the
  // step)
  const __m256d hv = _mm256_set1_pd(h);
  __m256i any = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {  // 4 masses, 12 elements
    __m256d pin[3];
    pinned_lanes(pinned, i, pin);
    for (std::size_t k = 0; k < 3; ++k) {
      double* px = x + 3 * i + 4 * k;
      const __m256d nx = _mm256_add_pd(_mm256_loadu_pd(px), _mm256_mul_pd(hv, _mm256_loadu_pd(v + 3 * i + 4 * k)));
      _mm256_storeu_pd(px, nx);
      any = _mm256_or_si256(any, _mm256_andnot_si256(_mm256_castpd_si256(pin[k]), nonfinite_lanes(nx)));
    }
  }
  bool ok = _mm256_movemask_pd(_mm256_castsi256_pd(any)) == 0;
  for (; i < n; ++i)
    for (std::size_t r = 0; r < 3; ++r) {
      x[3 * i + r] += h * v[3 * i + r];
      if (!pinned[i] && !finite_span_plain(x + 3 * i + r, 1)) ok = false;
    }
  return ok;
}
__attribute__((target("avx2"))) bool kick_avx2(double* v, const double* f, const double* im,
                                               const std::uint8_t* pinned, double h, std::size_t n) {
  // ... and whether every new v of a free mass is finite (a pinned one's is set to 0 after the
  // step)
  const __m256d hv = _mm256_set1_pd(h);
  __m256i any = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {  // 4 masses, 12 elements
    __m256d w[3], pin[3];
    spread3(_mm256_loadu_pd(im + i), w);
    pinned_lanes(pinned, i, pin);
    for (std::size_t k = 0; k < 3; ++k) {
      double* pv = v + 3 * i + 4 * k;
      const __m256d nv = _mm256_add_pd(_mm256_loadu_pd(pv),
                                       _mm256_mul_pd(hv, _mm256_mul_pd(_mm256_loadu_pd(f + 3 * i + 4 * k), w[k])));
      _mm256_storeu_pd(pv, nv);
      any = _mm256_or_si256(any, _mm256_andnot_si256(_mm256_castpd_si256(pin[k]), nonfinite_lanes(nv)));
    }
  }
  bool ok = _mm256_movemask_pd(_mm256_castsi256_pd(any)) == 0;
  for (; i < n; ++i)
    for (std::size_t r = 0; r < 3; ++r) {
      v[3 * i + r] += h * (f[3 * i + r] * im[i]);
      if (!pinned[i] && !finite_span_plain(v + 3 * i + r, 1)) ok = false;
    }
  return ok;
}

}  // namespace clothsim::detail

#endif  // CLOTHSIM_AVX2
