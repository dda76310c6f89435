// The AVX2 variants of the gathered spring passes (spring_passes.hpp): the same operations in
// the same order as the plain ones, four springs or a mass's four lanes at a time.
#include "spring_passes.hpp"

#ifdef CLOTHSIM_AVX2

#include <algorithm>
#include <cstring>

namespace clothsim::detail {

namespace {

// Listed: springs list[j0..j1), else springs j0..j1 (a range: consecutive rest lengths and
// kinds, contiguous stores, no list to read).
template <bool Listed>
__attribute__((target("avx2"))) void spring_pass_avx2_impl(const Model& model, const double* px, double* fs,
                                                           std::size_t j0, std::size_t j1,
                                                           const std::uint32_t* list) {
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const float* rest = model.rest_length0.data();
  const std::uint8_t* kind = model.spring_kind.data();
  // the stiffness of 4 springs: k_struct where the kind byte is 0, else k_bend (Model::spring_stiffness)
  const __m256d ks = _mm256_set1_pd(model.spring_modulus[0]), kb = _mm256_set1_pd(model.spring_modulus[1]);
  const float* scale = model.spring_scale.data();
  const __m256d zero = _mm256_setzero_pd();
  const __m256i xyz = _mm256_setr_epi64x(-1, -1, -1, 0);  // lanes x, y, z of a mass (never past x's end)
  // Eight springs per iteration as two independent groups of four, stage by stage, so that
  // one group's loads and products overlap the other's square root and division.
  constexpr int G = 2;
  std::size_t j = j0;
  for (; j + 4 * G <= j1; j += 4 * G) {
    std::size_t sl[G][4];
    for (int g = 0; g < G; ++g)
      for (int l = 0; l < 4; ++l) sl[g][l] = Listed ? list[j + 4 * g + l] : j + 4 * g + l;
    __m256d dx[G], dy[G], dz[G], len[G], kv[G], rv[G], c[G];
    for (int g = 0; g < G; ++g) {
      // per spring a lane vector xa - xb = (dx, dy, dz, 0), then transposed to dx, dy, dz of 4 springs
      __m256d d[4];
      for (int l = 0; l < 4; ++l)
        d[l] = _mm256_sub_pd(_mm256_maskload_pd(px + 3 * std::size_t{sa[sl[g][l]]}, xyz),
                             _mm256_maskload_pd(px + 3 * std::size_t{sb[sl[g][l]]}, xyz));
      const __m256d u0 = _mm256_unpacklo_pd(d[0], d[1]);  // x0 x1 z0 z1
      const __m256d u1 = _mm256_unpackhi_pd(d[0], d[1]);  // y0 y1 0 0
      const __m256d u2 = _mm256_unpacklo_pd(d[2], d[3]);  // x2 x3 z2 z3
      const __m256d u3 = _mm256_unpackhi_pd(d[2], d[3]);  // y2 y3 0 0
      dx[g] = _mm256_permute2f128_pd(u0, u2, 0x20);
      dy[g] = _mm256_permute2f128_pd(u1, u3, 0x20);
      dz[g] = _mm256_permute2f128_pd(u0, u2, 0x31);
    }
    for (int g = 0; g < G; ++g)
      len[g] = _mm256_sqrt_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx[g], dx[g]), _mm256_mul_pd(dy[g], dy[g])),
                                            _mm256_mul_pd(dz[g], dz[g])));
    for (int g = 0; g < G; ++g) {
      // A block's list is mostly runs of consecutive springs (the converter writes them edge by
      // edge): then the rest lengths and kinds load as in the list-free case.
      const bool run = Listed && sl[g][3] == sl[g][0] + 3;
      const std::size_t s0 = sl[g][0];
      __m256i kinds;  // the 4 kind bytes, widened
      __m128 sv;      // the 4 scales
      if (Listed && !run) {
        kinds = _mm256_setr_epi64x(kind[sl[g][0]], kind[sl[g][1]], kind[sl[g][2]], kind[sl[g][3]]);
        rv[g] = _mm256_setr_pd(rest[sl[g][0]], rest[sl[g][1]], rest[sl[g][2]], rest[sl[g][3]]);
        sv = _mm_setr_ps(scale[sl[g][0]], scale[sl[g][1]], scale[sl[g][2]], scale[sl[g][3]]);
      } else {
        std::uint32_t four;
        std::memcpy(&four, kind + s0, sizeof four);
        kinds = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(static_cast<int>(four)));
        rv[g] = _mm256_cvtps_pd(_mm_loadu_ps(rest + s0));
        sv = _mm_loadu_ps(scale + s0);
      }
      // k of the kind, times the spring's scale (Model::spring_stiffness)
      kv[g] = _mm256_mul_pd(
          _mm256_blendv_pd(kb, ks, _mm256_castsi256_pd(_mm256_cmpeq_epi64(kinds, _mm256_setzero_si256()))),
          _mm256_cvtps_pd(sv));
    }
    for (int g = 0; g < G; ++g) c[g] = _mm256_div_pd(_mm256_mul_pd(kv[g], _mm256_sub_pd(rv[g], len[g])), len[g]);
    for (int g = 0; g < G; ++g) {
      const __m256d cg = _mm256_blendv_pd(c[g], zero, _mm256_cmp_pd(len[g], zero, _CMP_EQ_OQ));
      const __m256d fx = _mm256_mul_pd(cg, dx[g]), fy = _mm256_mul_pd(cg, dy[g]), fz = _mm256_mul_pd(cg, dz[g]);
      // transpose (fx, fy, fz, 0) of 4 springs into 4 blocks x, y, z, 0
      const __m256d t0 = _mm256_unpacklo_pd(fx, fy);    // x0 y0 x2 y2
      const __m256d t1 = _mm256_unpackhi_pd(fx, fy);    // x1 y1 x3 y3
      const __m256d t2 = _mm256_unpacklo_pd(fz, zero);  // z0 0 z2 0
      const __m256d t3 = _mm256_unpackhi_pd(fz, zero);  // z1 0 z3 0
      _mm256_store_pd(fs + 4 * sl[g][0], _mm256_permute2f128_pd(t0, t2, 0x20));
      _mm256_store_pd(fs + 4 * sl[g][1], _mm256_permute2f128_pd(t1, t3, 0x20));
      _mm256_store_pd(fs + 4 * sl[g][2], _mm256_permute2f128_pd(t0, t2, 0x31));
      _mm256_store_pd(fs + 4 * sl[g][3], _mm256_permute2f128_pd(t1, t3, 0x31));
    }
  }
  spring_pass_scalar(model, px, fs, j, j1, Listed ? list : nullptr);
}

}  // namespace

