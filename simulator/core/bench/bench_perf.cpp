// Google Benchmark cases of docs/performance.md (perf_sweep prints the full tables):
//   bench_perf --benchmark_counters_tabular=true
// SpringsScatter is the reference (the plain scalar scatter loop); SpringsGather/N/threads the
// gathered forces; Step/N/threads a whole step of the seed's method (no collider); SkirtStep the
// baked skirt after 1 s. Counter per_spring / per_step: seconds (SI prefix) per spring / step.
// SpringsFloat/N: the same gathered, blocked forces in float (8 springs per AVX2 vector, a float
// state); SpringsMixed/N: the same with the state in double (xa - xb in double, then float).
// The float-versus-double experiment of docs/performance.md: counter rel_err is the largest
// force error against double, relative to the largest force, on a strained cloth, whose double
// forces SpringsGatherStrained/N times.
#include "perf_scenes.hpp"

#include <clothsim/scene.hpp>
#include <clothsim/stability.hpp>

#include "skirt.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define PERF_AVX2 1
#endif

namespace {

using namespace clothsim;

void per_spring(benchmark::State& st, const Model& m) {
  st.counters["per_spring"] = benchmark::Counter(static_cast<double>(m.spring_count()),
                                                 benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
}

void BM_SpringsScatter(benchmark::State& st) {
  const Model m = perf::grid_model(static_cast<int>(st.range(0)));
  const State s = make_state(m);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
  for (auto _ : st) {
    add_spring_forces(m, s.x, f);
    benchmark::DoNotOptimize(f.data());
  }
  per_spring(st, m);
}

void BM_SpringsGather(benchmark::State& st) {
  const Model m = perf::grid_model(static_cast<int>(st.range(0)));
  const State s = make_state(m);
  Workspace ws = make_workspace(m);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
  ws.threads = static_cast<int>(st.range(1));
  for (auto _ : st) {
    add_spring_forces(m, s.x, f, ws);
    benchmark::DoNotOptimize(f.data());
  }
  per_spring(st, m);
}

// The grid with every mass moved up to 2 mm at random: strained springs, forces of ~1 N.
State strained(const Model& m) {
  State s = make_state(m);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.002, 0.002);
  for (Eigen::Index i = 0; i < s.x.size(); ++i) s.x.data()[i] += u(rng);
  return s;
}

#ifdef PERF_AVX2
// The float experiment: positions as float4 (x, y, z, 0), spring forces as float4 per spring,
// the gather in float; the same blocks and order as the double path in spring_forces.cpp.
struct FloatSprings {
  std::vector<float> x, fs, f, rest, k;  // x: 4 per mass; fs: 4 per spring; f: 4 per mass
  void load(const Model& m, const Eigen::Matrix3Xd& xd) {
    const std::size_t n = m.mass_count(), sc = m.spring_count();
    x.assign(4 * n, 0.0f);
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < 3; ++r) x[4 * i + r] = static_cast<float>(xd(r, static_cast<Eigen::Index>(i)));
    fs.assign(4 * sc + 32, 0.0f);
    f.assign(4 * n, 0.0f);
    rest.assign(sc, 0.0f);
    k.assign(sc, 0.0f);
    for (std::size_t j = 0; j < sc; ++j) {
      rest[j] = static_cast<float>(m.rest_length0[j]);
      k[j] = static_cast<float>(m.spring_stiffness(j));
    }
  }
};

