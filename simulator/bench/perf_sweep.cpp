// The scaling sweep of issue 6: a triangulated N x N cloth over a unit icosphere of T triangles.
// Prints tables and writes CSV. Every speed is the minimum over repetitions, and each is shown
// next to a reference measured in the same run:
//   springs:   the gathered spring forces (1 and 2 threads) vs the plain scalar scatter loop;
//   collision: accumulate_penalty with the BVH (and the step's hints) vs brute force (every
//              triangle), the latter on an evenly strided subset of the masses so that one
//              repetition tests at most --brute-pairs point-triangle pairs;
//   step:      ms per step of the seed's method, 1 vs 2 threads, and whether the states agree
//              bit for bit after the same steps.
//   perf_sweep [--quick] [--csv DIR] [--reps R] [--max-n N] [--max-level L]
#include "perf_scenes.hpp"

#include <clothsim/scene.hpp>

#include "skirt.h"
#include "skirt_hires.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <sys/resource.h>

using namespace clothsim;
using Clock = std::chrono::steady_clock;

namespace {

int g_reps = 5;

// Minimum over g_reps repetitions of the seconds one call of fn takes (each repetition makes
// `inner` calls, after one untimed warm-up call).
double min_seconds(const std::function<void()>& fn, int inner) {
  fn();
  double best = 1e300;
  for (int r = 0; r < g_reps; ++r) {
    const auto t0 = Clock::now();
    for (int k = 0; k < inner; ++k) fn();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count() / inner);
  }
  return best;
}

// Enough calls per repetition for ~20 ms.
int inner_for(double est_seconds) { return std::max(1, static_cast<int>(0.02 / std::max(est_seconds, 1e-9))); }

double timed(const std::function<void()>& fn) {
  const auto t0 = Clock::now();
  fn();
  const double once = std::chrono::duration<double>(Clock::now() - t0).count();
  return min_seconds(fn, inner_for(once));
}

struct Csv {
  std::ofstream out;
  explicit Csv(const std::string& path, const char* header) {
    if (path.empty()) return;
    out.open(path);
    if (!out) {
      std::cerr << "perf_sweep: error: cannot write '" << path << "'\n";
      std::exit(1);
    }
    out << header << '\n';
  }
  template <class... A>
  void row(const A&... a) {
    if (!out) return;
    bool first = true;
    ((out << (first ? "" : ",") << a, first = false), ...);
    out << '\n';
  }
};

// Runs `steps` steps with `threads` threads from the model's start; returns the state hash.
std::uint64_t run_hash(const Model& m, int steps, int threads) {
  set_threads(threads);
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < steps; ++i) step(m, s, ws);
  set_threads(1);
  return state_hash(s);
}

