// The seed's integrator, report eqs. 1-7: x += h v(t); f at x(t+h); v += h f / m. Threaded,
// and in AVX2 where the CPU has it (the same bits either way).
#include "stages.hpp"
#include "symplectic_euler.hpp"

#include <algorithm>
#include <cstdint>

namespace clothsim::detail {

// One step of eqs. 1-7; on one thread with AVX2 it also tells whether the new state is finite
// (checked: true), as all_finite() would after it, from the values it writes.
void symplectic_euler(const Model& model, State& state, Workspace& ws, double h, bool& checked, bool& finite) {
  checked = false;
  const auto n = static_cast<std::int64_t>(model.mass_count());
  double* px = state.x.data();
  double* pv = state.v.data();
  const double* pf = ws.f.data();
  const double* im = model.inv_mass.data();
  const int nt = team(ws, static_cast<std::size_t>(n));
#ifdef CLOTHSIM_AVX2
  if (use_avx2()) {
    // In AVX2, each thread its share of masses (a multiple of 4; the same bits on any count),
    // with the finiteness of what it writes.
    const std::uint8_t* pinned = model.pinned.data();
    const auto nm = static_cast<std::size_t>(n);
    const auto share = [nm](std::size_t t, std::size_t parts) { return std::min(nm, (nm * t / parts + 3) / 4 * 4); };
    bool x_ok = true, v_ok = true;
    if (nt <= 1) {  // (on one thread no OpenMP region, as in parallel_for)
      x_ok = drift_avx2(px, pv, pinned, h, nm);
    } else {
#pragma omp parallel num_threads(nt) reduction(&& : x_ok)
      {
        const std::size_t lo = share(thread_num(), team_size()), hi = share(thread_num() + 1, team_size());
        x_ok = drift_avx2(px + 3 * lo, pv + 3 * lo, pinned + lo, h, hi - lo);
      }
    }
    compute_forces(model, state.x, state.v, ws.f, ws);  // eqs. 2-5 at x(t+h)
    if (nt <= 1) {
      v_ok = kick_avx2(pv, pf, im, pinned, h, nm);
    } else {
#pragma omp parallel num_threads(nt) reduction(&& : v_ok)
      {
        const std::size_t lo = share(thread_num(), team_size()), hi = share(thread_num() + 1, team_size());
        v_ok = kick_avx2(pv + 3 * lo, pf + 3 * lo, im + lo, pinned + lo, h, hi - lo);
      }
    }
    // the pinned masses end with their saved positions and velocity 0 (step() puts them back)
    checked = true;
    finite = x_ok && v_ok && finite_span(ws.pinned_x.data(), static_cast<std::size_t>(ws.pinned_x.size()));
    return;
  }
#endif
  parallel_for(nt, 3 * n, [&](std::int64_t e) { px[e] += h * pv[e]; });  // eq. 1
  compute_forces(model, state.x, state.v, ws.f, ws);            // eqs. 2-5 at x(t+h)
  // eqs. 6-7 (damping is in f): v += h (f / m), as h * (f * (1/m))
  parallel_for(nt, n, [&](std::int64_t i) {
    for (std::int64_t r = 0; r < 3; ++r) pv[3 * i + r] += h * (pf[3 * i + r] * im[i]);
  });
}

}  // namespace clothsim::detail
