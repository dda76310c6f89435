// What the core's loops share: thread teams, the run-time AVX2 choice, finiteness tests.
#pragma once

#include <clothsim/cpu.hpp>
#include <clothsim/step.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace clothsim::detail {

#ifdef _OPENMP
inline std::size_t thread_num() { return static_cast<std::size_t>(omp_get_thread_num()); }
inline std::size_t team_size() { return static_cast<std::size_t>(omp_get_num_threads()); }
inline double wtime() { return omp_get_wtime(); }
#else
inline std::size_t thread_num() { return 0; }
inline std::size_t team_size() { return 1; }
inline double wtime() { return 0.0; }
#endif

/// Below this many items a parallel region costs more than it saves.
inline constexpr std::size_t kTeamWork = 4096;

/// Threads for a loop of `work` items on a Workspace that steps on ws.threads threads.
inline int team(const Workspace& ws, std::size_t work) { return work >= kTeamWork ? ws.threads : 1; }

/// Runs body(i) for i in [0, n) on nt threads, a static share each; on one thread without an
/// OpenMP region (libgomp makes a system call to enter one, even for one thread).
template <class Body>
void parallel_for(int nt, std::int64_t n, Body&& body) {
  if (nt <= 1) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp parallel for schedule(static) num_threads(nt)
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

/// parallel_for with the items handed out as threads get free (items of uneven work).
template <class Body>
void parallel_for_dynamic(int nt, std::int64_t n, Body&& body) {
  if (nt <= 1) {
    for (std::int64_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp parallel for schedule(dynamic) num_threads(nt)
  for (std::int64_t i = 0; i < n; ++i) body(i);
}

/// parallel_for of a body that answers: whether any answer was true (every body runs).
template <class Body>
bool parallel_any(int nt, std::int64_t n, Body&& body) {
  bool any = false;
  if (nt <= 1) {
    for (std::int64_t i = 0; i < n; ++i) any = body(i) || any;
    return any;
  }
#pragma omp parallel for schedule(static) num_threads(nt) reduction(|| : any)
  for (std::int64_t i = 0; i < n; ++i) any = body(i) || any;
  return any;
}

/// Whether pred(i) holds for any i in [0, n), pred without side effects: the threads stop
/// once one has found it (each looks at the others' answer every kFindChunk items).
template <class Pred>
bool parallel_find(int nt, std::int64_t n, Pred&& pred) {
  constexpr std::int64_t kFindChunk = 1024;
  if (nt <= 1) {
    for (std::int64_t i = 0; i < n; ++i)
      if (pred(i)) return true;
    return false;
  }
  bool found = false;
#pragma omp parallel num_threads(nt) shared(found)
  {
    const auto t = static_cast<std::int64_t>(thread_num()), parts = static_cast<std::int64_t>(team_size());
    const std::int64_t end = n * (t + 1) / parts;
    for (std::int64_t i = n * t / parts; i < end; i += kFindChunk) {
      bool seen = false;
#pragma omp atomic read
      seen = found;
      if (seen) break;
      for (std::int64_t j = i; j < std::min(end, i + kFindChunk); ++j)
        if (pred(j)) {
#pragma omp atomic write
          found = true;
          break;
        }
    }
  }
  return found;
}

/// Runs body(t, parts) on each of nt threads; on one thread, body(0, 1) without a region.
template <class Body>
void parallel_region(int nt, Body&& body) {
  if (nt <= 1) return body(0, 1);
#pragma omp parallel num_threads(nt)
  body(static_cast<int>(thread_num()), static_cast<int>(team_size()));
}

/// The collision loop's work for team(): a query costs ~10 spring terms, so half a mass's.
inline std::size_t collision_work(std::size_t masses, std::size_t objects) { return masses * objects / 2; }


/// Whether p[0 .. n) are all finite (integer tests: the same answer on any path).
bool finite_span(const double* p, std::size_t n);
/// The same, without AVX2.
bool finite_span_plain(const double* p, std::size_t n);
/// Whether x and v are all finite, on ws.threads threads for big states.
bool all_finite(const State& s, const Workspace& ws);

/// A double is NaN or infinite when its exponent bits are all ones: (bits & kExpBits) +
/// kExpOne then carries into bit 63.
inline constexpr std::uint64_t kExpBits = 0x7ff0000000000000ull, kExpOne = std::uint64_t{1} << 52;

#ifdef CLOTHSIM_AVX2
/// finite_span()'s test on 4 values: bit 63 of a lane is set when its value is NaN or infinite.
__attribute__((target("avx2"), always_inline)) inline __m256i nonfinite_lanes(__m256d v) {
  return _mm256_add_epi64(_mm256_and_si256(_mm256_castpd_si256(v), _mm256_set1_epi64x(static_cast<long long>(kExpBits))),
                          _mm256_set1_epi64x(static_cast<long long>(kExpOne)));
}
#endif

}  // namespace clothsim::detail
