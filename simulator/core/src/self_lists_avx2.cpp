// The candidate lists' build in AVX2 (self_contact.hpp): four pairs at once, to rule out the
// many pairs whose boxes meet but whose elements are farther apart than the lists reach. Edge
// pairs by their segments' distance (edges_apart_avx2: Ericson 5.1.9, each branch computed and
// chosen per lane); a mass and a triangle by a lower bound on their distance (masses_apart_avx2).
#include "self_contact.hpp"

#ifdef CLOTHSIM_AVX2

namespace clothsim::detail {

namespace {

struct V3 {
  __m256d x, y, z;
};

__attribute__((target("avx2"), always_inline)) inline __m256d dot(const V3& a, const V3& b) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a.x, b.x), _mm256_mul_pd(a.y, b.y)), _mm256_mul_pd(a.z, b.z));
}
__attribute__((target("avx2"), always_inline)) inline V3 sub(const V3& a, const V3& b) {
  return {_mm256_sub_pd(a.x, b.x), _mm256_sub_pd(a.y, b.y), _mm256_sub_pd(a.z, b.z)};
}
__attribute__((target("avx2"), always_inline)) inline V3 cross(const V3& a, const V3& b) {
  return {_mm256_sub_pd(_mm256_mul_pd(a.y, b.z), _mm256_mul_pd(a.z, b.y)),
          _mm256_sub_pd(_mm256_mul_pd(a.z, b.x), _mm256_mul_pd(a.x, b.z)),
          _mm256_sub_pd(_mm256_mul_pd(a.x, b.y), _mm256_mul_pd(a.y, b.x))};
}
__attribute__((target("avx2"), always_inline)) inline __m256d clamp01(__m256d v) {
  return _mm256_min_pd(_mm256_max_pd(v, _mm256_setzero_pd()), _mm256_set1_pd(1.0));
}

// The four pairs' masses (corner, axis, lane).
__attribute__((target("avx2"), always_inline)) inline void gather(const double* x, const std::array<std::uint32_t, 4>* pairs,
                                                                   V3 p[4]) {
  alignas(32) double c[4][3][4];
  for (int k = 0; k < 4; ++k)
    for (int m = 0; m < 4; ++m)
      for (int a = 0; a < 3; ++a) c[m][a][k] = x[3 * std::size_t{pairs[k][static_cast<std::size_t>(m)]} + static_cast<std::size_t>(a)];
  for (int m = 0; m < 4; ++m) p[m] = {_mm256_load_pd(c[m][0]), _mm256_load_pd(c[m][1]), _mm256_load_pd(c[m][2])};
}

}  // namespace

// The triangle lies in its plane, inside the half-space behind each edge; so the mass is at
// least as far from it as from the plane and that half-space's intersection: sqrt((n.w)^2 +
// max(0, m.w)^2) over |n| for an edge p-q, w = v - p and m = (q - p) x n (|m| = |n| |q - p|).
__attribute__((target("avx2"))) std::uint32_t masses_apart_avx2(const double* x, const std::array<std::uint32_t, 4>* pairs,
                                                                 double r) {
  V3 p[4];
  gather(x, pairs, p);
  const V3 n = cross(sub(p[2], p[1]), sub(p[3], p[1]));
  const __m256d nn = dot(n, n), zero = _mm256_setzero_pd();
  const double room = r * (1.0 + 1e-6);
  const __m256d room2 = _mm256_set1_pd(room * room);
  // (sure only where the triangle is not a sliver: its normal well defined)
  const __m256d ab2 = dot(sub(p[2], p[1]), sub(p[2], p[1])), ac2 = dot(sub(p[3], p[1]), sub(p[3], p[1]));
  __m256d sure = _mm256_cmp_pd(nn, _mm256_mul_pd(_mm256_set1_pd(1e-10), _mm256_mul_pd(ab2, ac2)), _CMP_GT_OQ);
  const __m256d plane = dot(n, sub(p[0], p[1]));
  __m256d any = _mm256_cmp_pd(_mm256_mul_pd(plane, plane), _mm256_mul_pd(room2, nn), _CMP_GE_OQ);
  for (int e = 0; e < 3; ++e) {
    const V3 &from = p[1 + e], &to = p[1 + (e + 1) % 3];
    const V3 along = sub(to, from), m = cross(along, n);
    const __m256d out = _mm256_max_pd(dot(m, sub(p[0], from)), zero), ll = dot(along, along);
    // ((n.w)^2 |q - p|^2 + max(0, m.w)^2 >= room^2 |n|^2 |q - p|^2)
    const __m256d lhs = _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(plane, plane), ll), _mm256_mul_pd(out, out));
    any = _mm256_or_pd(any, _mm256_cmp_pd(lhs, _mm256_mul_pd(room2, _mm256_mul_pd(nn, ll)), _CMP_GE_OQ));
  }
  return static_cast<std::uint32_t>(_mm256_movemask_pd(_mm256_and_pd(sure, any)));
}

