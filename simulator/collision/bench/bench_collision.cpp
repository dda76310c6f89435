// BVH vs brute force: accumulate_penalty() for points around a tessellated unit sphere
// (icosphere, 1280 .. 1.3M triangles), eps = 0.1. Reported: time per point (counter s_per_query, SI prefix).
//   bench_collision --benchmark_counters_tabular=true
// Points lie in a shell of +-1.5 eps about the surface (as cloth draped over the sphere);
// "Hints" moves them by a small jitter between calls and keeps the previous closest triangle,
// as a simulation step does. BM_Moving: monotonic motion (see there), hints vs ContactCache.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "clothsim/collision.hpp"
#include "clothsim/collision_meshes.hpp"
#include "shell_points.hpp"

namespace {

constexpr double kEps = 0.1;
constexpr double kRep = 1000.0;

const clothsim::ColliderSet& sphere(int level) {
  static std::map<int, std::unique_ptr<clothsim::ColliderSet>> cache;
  auto& s = cache[level];
  if (!s) {
    const auto m = clothsim::meshes::icosphere(level, 1.0);
    s = std::make_unique<clothsim::ColliderSet>();
    s->add_object("sphere", m.vertices, m.indices);
    s->build();
  }
  return *s;
}

using clothsim::bench::shell_points;

void run(benchmark::State& state, clothsim::QueryMethod method, bool hints, int n, double lo,
         double hi, bool coherent = true, double step = 1e-3) {
  const auto& set = sphere(static_cast<int>(state.range(0)));
  // Two nearby configurations (~1 mm apart), alternated when hints are used.
  const Eigen::Matrix3Xd xa = shell_points(n, lo, hi, 42, coherent);
  const Eigen::Matrix3Xd xb = xa + step * shell_points(n, 0.0, 1.0, 7, false);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, n);
  std::vector<std::int32_t> h(hints ? static_cast<std::size_t>(n) : 0, -1);
  clothsim::PenaltyStats stats;
  std::size_t contacts = 0;
  bool odd = false;
  for (auto _ : state) {
    accumulate_penalty(set, hints && odd ? xb : xa, kEps, kRep, f, stats, h, method);
    odd = !odd;
    contacts += stats.contacts;
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["triangles"] = static_cast<double>(set.triangle_count());
  state.counters["bytes_per_tri"] =
      static_cast<double>(set.bvh_bytes()) / static_cast<double>(set.triangle_count());
  state.counters["s_per_query"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * n,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["contact_ratio"] = static_cast<double>(contacts) /
                                    (static_cast<double>(state.iterations()) * n);
}

void BM_BruteForce(benchmark::State& s) {
  // Fewer points for the large meshes: brute force is O(T) per point.
  const int n = s.range(0) >= 6 ? 16 : 256;
  run(s, clothsim::QueryMethod::BruteForce, false, n, 1.0 - 1.5 * kEps, 1.0 + 1.5 * kEps);
}
void BM_Bvh(benchmark::State& s) {
  run(s, clothsim::QueryMethod::Bvh, false, 4096, 1.0 - 1.5 * kEps, 1.0 + 1.5 * kEps);
}
void BM_BvhHints(benchmark::State& s) {
  run(s, clothsim::QueryMethod::Bvh, true, 4096, 1.0 - 1.5 * kEps, 1.0 + 1.5 * kEps);
}
// Monotonic motion: the points turn rigidly about the x axis through the sphere's centre by
// step / (mean distance from the axis) radians per call, so on average each point moves `step`
// per call (exactly |p x a| * angle) and keeps its distance to the sphere while it crosses
// triangles; a candidate list or certificate expires as it would for sliding cloth (a back and
// forth between two configurations would never expire it). range(1): step in um (1: at rest,
// 200: 0.1 m/s at dt 0.002, 1000: 1 mm per call); range(2): 0 = BVH + hints, K >= 1 = a
// ContactCache with K candidates (1: the single-triangle certificate).
void moving(benchmark::State& state, double eps, bool front = false, bool prepared = false) {
  // A copy of the built sphere, whose clearances no other benchmark has computed.
  const clothsim::ColliderSet set = sphere(static_cast<int>(state.range(0)));
  if (prepared) set.prepare_clearances();  // else computed as first needed, in the timing
  const double step = 1e-6 * static_cast<double>(state.range(1));
  const auto k = static_cast<std::size_t>(state.range(2));
  const int n = 4096;
  Eigen::Matrix3Xd x = front ? shell_points(n, 1.0, 1.0 + eps, 42)
                             : shell_points(n, 1.0 - 1.5 * eps, 1.0 + 1.5 * eps, 42);
  const double mean_rho = x.bottomRows(2).colwise().norm().mean();
  const double angle = step / mean_rho;
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
  clothsim::ContactCache cache;
  cache.resize(static_cast<std::size_t>(n), set.object_count(), k);
  std::vector<std::int32_t> h(static_cast<std::size_t>(n), -1);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, n);
  clothsim::PenaltyStats stats;
  std::size_t certified = 0, contacts = 0;
  // Warm up: 20 moving calls (the lists and certificates get their steady mix of ages).
  for (int w = 0; w < 20; ++w) {
    x = rot * x;
    if (k > 0) accumulate_penalty(set, x, eps, kRep, f, stats, cache);
    else accumulate_penalty(set, x, eps, kRep, f, stats, h);
  }
  for (auto _ : state) {
    state.PauseTiming();
    x = rot * x;
    state.ResumeTiming();
    if (k > 0) {
      accumulate_penalty(set, x, eps, kRep, f, stats, cache);
      certified += stats.certified;
    } else {
      accumulate_penalty(set, x, eps, kRep, f, stats, h);
    }
    contacts += stats.contacts;
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["s_per_query"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * n,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["certified"] =
      static_cast<double>(certified) / (static_cast<double>(state.iterations()) * n);
  state.counters["contact_ratio"] = static_cast<double>(contacts) /
                                    (static_cast<double>(state.iterations()) * n);
  state.counters["cache_B_per_point"] = static_cast<double>(k > 0 ? cache.bytes_per_entry() : 4);
}
void MovingArgs(benchmark::internal::Benchmark* b) {
  for (int level = 3; level <= 8; ++level)
    for (int step : {1, 200, 1000})
      for (int k : {0, 1, 8, 16, 32}) b->Args({level, step, k});
}
void BM_Moving(benchmark::State& state) { moving(state, kEps); }
// BM_Moving with every point in front of the sphere within eps (0 < d <= eps, 1 <= |x| <= 1.1):
// cloth lying or sliding on a collider, which stays on its front side. (BM_Moving's shell also
// holds points up to 1.5 eps deep inside the sphere.)
// range(3) = 1: the clearances computed before (ColliderSet::prepare_clearances()); 0: as
// the points first need them, inside the timing (the points keep reaching new triangles).
void BM_MovingFront(benchmark::State& state) { moving(state, kEps, true, state.range(3) != 0); }
void MovingFrontArgs(benchmark::internal::Benchmark* b) {
  for (int level = 3; level <= 8; ++level)
    for (int step : {1, 200, 1000}) {
      b->Args({level, step, 0, 0});
      for (int prepared : {0, 1}) b->Args({level, step, 16, prepared});
    }
}
// BM_Moving with the band eps = range(3) mm (points in +-1.5 eps): what the cost owes to the
// band's width against the triangles' (level 6: edges ~19 mm, level 8: ~5 mm). A wide band
// holds many nearly equidistant triangles, so certificates break sooner and searches visit more.
void BM_MovingBand(benchmark::State& state) { moving(state, 1e-3 * static_cast<double>(state.range(3))); }
void MovingBandArgs(benchmark::internal::Benchmark* b) {
  for (int level = 3; level <= 8; ++level)
    for (int k : {0, 16})
      for (int eps_mm : {5, 10, 20, 50, 100}) b->Args({level, 200, k, eps_mm});
}
void BM_BvhHintsShuffled(benchmark::State& s) {  // no memory coherence between points
  run(s, clothsim::QueryMethod::Bvh, true, 4096, 1.0 - 1.5 * kEps, 1.0 + 1.5 * kEps, false);
}
void BM_BvhFar(benchmark::State& s) {  // nothing in reach: the root-box early-out
  run(s, clothsim::QueryMethod::Bvh, false, 4096, 2.0, 3.0);
}

// The 2016 skirt scene's colliders (models/README.md): floor 18 x 18 quads (648 triangles) at
// y = -2.33, icosphere 80 triangles r 0.87; 353 masses: 2/3 resting on the floor at d = 0.099
// (eps - m g / k_rep with k_rep 1000), 1/3 at 0.05 outside the sphere's circumsphere (inside the
// band of its flat faces). Time of one step's collision call; arg 0 = BVH + hints,
// 1 = brute force, 2 = ContactCache (masses at rest: the same positions every call).
void BM_SkirtLike(benchmark::State& state) {
  static const clothsim::ColliderSet set = [] {
    clothsim::ColliderSet s;
    const auto fl = clothsim::meshes::floor_grid(18, 10.0, -2.33);
    const auto sp = clothsim::meshes::icosphere(1, 0.87, Eigen::Vector3d(0.04, -1.08, 0.03));
    s.add_object("Grid", fl.vertices, fl.indices);
    s.add_object("Icosphere", sp.vertices, sp.indices);
    s.build();
    return s;
  }();
  const bool brute = state.range(0) == 1, cached = state.range(0) == 2;
  const int n = 353;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Matrix3Xd x(3, n), f = Eigen::Matrix3Xd::Zero(3, n);
  for (int i = 0; i < n; ++i) {
    if (i % 3 != 0) {
      x.col(i) = Eigen::Vector3d(2.0 * u(rng), -2.33 + 0.099, 2.0 * u(rng));
    } else {
      Eigen::Vector3d d(g(rng), std::abs(g(rng)), g(rng));
      x.col(i) = Eigen::Vector3d(0.04, -1.08, 0.03) + (0.87 + 0.05) * d.normalized();
    }
  }
  std::vector<std::int32_t> h(brute ? 0 : static_cast<std::size_t>(n) * 2, -1);
  clothsim::PenaltyStats stats;
  clothsim::ContactCache cache;
  cache.resize(static_cast<std::size_t>(n), set.object_count());
  for (auto _ : state) {
    if (cached)
      accumulate_penalty(set, x, kEps, kRep, f, stats, cache);
    else
      accumulate_penalty(set, x, kEps, kRep, f, stats, h,
                         brute ? clothsim::QueryMethod::BruteForce : clothsim::QueryMethod::Bvh);
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["s_per_query"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * n,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["contacts"] = static_cast<double>(stats.contacts);
}

}  // namespace

BENCHMARK(BM_SkirtLike)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BruteForce)->DenseRange(3, 8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Bvh)->DenseRange(3, 8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BvhHints)->DenseRange(3, 8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Moving)->Apply(MovingArgs)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MovingFront)->Apply(MovingFrontArgs)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MovingBand)->Apply(MovingBandArgs)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BvhHintsShuffled)->DenseRange(3, 8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BvhFar)->Arg(6)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
