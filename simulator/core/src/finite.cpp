// Whether a state is finite: integer tests on the bits, so the answer is the same in any
// order, on any thread count, with or without AVX2.
#include "parallel.hpp"

#include <cstring>
#include <limits>

namespace clothsim::detail {

namespace {

#ifdef CLOTHSIM_AVX2
// finite_span()'s test on the first n - n % 4 values in AVX2: that count, or SIZE_MAX when one
// of them is not finite.
__attribute__((target("avx2"))) std::size_t finite_prefix_avx2(const double* p, std::size_t n) {
  __m256i any = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) any = _mm256_or_si256(any, nonfinite_lanes(_mm256_loadu_pd(p + i)));
  return _mm256_movemask_pd(_mm256_castsi256_pd(any)) != 0 ? std::numeric_limits<std::size_t>::max() : i;
}
#endif

}  // namespace

bool finite_span_plain(const double* p, std::size_t n) {
  std::uint64_t any = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t b;
    std::memcpy(&b, p + i, sizeof b);
    any |= (b & kExpBits) + kExpOne;
  }
  return (any >> 63) == 0;
}

bool finite_span(const double* p, std::size_t n) {
#ifdef CLOTHSIM_AVX2
  if (use_avx2()) {
    const std::size_t i = finite_prefix_avx2(p, n);
    return i != std::numeric_limits<std::size_t>::max() && finite_span_plain(p + i, n - i);
  }
#endif
  return finite_span_plain(p, n);
}

bool all_finite(const State& s, const Workspace& ws) {
  // In 16 fixed slices (threaded for big states).
  constexpr int kSlices = 16;
  const auto n = static_cast<std::size_t>(s.x.size());
  const auto nv = static_cast<std::size_t>(s.v.size());
  [[maybe_unused]] const int nt = team(ws, n);
  if (n < 4096 || nv != n || nt <= 1) return finite_span(s.x.data(), n) && finite_span(s.v.data(), nv);
  bool part[kSlices];
#pragma omp parallel for schedule(static) num_threads(nt)
  for (int k = 0; k < kSlices; ++k) {
    const std::size_t lo = n * static_cast<std::size_t>(k) / kSlices, hi = n * static_cast<std::size_t>(k + 1) / kSlices;
    part[k] = finite_span(s.x.data() + lo, hi - lo) && finite_span(s.v.data() + lo, hi - lo);
  }
  for (bool ok : part)
    if (!ok) return false;
  return true;
}

}  // namespace clothsim::detail
