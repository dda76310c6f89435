// The two passes of the gathered spring forces: pass 1 computes each spring's force once, pass
// 2 sums each mass's springs in the scatter loop's order. Each exists in plain C++ and in AVX2
// (spring_passes_avx2.cpp, chosen at run time); both do the same IEEE operations in the same
// order (sqrt and / are correctly rounded in both; no FMA), so the results are bit-identical
// to each other and to the scatter loop.
#pragma once

#include "parallel.hpp"

#include <clothsim/step.hpp>

#include <cstddef>
#include <cstdint>

namespace clothsim::detail {

/// Pass 1, springs [j0, j1) (or those list[j0..j1) names): fs[4s..4s+2] = c dx,
/// c = k (l - |dx|) / |dx|, the scatter's arithmetic; |dx| = 0 gives 0.
void spring_pass_scalar(const Model& model, const double* px, double* fs, std::size_t j0, std::size_t j1,
                        const std::uint32_t* list = nullptr);
/// Pass 2, masses [i0, i1): f_i = base_i + sum over i's springs, in increasing index, of +-fs;
/// with velocities pv, base_i = g m_i - gamma v_i, else the f_i already there.
void mass_pass_scalar(const Model& model, const SpringAdjacency& adj, const double* fs, const double* pv,
                      double* pf, std::size_t i0, std::size_t i1);
#ifdef CLOTHSIM_AVX2
void spring_pass_avx2(const Model& model, const double* px, double* fs, std::size_t j0, std::size_t j1,
                      const std::uint32_t* list = nullptr);
void mass_pass_avx2(const Model& model, const SpringAdjacency& adj, const double* fs, const double* pv,
                    double* pf, std::size_t i0, std::size_t i1);
#endif

}  // namespace clothsim::detail