// Mixed = true: the positions stay double (xd, 3 per mass) and each xa - xb is taken in double,
// then rounded to float: the float error is then relative to the spring, not to the position.
template <bool Mixed>
__attribute__((target("avx2"))) void float_springs(const Model& m, const SpringAdjacency& adj,
                                                   FloatSprings& w, const double* xd) {
  const std::uint32_t* sa = m.spring_a.data();
  const std::uint32_t* sb = m.spring_b.data();
  const float* px = w.x.data();
  const __m256i xyz = _mm256_setr_epi64x(-1, -1, -1, 0);
  float* fs = w.fs.data();
  const std::size_t blocks = adj.block_start.size() - 1, nm = m.mass_count();
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t* list = adj.block_springs.data();
    std::size_t j = adj.block_start[b];
    const std::size_t j1 = adj.block_start[b + 1];
    for (; j + 8 <= j1; j += 8) {
      __m128 d[8];
      std::uint32_t sl[8];
      for (int l = 0; l < 8; ++l) {
        sl[l] = list[j + l];
        if constexpr (Mixed)
          d[l] = _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_maskload_pd(xd + 3 * std::size_t{sa[sl[l]]}, xyz),
                                               _mm256_maskload_pd(xd + 3 * std::size_t{sb[sl[l]]}, xyz)));
        else
          d[l] = _mm_sub_ps(_mm_load_ps(px + 4 * std::size_t{sa[sl[l]]}), _mm_load_ps(px + 4 * std::size_t{sb[sl[l]]}));
      }
      _MM_TRANSPOSE4_PS(d[0], d[1], d[2], d[3]);  // d[0] = x of springs 0-3, d[1] = y, d[2] = z
      _MM_TRANSPOSE4_PS(d[4], d[5], d[6], d[7]);
      const __m256 dx = _mm256_set_m128(d[4], d[0]), dy = _mm256_set_m128(d[5], d[1]),
                   dz = _mm256_set_m128(d[6], d[2]);
      const __m256 len = _mm256_sqrt_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                                      _mm256_mul_ps(dz, dz)));
      float rv[8], kv[8];
      for (int l = 0; l < 8; ++l) rv[l] = w.rest[sl[l]], kv[l] = w.k[sl[l]];
      const __m256 c = _mm256_div_ps(_mm256_mul_ps(_mm256_loadu_ps(kv), _mm256_sub_ps(_mm256_loadu_ps(rv), len)), len);
      __m128 o[8];
      const __m256 fx = _mm256_mul_ps(c, dx), fy = _mm256_mul_ps(c, dy), fz = _mm256_mul_ps(c, dz);
      o[0] = _mm256_castps256_ps128(fx), o[1] = _mm256_castps256_ps128(fy), o[2] = _mm256_castps256_ps128(fz);
      o[3] = _mm_setzero_ps();
      o[4] = _mm256_extractf128_ps(fx, 1), o[5] = _mm256_extractf128_ps(fy, 1), o[6] = _mm256_extractf128_ps(fz, 1);
      o[7] = _mm_setzero_ps();
      _MM_TRANSPOSE4_PS(o[0], o[1], o[2], o[3]);
      _MM_TRANSPOSE4_PS(o[4], o[5], o[6], o[7]);
      for (int l = 0; l < 8; ++l) _mm_store_ps(fs + 4 * std::size_t{sl[l]}, o[l]);
    }
    for (; j < j1; ++j) {
      const std::uint32_t sl = list[j];
      const float* a = px + 4 * std::size_t{sa[sl]};
      const float* bb = px + 4 * std::size_t{sb[sl]};
      const float dx = a[0] - bb[0], dy = a[1] - bb[1], dz = a[2] - bb[2];
      const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
      const float c = len == 0.0f ? 0.0f : w.k[sl] * (w.rest[sl] - len) / len;
      float* o = fs + 4 * std::size_t{sl};
      o[0] = c * dx, o[1] = c * dy, o[2] = c * dz, o[3] = 0.0f;
    }
    const __m128 negate = _mm_set1_ps(-0.0f);
    for (std::size_t i = b * SpringAdjacency::kBlock; i < std::min(nm, (b + 1) * SpringAdjacency::kBlock); ++i) {
      __m128 acc = _mm_setzero_ps();
      for (std::uint32_t e = adj.start[i]; e < adj.start[i + 1]; ++e) {
        const std::uint32_t en = adj.entry[e];
        const __m128 q = _mm_load_ps(fs + 4 * std::size_t{en & ~SpringAdjacency::kB});
        acc = _mm_add_ps(acc, (en & SpringAdjacency::kB) ? _mm_xor_ps(q, negate) : q);
      }
      _mm_store_ps(w.f.data() + 4 * i, acc);
    }
  }
}

