// accumulate_penalty()'s loop four points at a time in AVX2 lanes: their box tests and plane
// records, with the same IEEE operations in the same order as the scalar loop (no FMA), so
// the same bits; the pairs the lanes do not answer go to PenaltyPass::pair() one by one.
#include "penalty.hpp"

#ifdef CLOTHSIM_AVX2
#include <immintrin.h>

#include <algorithm>
#include <cstddef>

namespace clothsim::detail {

namespace {

// Rows r[0..3] (4 doubles each) to columns c0..c3.
__attribute__((target("avx2"), always_inline)) inline void transpose4(const __m256d r[4], __m256d& c0, __m256d& c1,
                                                                      __m256d& c2, __m256d& c3) {
  const __m256d t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
  const __m256d t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
  c0 = _mm256_permute2f128_pd(t0, t2, 0x20), c1 = _mm256_permute2f128_pd(t1, t3, 0x20);
  c2 = _mm256_permute2f128_pd(t0, t2, 0x31), c3 = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// Four points' x, y, z stored one after another (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) to
// lanes: v[0] = x0 x1 x2 x3, v[1] the y, v[2] the z; and back.
__attribute__((target("avx2"), always_inline)) inline void aos_to_lanes(const double* a, __m256d v[3]) {
  const __m256d v0 = _mm256_loadu_pd(a), v1 = _mm256_loadu_pd(a + 4), v2 = _mm256_loadu_pd(a + 8);
  const __m256d xy = _mm256_blend_pd(v0, v1, 0b1100);       // x0 y0 x2 y2
  const __m256d zx = _mm256_permute2f128_pd(v0, v2, 0x21);  // z0 x1 z2 x3
  const __m256d yz = _mm256_blend_pd(v1, v2, 0b1100);       // y1 z1 y3 z3
  v[0] = _mm256_blend_pd(xy, zx, 0b1010);
  v[1] = _mm256_shuffle_pd(xy, yz, 0b0101);
  v[2] = _mm256_blend_pd(zx, yz, 0b1010);
}
__attribute__((target("avx2"), always_inline)) inline void lanes_to_aos(const __m256d v[3], double* a) {
  const __m256d xy = _mm256_shuffle_pd(v[0], v[1], 0b0000);  // x0 y0 x2 y2
  const __m256d zx = _mm256_blend_pd(v[2], v[0], 0b1010);    // z0 x1 z2 x3
  const __m256d yz = _mm256_shuffle_pd(v[1], v[2], 0b1111);  // y1 z1 y3 z3
  _mm256_storeu_pd(a, _mm256_permute2f128_pd(xy, zx, 0x20));
  _mm256_storeu_pd(a + 4, _mm256_blend_pd(yz, xy, 0b1100));
  _mm256_storeu_pd(a + 8, _mm256_permute2f128_pd(zx, yz, 0x31));
}

// box_dist_sq() in lanes: e = p < lo ? lo - p : (p > hi ? p - hi : 0), summed from 0 in x, y,
// z order (the same operations).
__attribute__((target("avx2"), always_inline)) inline __m256d box_dist_sq_lanes(const __m256d p[3], const double* lo,
                                                                              const double* hi) {
  const __m256d zero = _mm256_setzero_pd();
  __m256d d2 = zero;
  for (int k = 0; k < 3; ++k) {
    const __m256d l = _mm256_set1_pd(lo[k]), h = _mm256_set1_pd(hi[k]);
    __m256d ek = _mm256_blendv_pd(zero, _mm256_sub_pd(p[k], h), _mm256_cmp_pd(p[k], h, _CMP_GT_OQ));
    ek = _mm256_blendv_pd(ek, _mm256_sub_pd(l, p[k]), _mm256_cmp_pd(p[k], l, _CMP_LT_OQ));
    d2 = _mm256_add_pd(d2, _mm256_mul_pd(ek, ek));
  }
  return d2;
}

// The 32-bit halves idx[0..3] of v.
__attribute__((target("avx2"), always_inline)) inline __m128i half(__m256d v, __m256i idx) {
  return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(_mm256_castpd_si256(v), idx));
}

/// pair()'s box test and plane certificate (PenaltyPass) for four consecutive points (p: their
/// x, y, z in lanes; f: the first point's force, x, y, z per point) and one object (e: the first
/// point's entry, the next ones `stride` entries on), in AVX2 lanes: the same IEEE operations
/// in the same order as the scalar code (no FMA), so the same bits. Adds the forces of the
/// pairs it answers to f, and their statistics; returns the lanes (bits) in the object's
/// reach that it did not answer.
__attribute__((target("avx2"), always_inline)) inline unsigned plane_lanes_avx2(
    const __m256d p[3], const ContactCache::Entry* e, std::size_t stride, const double* lo, const double* hi,
    double reach_sq, double eps, double k_rep, double rest, double* f, PenaltyStats& stats) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d reach =  // not out_of_reach()
      _mm256_cmp_pd(box_dist_sq_lanes(p, lo, hi), _mm256_set1_pd(reach_sq), _CMP_NGT_UQ);
  const int in_reach = _mm256_movemask_pd(reach);
  if (in_reach == 0) return 0;
  // The four planes (64 bytes each: a, n, x0 as floats, r2 and born), transposed to lanes.
  const auto* base = reinterpret_cast<const double*>(&e->plane);
  const std::size_t step = stride * (sizeof(ContactCache::Entry) / sizeof(double));
  __m256d lo4[4], hi4[4];
  for (std::size_t l = 0; l < 4; ++l) {
    lo4[l] = _mm256_load_pd(base + l * step);      // a0 a1 a2 n0
    hi4[l] = _mm256_load_pd(base + l * step + 4);  // n1 n2 (x0[0] x0[1]) (x0[2] r2|born)
  }
  __m256d a[3], n[3], q[4];
  transpose4(lo4, a[0], a[1], a[2], n[0]);
  transpose4(hi4, n[1], n[2], q[0], q[1]);
  // the floats: q[0] holds x0[0] and x0[1] of each lane, q[1] x0[2] and the word r2 | born << 16
  const __m256i even = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6), odd = _mm256_setr_epi32(1, 3, 5, 7, 1, 3, 5, 7);
  const __m256d dx = _mm256_sub_pd(p[0], _mm256_cvtps_pd(_mm_castsi128_ps(half(q[0], even))));
  const __m256d dy = _mm256_sub_pd(p[1], _mm256_cvtps_pd(_mm_castsi128_ps(half(q[0], odd))));
  const __m256d dz = _mm256_sub_pd(p[2], _mm256_cvtps_pd(_mm_castsi128_ps(half(q[1], even))));
  // radius_sq(): r2 as the upper half of a float (`born`, the word's upper half, shifts out)
  const __m256d r2 = _mm256_cvtps_pd(_mm_castsi128_ps(_mm_slli_epi32(half(q[1], odd), 16)));
  const __m256d abs_r2 = _mm256_andnot_pd(_mm256_set1_pd(-0.0), r2);
  const __m256d dist2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
  const __m256d inside = _mm256_and_pd(reach, _mm256_cmp_pd(dist2, abs_r2, _CMP_LT_OQ));
  __m256d face = _mm256_and_pd(inside, _mm256_cmp_pd(r2, zero, _CMP_GT_OQ));
  int answered = _mm256_movemask_pd(inside);
  if (_mm256_movemask_pd(face) != 0) {
    const __m256d s = _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(n[0], _mm256_sub_pd(p[0], a[0])), _mm256_mul_pd(n[1], _mm256_sub_pd(p[1], a[1]))),
        _mm256_mul_pd(n[2], _mm256_sub_pd(p[2], a[2])));
    // |s| < 1e-150 (s * s would underflow): left to the scalar code's signed_distance()
    const __m256d tiny = _mm256_and_pd(face, _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), s),
                                                          _mm256_set1_pd(1e-150), _CMP_NGE_UQ));
    answered &= ~_mm256_movemask_pd(tiny);
    face = _mm256_andnot_pd(tiny, face);
    const __m256d d = s;
    // respond(): the deepest penetration, then the band
    const __m256d behind = _mm256_and_pd(face, _mm256_cmp_pd(d, zero, _CMP_LT_OQ));
    alignas(32) double depth[4];
    _mm256_store_pd(depth, _mm256_and_pd(behind, _mm256_sub_pd(zero, d)));
    for (double v : depth) stats.max_penetration = std::max(stats.max_penetration, v);
    const __m256d veps = _mm256_set1_pd(eps), vrest = _mm256_set1_pd(rest);
    const __m256d near = _mm256_and_pd(face, _mm256_cmp_pd(d, vrest, _CMP_NGT_UQ));
    const __m256d tunnelled = _mm256_and_pd(near, _mm256_cmp_pd(d, _mm256_sub_pd(zero, veps), _CMP_LT_OQ));
    const int contact = _mm256_movemask_pd(_mm256_andnot_pd(tunnelled, near));
    stats.tunnelled += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(_mm256_movemask_pd(tunnelled))));
    if (contact != 0) {
      const __m256d c = _mm256_mul_pd(_mm256_set1_pd(k_rep), _mm256_sub_pd(vrest, d));  // k_rep (rest - d)
      __m256d cn[3];
      for (int k = 0; k < 3; ++k) cn[k] = _mm256_mul_pd(c, n[k]);
      // f_i += c n in lanes, only where in contact (the others keep their bits)
      __m256d fv[3];
      aos_to_lanes(f, fv);
      const __m256d in = _mm256_castsi256_pd(_mm256_setr_epi64x(-(contact & 1), -((contact >> 1) & 1),
                                                                -((contact >> 2) & 1), -((contact >> 3) & 1)));
      for (int k = 0; k < 3; ++k) fv[k] = _mm256_blendv_pd(fv[k], _mm256_add_pd(fv[k], cn[k]), in);
      lanes_to_aos(fv, f);
      stats.contacts += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(contact)));
    }
  }
  stats.certified += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(answered)));
  return static_cast<unsigned>(in_reach & ~answered);
}

}  // namespace

