// Which vector instructions the wide loops of the collision and the core use, chosen once at
// run time: AVX2 where the CPU has it, unless CLOTHSIM_NO_AVX2 is set (the plain loops give
// the same bits; the tests run both). CLOTHSIM_AVX2 is defined where the AVX2 variants are built.
#pragma once

#include <cstdlib>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CLOTHSIM_AVX2 1
#endif

namespace clothsim::detail {

#ifdef CLOTHSIM_AVX2
inline bool use_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") && std::getenv("CLOTHSIM_NO_AVX2") == nullptr;
  return yes;
}
#else
inline bool use_avx2() { return false; }
#endif

}  // namespace clothsim::detail