void skirt_table(const char* label, const b2o::Scene& scene, int settle, Csv& csv) {
  const Model m = build_model(scene, scene_options(scene));
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  for (int i = 0; i < settle; ++i) step(m, s, ws);  // on the collider, as most of a run is
  set_threads(1);
  const double t1 = timed([&] { step(m, s, ws); });
  set_threads(2);
  const double t2 = timed([&] { step(m, s, ws); });
  set_threads(1);
  // collision alone: BVH with hints (as in step) vs brute force, same positions
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
  PenaltyStats st;
  std::vector<std::int32_t> hints(static_cast<std::size_t>(s.x.cols()) * m.colliders->object_count(), -1);
  const auto& o = m.options;
  const double bvh = timed([&] { accumulate_penalty(*m.colliders, s.x, o.epsilon, o.k_rep, f, st, hints); });
  const double brute = timed([&] {
    accumulate_penalty(*m.colliders, s.x, o.epsilon, o.k_rep, f, st, {}, QueryMethod::BruteForce);
  });
  const double n = static_cast<double>(m.mass_count());
  std::printf("%-12s %7zu %8zu %7zu | %9.2f %9.2f %6.2f | %9.1f %9.1f %7.1f | %7.3f\n", label, m.mass_count(),
              m.spring_count(), collider_triangle_count(m), t1 * 1e6, t2 * 1e6, t1 / t2, bvh / n * 1e9,
              brute / n * 1e9, brute / bvh, o.dt / t1);
  csv.row(label, m.mass_count(), m.spring_count(), collider_triangle_count(m), t1 * 1e6, t2 * 1e6, bvh / n * 1e9,
          brute / n * 1e9, o.dt / t1);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string csv_dir;
  int max_n = 512, max_level = 8;
  double brute_pairs = 3e7;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "perf_sweep: error: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--quick") quick = true;
      else if (a == "--csv") csv_dir = next();
      else if (a == "--reps") g_reps = std::stoi(next());
      else if (a == "--max-n") max_n = std::stoi(next());
      else if (a == "--max-level") max_level = std::stoi(next());
      else if (a == "--brute-pairs") brute_pairs = std::stod(next());
      else {
        std::cerr << "perf_sweep: error: unknown option '" << a << "'\n";
        return 2;
      }
    } catch (const std::exception&) {
      std::cerr << "perf_sweep: error: " << a << ": not a number\n";
      return 2;
    }
  }
  if (g_reps < 1 || max_n < 16 || max_level < 3 || brute_pairs < 1) {
    std::cerr << "perf_sweep: error: need --reps >= 1, --max-n >= 16, --max-level >= 3, --brute-pairs >= 1\n";
    return 2;
  }
  if (quick) max_n = std::min(max_n, 64), max_level = std::min(max_level, 4), g_reps = std::min(g_reps, 2);
  if (!csv_dir.empty()) std::filesystem::create_directories(csv_dir);
  auto path = [&](const char* name) { return csv_dir.empty() ? std::string() : csv_dir + "/" + name; };

  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) < 0) load[0] = -1;
  std::printf("perf_sweep: %d repetitions (min), load average %.2f, threads 1 and 2\n\n", g_reps, load[0]);

  // --- springs and the step without a collider, per N ---------------------------------
  Csv csv_s(path("springs.csv"),
            "n,masses,springs,scatter_ns_per_spring,gather1_ns_per_spring,gather2_ns_per_spring,"
            "step1_ms,step2_ms,speedup2,identical,model_B_per_mass,state_B_per_mass,workspace_B_per_mass");
  std::printf("springs (no collider)                     ns per spring per step       |  step ms (no collider)        | bytes per mass\n");
  std::printf("%5s %8s %8s | %8s %8s %8s %6s | %8s %8s %6s %5s | %6s %6s %6s\n", "N", "masses", "springs",
              "scatter", "gather1", "gather2", "ratio", "1 thr", "2 thr", "x", "same", "model", "state", "work");
  bool all_identical = true;
  for (int n = 16; n <= max_n; n *= 2) {
    const Model m = perf::grid_model(n);
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    const double sc = static_cast<double>(m.spring_count());
    Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
    const double scatter = timed([&] { add_spring_forces(m, s.x, f); });
    set_threads(1);
    const double g1 = timed([&] { add_spring_forces(m, s.x, f, ws); });
    set_threads(2);
    const double g2 = timed([&] { add_spring_forces(m, s.x, f, ws); });
    set_threads(1);
    const double st1 = timed([&] { step(m, s, ws); });
    set_threads(2);
    const double st2 = timed([&] { step(m, s, ws); });
    set_threads(1);
    const bool same = run_hash(m, 20, 1) == run_hash(m, 20, 2);
    all_identical = all_identical && same;
    const auto mem = perf::memory_per_mass(m, s, ws);
    std::printf("%5d %8zu %8zu | %8.2f %8.2f %8.2f %6.1f | %8.3f %8.3f %6.2f %5s | %6.0f %6.0f %6.0f\n", n,
                m.mass_count(), m.spring_count(), scatter / sc * 1e9, g1 / sc * 1e9, g2 / sc * 1e9, scatter / g1,
                st1 * 1e3, st2 * 1e3, st1 / st2, same ? "yes" : "NO", mem.model, mem.state, mem.workspace);
    csv_s.row(n, m.mass_count(), m.spring_count(), scatter / sc * 1e9, g1 / sc * 1e9, g2 / sc * 1e9, st1 * 1e3,
              st2 * 1e3, st1 / st2, same ? 1 : 0, mem.model, mem.state, mem.workspace);
  }

  // --- collision and the full step, per (N, T) ---------------------------------------------
  Csv csv_c(path("collision.csv"),
            "n,masses,triangles,bvh_bytes_per_triangle,bvh_ns_per_mass,cache_ns_per_mass,certified,"
            "brute_ns_per_mass,brute_masses,step1_ms,step2_ms,identical");
  std::printf("\ncollision (cloth 0.05 m over a unit icosphere, eps 0.1; moving 1 mm per call)  ns per mass  |  step ms\n");
  std::printf("%5s %8s %8s %7s | %9s %9s %5s %10s %8s %8s | %8s %8s %5s\n", "N", "masses", "tris", "B/tri",
              "bvh+hint", "cache", "cert", "brute", "ratio", "brute_n", "1 thr", "2 thr", "same");
  for (int level = 3; level <= max_level; ++level) {
    const auto set = perf::sphere_collider(level);
    const double tris = static_cast<double>(set->triangle_count());
    for (int n = 16; n <= max_n; n *= 2) {
      const Model m = perf::grid_model(n, set);
      State s = make_state(m);
      Workspace ws = make_workspace(m);
      const auto& o = m.options;
      Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
      PenaltyStats st;
      std::vector<std::int32_t> hints(m.mass_count(), -1);
      const double masses = static_cast<double>(m.mass_count());
      // the search every call, from the previous answer (hints), the two configurations alternating
      Eigen::Matrix3Xd xb = s.x;
      xb.row(0).array() += 1e-3;  // 1 mm apart: cloth sliding at 0.1 m/s, dt 0.01
      bool flip = false;
      const double bvh = timed([&] {
        accumulate_penalty(*set, (flip = !flip) ? xb : s.x, o.epsilon, o.k_rep, f, st, hints);
      }) / masses;
      // as the step does: the ContactCache (exact certificates), the same alternation
      ContactCache cache;
      cache.resize(m.mass_count(), set->object_count());
      std::size_t certified = 0, queried = 0;
      const double cached = timed([&] {
        accumulate_penalty(*set, (flip = !flip) ? xb : s.x, o.epsilon, o.k_rep, f, st, cache);
        certified += st.certified;
        queried += m.mass_count();
      }) / masses;
      const double cert = static_cast<double>(certified) / static_cast<double>(queried);
      // brute force on every k-th mass (the cost cap)
      const auto cap = static_cast<Eigen::Index>(std::max(1.0, std::min(masses, brute_pairs / tris)));
      const Eigen::Index stride = (s.x.cols() + cap - 1) / cap;
      Eigen::Matrix3Xd xs(3, (s.x.cols() + stride - 1) / stride);
      for (Eigen::Index i = 0; i < xs.cols(); ++i) xs.col(i) = s.x.col(i * stride);
      Eigen::Matrix3Xd fs = Eigen::Matrix3Xd::Zero(3, xs.cols());
      const double brute = timed([&] {
        accumulate_penalty(*set, xs, o.epsilon, o.k_rep, fs, st, {}, QueryMethod::BruteForce);
      }) / static_cast<double>(xs.cols());
      set_threads(1);
      const double st1 = timed([&] { step(m, s, ws); });
      set_threads(2);
      const double st2 = timed([&] { step(m, s, ws); });
      set_threads(1);
      const bool same = run_hash(m, 5, 1) == run_hash(m, 5, 2);
      all_identical = all_identical && same;
      const double bpt = static_cast<double>(set->bvh_bytes()) / tris;
      std::printf("%5d %8zu %8.0f %7.0f | %9.1f %9.1f %4.0f%% %10.1f %8.0f %8ld | %8.3f %8.3f %5s\n", n,
                  m.mass_count(), tris, bpt, bvh * 1e9, cached * 1e9, cert * 100, brute * 1e9, brute / bvh,
                  static_cast<long>(xs.cols()), st1 * 1e3, st2 * 1e3, same ? "yes" : "NO");
      csv_c.row(n, m.mass_count(), tris, bpt, bvh * 1e9, cached * 1e9, cert, brute * 1e9, xs.cols(), st1 * 1e3,
                st2 * 1e3, same ? 1 : 0);
    }
  }

  // --- the baked skirts -------------------------------------------------------------------------
  Csv csv_k(path("skirt.csv"),
            "scene,masses,springs,triangles,step1_us,step2_us,bvh_ns_per_mass,brute_ns_per_mass,realtime_factor");
  std::printf("\nbaked scenes (after 1 s of simulation)   step us             | collision ns per mass       | real time\n");
  std::printf("%-12s %7s %8s %7s | %9s %9s %6s | %9s %9s %7s | %7s\n", "scene", "masses", "springs", "tris",
              "1 thr", "2 thr", "x", "bvh+hint", "brute", "ratio", "factor");
  skirt_table("skirt", b2o::gen::skirt::scene, 100, csv_k);
  skirt_table("skirt_hires", b2o::gen::skirt_hires::scene, quick ? 10 : 100, csv_k);

  if (!all_identical) {
    std::printf("\nperf_sweep: error: a 2-thread run differed from the 1-thread run\n");
    return 1;
  }
  return 0;
}
