// XPBD's link updates in AVX2 (xpbd_links.hpp): four links of a colour at a time, each lane
// doing project()'s or bend()'s operations in their order; a link of length 0 is left alone.
#include "xpbd_links.hpp"

#ifdef CLOTHSIM_AVX2

namespace clothsim::detail {

namespace {

// p[0..3) as lanes x, y, z (0 in the fourth), and back: a 16- and an 8-byte access each, so
// that a load finds the stores of a link just before it (a masked store is slow on AMD cores,
// and a 32-byte load cannot take its bytes from two stores).
__attribute__((target("avx2"), always_inline)) inline __m256d load3(const double* p) {
  return _mm256_set_m128d(_mm_load_sd(p + 2), _mm_loadu_pd(p));
}
__attribute__((target("avx2"), always_inline)) inline void store3(double* p, __m256d v) {
  _mm_storeu_pd(p, _mm256_castpd256_pd128(v));
  _mm_store_sd(p + 2, _mm256_extractf128_pd(v, 1));
}

// Four links' a - b as lane vectors (dx, dy, dz, 0) in d, and transposed into dx, dy, dz.
struct Four {
  __m256d d[4], dx, dy, dz, len, wa, wb;
};

__attribute__((target("avx2"), always_inline)) inline void load_four(const Link* l, const double* w, const double* x,
                                                                     Four& f) {
  for (int k = 0; k < 4; ++k)
    f.d[k] = _mm256_sub_pd(load3(x + 3 * std::size_t{l[k].a}), load3(x + 3 * std::size_t{l[k].b}));
  const __m256d u0 = _mm256_unpacklo_pd(f.d[0], f.d[1]), u1 = _mm256_unpackhi_pd(f.d[0], f.d[1]);
  const __m256d u2 = _mm256_unpacklo_pd(f.d[2], f.d[3]), u3 = _mm256_unpackhi_pd(f.d[2], f.d[3]);
  f.dx = _mm256_permute2f128_pd(u0, u2, 0x20);
  f.dy = _mm256_permute2f128_pd(u1, u3, 0x20);
  f.dz = _mm256_permute2f128_pd(u0, u2, 0x31);
  f.len = _mm256_sqrt_pd(
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(f.dx, f.dx), _mm256_mul_pd(f.dy, f.dy)), _mm256_mul_pd(f.dz, f.dz)));
  f.wa = _mm256_setr_pd(w[l[0].a], w[l[1].a], w[l[2].a], w[l[3].a]);
  f.wb = _mm256_setr_pd(w[l[0].b], w[l[1].b], w[l[2].b], w[l[3].b]);
}

// y[a] += ca d and y[b] -= cb d for each link whose length is not 0.
__attribute__((target("avx2"), always_inline)) inline void apply_four(const Link* l, const Four& f, __m256d ca,
                                                                      __m256d cb, double* y) {
  const int zero = _mm256_movemask_pd(_mm256_cmp_pd(f.len, _mm256_setzero_pd(), _CMP_EQ_OQ));
  alignas(32) double a[4], b[4];
  _mm256_store_pd(a, ca), _mm256_store_pd(b, cb);
  for (int k = 0; k < 4; ++k) {
    if (zero & (1 << k)) continue;
    double* ya = y + 3 * std::size_t{l[k].a};
    double* yb = y + 3 * std::size_t{l[k].b};
    store3(ya, _mm256_add_pd(load3(ya), _mm256_mul_pd(_mm256_set1_pd(a[k]), f.d[k])));
    store3(yb, _mm256_sub_pd(load3(yb), _mm256_mul_pd(_mm256_set1_pd(b[k]), f.d[k])));
  }
}

__attribute__((target("avx2"), always_inline)) inline __m256d rest_of(const Link* l) {
  return _mm256_setr_pd(l[0].rest, l[1].rest, l[2].rest, l[3].rest);
}
__attribute__((target("avx2"), always_inline)) inline __m256d k_of(const Link* l) {
  return _mm256_setr_pd(l[0].k, l[1].k, l[2].k, l[3].k);
}

// The links [0, n) four at a time, the last n % 4 one at a time. Bend: each pulls on the
// velocities y with c = h k (rest - len) / len (s = h); else each is projected on the positions
// y = x with c = (rest - len) / (wa + wb + inv_h2 / k) / len (s = inv_h2). Either way mass a
// moves by c wa d and mass b by -c wb d.
template <bool Bend>
__attribute__((target("avx2"))) void links_avx2(const Link* links, std::size_t n, const double* w, double s,
                                                const double* x, double* y) {
  const __m256d sv = _mm256_set1_pd(s);
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const Link* l = links + j;
    Four f;
    load_four(l, w, x, f);
    const __m256d stretch = _mm256_sub_pd(rest_of(l), f.len);
    const __m256d c =
        Bend ? _mm256_div_pd(_mm256_mul_pd(_mm256_mul_pd(sv, k_of(l)), stretch), f.len)
             : _mm256_div_pd(_mm256_div_pd(stretch, _mm256_add_pd(_mm256_add_pd(f.wa, f.wb), _mm256_div_pd(sv, k_of(l)))), f.len);
    apply_four(l, f, _mm256_mul_pd(c, f.wa), _mm256_mul_pd(c, f.wb), y);
  }
  for (; j < n; ++j) Bend ? bend(links[j], w, s, x, y) : project(links[j], w, s, y);
}

}  // namespace

void project_links_avx2(const Link* links, std::size_t n, const double* w, double inv_h2, double* x) {
  links_avx2<false>(links, n, w, inv_h2, x, x);
}

void bend_links_avx2(const Link* links, std::size_t n, const double* w, double h, const double* x, double* v) {
  links_avx2<true>(links, n, w, h, x, v);
}

}  // namespace clothsim::detail

#endif
