// The AVX2 updates of the symplectic Euler step (symplectic_euler_avx2.cpp).
#pragma once

#include "parallel.hpp"

#include <cstddef>
#include <cstdint>

namespace clothsim::detail {

#ifdef CLOTHSIM_AVX2
/// x += h v for n masses; whether every new x of a free mass is finite.
bool drift_avx2(double* x, const double* v, const std::uint8_t* pinned, double h, std::size_t n);
/// v += h (f * (1/m)) for n masses; whether every new v of a free mass is finite.
bool kick_avx2(double* v, const double* f, const double* im, const std::uint8_t* pinned, double h, std::size_t n);
#endif

}  // namespace clothsim::detail