template <bool Mixed>
void springs_float(benchmark::State& st) {
  if (!__builtin_cpu_supports("avx2")) {
    st.SkipWithError("no AVX2");
    return;
  }
  const Model m = perf::grid_model(static_cast<int>(st.range(0)));
  const State s = strained(m);
  Workspace ws = make_workspace(m);
  FloatSprings w;
  w.load(m, s.x);
  // the double forces of the same state, for the error
  Eigen::Matrix3Xd fd = Eigen::Matrix3Xd::Zero(3, s.x.cols());
  add_spring_forces(m, s.x, fd, ws);
  for (auto _ : st) {
    float_springs<Mixed>(m, *ws.adjacency, w, s.x.data());
    benchmark::DoNotOptimize(w.f.data());
  }
  double err = 0.0, big = 0.0;
  for (Eigen::Index i = 0; i < fd.cols(); ++i)
    for (int r = 0; r < 3; ++r) {
      err = std::max(err, std::abs(static_cast<double>(w.f[4 * static_cast<std::size_t>(i) + static_cast<std::size_t>(r)]) - fd(r, i)));
      big = std::max(big, std::abs(fd(r, i)));
    }
  st.counters["rel_err"] = err / big;
  per_spring(st, m);
}
void BM_SpringsFloat(benchmark::State& st) { springs_float<false>(st); }
void BM_SpringsMixed(benchmark::State& st) { springs_float<true>(st); }
#endif

// SpringsGather on the strained cloth of SpringsFloat (the same work; the forces differ).
void BM_SpringsGatherStrained(benchmark::State& st) {
  const Model m = perf::grid_model(static_cast<int>(st.range(0)));
  const State s = strained(m);
  Workspace ws = make_workspace(m);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
  for (auto _ : st) {
    add_spring_forces(m, s.x, f, ws);
    benchmark::DoNotOptimize(f.data());
  }
  per_spring(st, m);
}

void BM_Step(benchmark::State& st) {
  const Model m = perf::grid_model(static_cast<int>(st.range(0)));
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.threads = static_cast<int>(st.range(1));
  for (auto _ : st) step(m, s, ws);
  per_spring(st, m);
}

// The skirt in the seed's per-vertex model (its weight per mass at real gravity, symplectic
// Euler, dt 2 ms: docs/physics.md), the 2016 program's scene and method.
void BM_SkirtStep(benchmark::State& st) {
  const auto& scene = b2o::gen::skirt::scene;
  Options o;
  o.material = Material::Seed, o.mass = 0.0102, o.damping = 0.03, o.dt = 0.002;
  const Model m = build_model(scene, resolve_options(o, true));
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  // The mean over whole 20 s runs (fall, wrap, slide, rest), as the headless summary measures
  // it: the state starts again at every 20 s of simulated time, so the phases weigh as in a run
  // (not mostly the cloth at rest).
  for (auto _ : st) {
    step(m, s, ws);
    if (s.t >= 20.0) {
      st.PauseTiming();
      s = make_state(m);
      st.ResumeTiming();
    }
  }
  st.counters["masses"] = static_cast<double>(m.mass_count());
}

// The skirt as baked (rubber, XPBD, its planned substeps): one step of dt, averaged over a
// whole 20 s run (fall, wrap, slide, rest), with self-contact off (0) and on (1). Their ratio,
// measured in one run, is what self-contact costs.
void BM_SkirtSelfContact(benchmark::State& st) {
  const auto& scene = b2o::gen::skirt::scene;
  Options o = scene_options(scene);
  o.self_collision = st.range(0) != 0 ? Switch::On : Switch::Off;
  const Model m = build_model(scene, o);
  const int substeps = plan_substeps(m.options.dt, analyse_stability(m).dt_stable, SubstepPolicy{}).substeps;
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.substeps = substeps;
  for (auto _ : st) {
    for (int q = 0; q < substeps; ++q) step(m, s, ws);
    if (s.t >= 20.0 - 1e-9) {
      st.PauseTiming();
      s = make_state(m);
      ws = make_workspace(m);
      ws.substeps = substeps;
      st.ResumeTiming();
    }
  }
  st.counters["substeps"] = substeps;
}

}  // namespace

BENCHMARK(BM_SkirtSelfContact)->Arg(0)->Arg(1)->Iterations(2000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SpringsScatter)->RangeMultiplier(4)->Range(16, 256)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SpringsGather)->ArgsProduct({{16, 64, 256}, {1, 2}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SpringsGatherStrained)->RangeMultiplier(4)->Range(16, 256)->Unit(benchmark::kMicrosecond);
#ifdef PERF_AVX2
BENCHMARK(BM_SpringsFloat)->RangeMultiplier(4)->Range(16, 256)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SpringsMixed)->RangeMultiplier(4)->Range(16, 256)->Unit(benchmark::kMicrosecond);
#endif
BENCHMARK(BM_Step)->ArgsProduct({{64, 256}, {1, 2}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SkirtStep)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