__attribute__((target("avx2"))) void spring_pass_avx2(const Model& model, const double* px, double* fs,
                                                      std::size_t j0, std::size_t j1,
                                                      const std::uint32_t* list) {
  if (list)
    spring_pass_avx2_impl<true>(model, px, fs, j0, j1, list);
  else
    spring_pass_avx2_impl<false>(model, px, fs, j0, j1, nullptr);
}

namespace {

// The gather's first term for mass i: g m_i - gamma v_i with v, else the f_i already there.
__attribute__((target("avx2"), always_inline)) inline __m256d mass_base(std::size_t i, const double* m, __m256d g,
                                                                        double damping, double drag,
                                                                        const double* pv, const double* pf) {
  if (pv) {
    const __m256d v = _mm256_setr_pd(pv[3 * i], pv[3 * i + 1], pv[3 * i + 2], 0.0);
    const __m256d gamma = _mm256_set1_pd(damping + drag * m[i]);  // Model::damping_of
    return _mm256_sub_pd(_mm256_mul_pd(g, _mm256_set1_pd(m[i])), _mm256_mul_pd(gamma, v));
  }
  return _mm256_setr_pd(pf[3 * i], pf[3 * i + 1], pf[3 * i + 2], 0.0);
}

// The force of the spring whose b end entry `en` is (spring | kB): en << 5 in 32 bits drops
// the flag and is the byte offset of fs[4 spring] (SpringAdjacency::run, which enables the
// paths that use this, is made only for fewer than 2^27 springs).
__attribute__((target("avx2"), always_inline)) inline __m256d b_term(const char* fs_bytes, std::uint32_t en) {
  return _mm256_load_pd(reinterpret_cast<const double*>(fs_bytes + static_cast<std::uint32_t>(en << 5)));
}

}  // namespace

