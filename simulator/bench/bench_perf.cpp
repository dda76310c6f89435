// Google Benchmark cases of issue 6 (perf_sweep prints the full tables):
//   bench_perf --benchmark_counters_tabular=true
// SpringsScatter is the reference (the plain scalar scatter loop); SpringsGather/N/threads the
// gathered forces; Step/N/threads a whole step of the seed's method (no collider); SkirtStep the
// baked skirt after 1 s. Counter per_spring / per_step: seconds (SI prefix) per spring / step.
#include "perf_scenes.hpp"

#include <clothsim/scene.hpp>

#include "skirt.h"

#include <benchmark/benchmark.h>

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
  set_threads(static_cast<int>(st.range(1)));
  for (auto _ : st) {
    add_spring_forces(m, s.x, f, ws);
    benchmark::DoNotOptimize(f.data());
  }
  set_threads(1);
  per_spring(st, m);
}

void BM_Step(benchmark::State& st) {
  const Model m = perf::grid_model(static_cast<int>(st.range(0)));
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  set_threads(static_cast<int>(st.range(1)));
  for (auto _ : st) step(m, s, ws);
  set_threads(1);
  per_spring(st, m);
}

void BM_SkirtStep(benchmark::State& st) {
  const auto& scene = b2o::gen::skirt::scene;
  const Model m = build_model(scene, scene_options(scene));
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < 100; ++i) step(m, s, ws);
  for (auto _ : st) step(m, s, ws);
  st.counters["masses"] = static_cast<double>(m.mass_count());
}

}  // namespace

BENCHMARK(BM_SpringsScatter)->RangeMultiplier(4)->Range(16, 256)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SpringsGather)->ArgsProduct({{16, 64, 256}, {1, 2}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Step)->ArgsProduct({{64, 256}, {1, 2}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SkirtStep)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