/// The pass's points [i, end) four at a time (x and f: x, y, z per point): whether all four
/// are finite and near a collider (else point(i + l) for each), then per object their plane
/// certificates in lanes and pair(i + l, o, p) for the rest, object by object so that every
/// point adds its objects' forces in the same order. Returns where it stopped.
__attribute__((target("avx2"))) std::size_t groups_avx2(PenaltyPass& pass, std::size_t i, std::size_t end) {
  const ColliderSet& set = pass.set;
  const double* x = pass.px;
  double* f = pass.pf;
  ContactCache& cache = *pass.cache;
  const Eigen::Vector3d& lo = pass.lo;
  const Eigen::Vector3d& hi = pass.hi;
  const double reach_sq = pass.reach_sq, eps = pass.eps, k_rep = pass.k_rep, to = pass.rest;
  PenaltyStats& stats = pass.stats;
  const std::size_t no = set.object_count();
  const __m256d zero = _mm256_setzero_pd(), limit = _mm256_set1_pd(reach_sq);
  for (; i + 4 <= end; i += 4) {
    __m256d p[3];  // x, y, z of the four points
    aos_to_lanes(x + 3 * i, p);
    // isfinite(x + y + z) and not box_dist_sq(lo, hi, p) > reach_sq, as point() tests them
    const __m256d sum = _mm256_add_pd(_mm256_add_pd(p[0], p[1]), p[2]);
    const int finite = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_sub_pd(sum, sum), zero, _CMP_EQ_OQ));
    const int near = _mm256_movemask_pd(_mm256_cmp_pd(box_dist_sq_lanes(p, lo.data(), hi.data()), limit, _CMP_NGT_UQ));
    if ((finite & near) != 0xf) [[unlikely]] {
      // four finite points far from every collider: point() would leave them as they are
      if (finite == 0xf && near == 0) continue;
      for (std::size_t l = 0; l < 4; ++l) pass.point(i + l);
      continue;
    }
    for (std::size_t o = 0; o < no; ++o) {
      const double *olo, *ohi;
      if (!detail::PenaltyLoop::box(set, o, olo, ohi)) continue;  // no triangles: out of reach
      for (unsigned rest = plane_lanes_avx2(p, &cache.entries[i * no + o], no, olo, ohi, reach_sq, eps, k_rep,
                                            to, f + 3 * i, stats);
           rest != 0; rest &= rest - 1) {
        const auto l = static_cast<std::size_t>(__builtin_ctz(rest));
        const double* xl = x + 3 * (i + l);
        const double q[3] = {xl[0], xl[1], xl[2]};
        pass.pair(i + l, o, q);
      }
    }
  }
  return i;
}

}  // namespace clothsim::detail

#endif  // CLOTHSIM_AVX2