__attribute__((target("avx2"))) void mass_pass_avx2(const Model& model, const SpringAdjacency& adj,
                                                    const double* fs, const double* pv, double* pf,
                                                    std::size_t i0, std::size_t i1) {
  const double* m = model.mass.data();
  const Eigen::Vector3d& gv = model.gravity;
  const __m256d g = _mm256_setr_pd(gv[0], gv[1], gv[2], 0.0);
  const double damping = model.damping, drag = model.drag;
  const std::uint32_t* start = adj.start.data();
  const std::uint32_t* entry = adj.entry.data();
  const std::uint32_t* run = adj.run.empty() ? nullptr : adj.run.data();
  alignas(32) static const double signs[8] = {0.0, 0.0, 0.0, 0.0, -0.0, -0.0, -0.0, -0.0};
  const char* fb = reinterpret_cast<const char*>(fs);
  std::size_t i = i0;
  if (run) {
    // Two masses at a time, their sums interleaved term by term (each in its own order, so
    // the same bits): two dependency chains of adds for the core to overlap.
    for (; i + 2 <= i1; i += 2) {
      __m256d f[2] = {mass_base(i, m, g, damping, drag, pv, pf), mass_base(i + 1, m, g, damping, drag, pv, pf)};
      // the a ends: consecutive springs from the first entry on
      const std::uint32_t na0 = run[i], na1 = run[i + 1];
      const double* q0 = na0 > 0 ? fs + 4 * std::size_t{entry[start[i]]} : fs;
      const double* q1 = na1 > 0 ? fs + 4 * std::size_t{entry[start[i + 1]]} : fs;
      const std::uint32_t both = std::min(na0, na1);
      std::uint32_t t = 0;
      for (; t < both; ++t) {
        f[0] = _mm256_add_pd(f[0], _mm256_load_pd(q0 + 4 * std::size_t{t}));
        f[1] = _mm256_add_pd(f[1], _mm256_load_pd(q1 + 4 * std::size_t{t}));
      }
      for (std::uint32_t u = t; u < na0; ++u) f[0] = _mm256_add_pd(f[0], _mm256_load_pd(q0 + 4 * std::size_t{u}));
      for (std::uint32_t u = t; u < na1; ++u) f[1] = _mm256_add_pd(f[1], _mm256_load_pd(q1 + 4 * std::size_t{u}));
      // the b ends
      const std::uint32_t *b0 = entry + start[i] + na0, *b0_end = entry + start[i + 1];
      const std::uint32_t *b1 = entry + start[i + 1] + na1, *b1_end = entry + start[i + 2];
      for (; b0 < b0_end && b1 < b1_end; ++b0, ++b1) {
        f[0] = _mm256_sub_pd(f[0], b_term(fb, *b0));
        f[1] = _mm256_sub_pd(f[1], b_term(fb, *b1));
      }
      for (; b0 < b0_end; ++b0) f[0] = _mm256_sub_pd(f[0], b_term(fb, *b0));
      for (; b1 < b1_end; ++b1) f[1] = _mm256_sub_pd(f[1], b_term(fb, *b1));
      for (int h = 0; h < 2; ++h) {
        double* out = pf + 3 * (i + static_cast<std::size_t>(h));
        _mm_storeu_pd(out, _mm256_castpd256_pd128(f[h]));
        _mm_store_sd(out + 2, _mm256_extractf128_pd(f[h], 1));
      }
    }
  }
  for (; i < i1; ++i) {  // one at a time: every mass without runs, else the last of an odd range
    __m256d f = mass_base(i, m, g, damping, drag, pv, pf);
    // A run of a ends (+fs), a run of b ends (-fs: f - y), then any other order term by term
    // (ModelBuilder orders springs so that there is none; then the a ends are consecutive
    // springs, read as a range, and the rest are all b ends).
    std::uint32_t e = start[i];
    const std::uint32_t end = start[i + 1];
    if (run) {  // the a ends are consecutive springs: read as a range
      const std::uint32_t na = run[i];
      if (na > 0) {
        const double* q = fs + 4 * std::size_t{entry[e]};
        for (std::uint32_t k = 0; k < na; ++k) f = _mm256_add_pd(f, _mm256_load_pd(q + 4 * std::size_t{k}));
        e += na;
      }
      // the rest are b ends (SpringAdjacency::build checked)
      for (const std::uint32_t* b = entry + e; b < entry + end; ++b) f = _mm256_sub_pd(f, b_term(fb, *b));
      e = end;
    } else {
      for (; e < end && !(entry[e] & SpringAdjacency::kB); ++e)
        f = _mm256_add_pd(f, _mm256_load_pd(fs + 4 * std::size_t{entry[e]}));
    }
    for (; e < end && (entry[e] & SpringAdjacency::kB); ++e)
      f = _mm256_sub_pd(f, _mm256_load_pd(fs + 4 * std::size_t{entry[e] & ~SpringAdjacency::kB}));
    for (; e < end; ++e) {
      // +-fs: flip the sign bits for the b end (x + (-y) == x - y exactly)
      const std::uint32_t en = entry[e];
      const __m256d sign = _mm256_load_pd(signs + 4 * (en >> 31));
      f = _mm256_add_pd(f, _mm256_xor_pd(_mm256_load_pd(fs + 4 * std::size_t{en & ~SpringAdjacency::kB}), sign));
    }
    _mm_storeu_pd(pf + 3 * i, _mm256_castpd256_pd128(f));
    _mm_store_sd(pf + 3 * i + 2, _mm256_extractf128_pd(f, 1));
  }
}

}  // namespace clothsim::detail

#endif  // CLOTHSIM_AVX2