__attribute__((target("avx2"))) std::uint32_t edges_apart_avx2(const double* x, const std::array<std::uint32_t, 4>* pairs,
                                                                double r) {
  V3 p[4];
  gather(x, pairs, p);
  const V3 d1 = sub(p[1], p[0]), d2 = sub(p[3], p[2]), w = sub(p[0], p[2]);
  const __m256d a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, w), cc = dot(d1, w), b = dot(d1, d2);
  const __m256d ae = _mm256_mul_pd(a, e), denom = _mm256_sub_pd(ae, _mm256_mul_pd(b, b));
  // (sure only where the closest points are well defined: both edges longer than a picometre,
  // far from parallel)
  const __m256d tiny = _mm256_set1_pd(1e-24);
  __m256d sure = _mm256_and_pd(_mm256_cmp_pd(a, tiny, _CMP_GT_OQ), _mm256_cmp_pd(e, tiny, _CMP_GT_OQ));
  sure = _mm256_and_pd(sure, _mm256_cmp_pd(denom, _mm256_mul_pd(_mm256_set1_pd(1e-10), ae), _CMP_GT_OQ));
  const __m256d s0 = clamp01(_mm256_div_pd(_mm256_sub_pd(_mm256_mul_pd(b, f), _mm256_mul_pd(cc, e)), denom));
  const __m256d t0 = _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(b, s0), f), e);
  const __m256d below = _mm256_cmp_pd(t0, _mm256_setzero_pd(), _CMP_LT_OQ);
  const __m256d above = _mm256_cmp_pd(t0, _mm256_set1_pd(1.0), _CMP_GT_OQ);
  const __m256d s_below = clamp01(_mm256_div_pd(_mm256_sub_pd(_mm256_setzero_pd(), cc), a));
  const __m256d s_above = clamp01(_mm256_div_pd(_mm256_sub_pd(b, cc), a));
  const __m256d s = _mm256_blendv_pd(_mm256_blendv_pd(s0, s_above, above), s_below, below);
  const __m256d t = clamp01(t0);
  // (the gap p0 + s d1 - p2 - t d2)
  const V3 g = {_mm256_sub_pd(_mm256_add_pd(w.x, _mm256_mul_pd(s, d1.x)), _mm256_mul_pd(t, d2.x)),
                _mm256_sub_pd(_mm256_add_pd(w.y, _mm256_mul_pd(s, d1.y)), _mm256_mul_pd(t, d2.y)),
                _mm256_sub_pd(_mm256_add_pd(w.z, _mm256_mul_pd(s, d1.z)), _mm256_mul_pd(t, d2.z))};
  const double room = r * (1.0 + 1e-6);
  sure = _mm256_and_pd(sure, _mm256_cmp_pd(dot(g, g), _mm256_set1_pd(room * room), _CMP_GE_OQ));
  return static_cast<std::uint32_t>(_mm256_movemask_pd(sure));
}

}  // namespace clothsim::detail

#endif
