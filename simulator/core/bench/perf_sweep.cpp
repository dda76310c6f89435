// The scaling sweep (docs/performance.md): a triangulated N x N cloth over a unit icosphere of T
// triangles.
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

#include <charconv>
#include <chrono>
#include <cmath>
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

// The cloth turning rigidly about the horizontal x axis through the unit sphere's centre, so
// that its masses keep their distance to the sphere and slide across its triangles, `step`
// metres per call on average over the masses within reach (|x| <= 1 + 2 eps): monotonic motion,
// which a back-and-forth between two configurations would not be (a cache would never expire).
// `warm` untimed calls first (the lists and certificates reach their steady age), then the
// minimum over g_reps repetitions of `inner` calls of the query alone (the rotation untimed).
// cache_k: 0 = BVH + hints, K >= 1 = a ContactCache with K candidates. Returns s per call and
// the share of certified (point, object) pairs.
std::pair<double, double> sliding_seconds(const ColliderSet& set, const Eigen::Matrix3Xd& x0, double eps,
                                          double k_rep, double step, std::size_t cache_k, int warm, int inner) {
  Eigen::Matrix3Xd x = x0, f = Eigen::Matrix3Xd::Zero(3, x0.cols());
  double rho = 0.0;
  int near = 0;
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    if (x.col(i).norm() <= 1.0 + 2.0 * eps) rho += x.col(i).tail<2>().norm(), ++near;
  const double angle = step / (near > 0 ? rho / near : 1.0);
  const double c = std::cos(angle), sn = std::sin(angle);
  std::vector<std::int32_t> hints(static_cast<std::size_t>(x.cols()) * set.object_count(), -1);
  ContactCache cache;
  cache.resize(static_cast<std::size_t>(x.cols()), set.object_count(), cache_k);
  PenaltyStats st;
  std::size_t certified = 0, pairs = 0;
  const auto call = [&] {
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      const double y = x(1, i), z = x(2, i);
      x(1, i) = c * y - sn * z;
      x(2, i) = sn * y + c * z;
    }
    const auto t0 = Clock::now();
    if (cache_k > 0) accumulate_penalty(set, x, eps, k_rep, f, st, cache);
    else accumulate_penalty(set, x, eps, k_rep, f, st, hints);
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  for (int k = 0; k < warm; ++k) call();
  double best = 1e300;
  for (int r = 0; r < g_reps; ++r) {
    double sum = 0.0;
    for (int k = 0; k < inner; ++k) {
      sum += call();
      certified += st.certified;
      pairs += static_cast<std::size_t>(x.cols()) * set.object_count();
    }
    best = std::min(best, sum / inner);
  }
  return {best, static_cast<double>(certified) / static_cast<double>(pairs)};
}

bool g_write_failed = false;  // a CSV write failed (a full disk): the exit code says so

struct Csv {
  std::ofstream out;
  std::string path;
  explicit Csv(const std::string& p, const char* header) : path(p) {
    if (path.empty()) return;
    out.open(path);
    if (!out) {
      std::cerr << "perf_sweep: error: cannot write '" << path << "'\n";
      std::exit(1);
    }
    out << header << '\n';
  }
  Csv(const Csv&) = delete;
  Csv& operator=(const Csv&) = delete;
  ~Csv() {
    if (path.empty()) return;
    out.close();
    if (out.fail()) {
      std::cerr << "perf_sweep: error: writing '" << path << "' failed (disk full?)\n";
      g_write_failed = true;
    }
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
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.threads = threads;
  for (int i = 0; i < steps; ++i) step(m, s, ws);
  return state_hash(s);
}

void skirt_table(const char* label, const b2o::Scene& scene, double settle, Csv& csv) {
  const Model m = build_model(scene, scene_options(scene));
  State s = make_state(m);
  Workspace ws = make_workspace(m);
  ws.threads = 2;
  while (s.t < settle - 0.5 * m.options.dt) step(m, s, ws);  // on the collider, as most of a run is
  ws.threads = 1;
  const double t1 = timed([&] { step(m, s, ws); });
  ws.threads = 2;
  const double t2 = timed([&] { step(m, s, ws); });
  ws.threads = 1;
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

// A whole decimal integer or number (std::stoi reads "1e9" as 1 and "3x" as 3).
bool whole_int(const std::string& t, int& v) {
  const char* end = t.data() + t.size();
  const auto r = std::from_chars(t.data(), end, v);
  return r.ec == std::errc() && r.ptr == end;
}
bool whole_double(const std::string& t, double& v) {
  char* end = nullptr;
  v = std::strtod(t.c_str(), &end);
  return !t.empty() && end == t.c_str() + t.size() && std::isfinite(v);
}

constexpr const char* kUsage =
    "Usage: perf_sweep [--quick] [--csv DIR] [--reps R] [--max-n N] [--max-level L] [--brute-pairs P]\n"
    "The scaling sweep (docs/performance.md): springs, collision and whole steps of an\n"
    "N x N cloth over an icosphere, each next to its reference in the same run, then the baked skirts.\n"
    "  --quick          N <= 64, levels <= 4, 2 repetitions (a minute instead of ~10)\n"
    "  --csv DIR        also write springs.csv, collision.csv, collision_speed.csv, skirt.csv into DIR\n"
    "  --reps R         repetitions per measurement, the minimum is shown (default 5; 1..1000)\n"
    "  --max-n N        largest cloth side (default 512; 16..2048)\n"
    "  --max-level L    finest icosphere level (default 8: 1.3M triangles; 3..9)\n"
    "  --brute-pairs P  point-triangle pairs per brute-force repetition (default 3e7; 1..1e11)\n"
    "Exit codes: 0 ok, 1 a 2-thread run differed or a CSV could not be written, 2 bad usage.\n";

namespace {

// The sweep's settings from the command line.
struct Args {
  bool quick = false;
  std::string csv_dir;
  int max_n = 512, max_level = 8;
  double brute_pairs = 3e7;
  std::string path(const char* name) const { return csv_dir.empty() ? std::string() : csv_dir + "/" + name; }
};

// Reads the command line into `a`; -1 to go on, else the exit code (help: 0, bad input: 2).
int parse_args(int argc, char** argv, Args& args) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "perf_sweep: error: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    bool number = true;
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--quick") {
      args.quick = true;
    } else if (a == "--csv") {
      args.csv_dir = next();
    } else if (a == "--reps") {
      number = whole_int(next(), g_reps);
    } else if (a == "--max-n") {
      number = whole_int(next(), args.max_n);
    } else if (a == "--max-level") {
      number = whole_int(next(), args.max_level);
    } else if (a == "--brute-pairs") {
      number = whole_double(next(), args.brute_pairs);
    } else {
      std::cerr << "perf_sweep: error: unknown option '" << a << "' (perf_sweep --help lists them)\n";
      return 2;
    }
    if (!number) {
      std::cerr << "perf_sweep: error: " << a << " " << argv[i] << ": not a whole number\n";
      return 2;
    }
  }
  // (upper limits: --max-n 70000 or --max-level 17 run out of memory and abort)
  if (g_reps < 1 || g_reps > 1000 || args.max_n < 16 || args.max_n > 2048 || args.max_level < 3 ||
      args.max_level > 9 || args.brute_pairs < 1 || args.brute_pairs > 1e11) {
    std::cerr << "perf_sweep: error: need --reps 1..1000, --max-n 16..2048, --max-level 3..9 (20 * 4^9 = 5.2M "
                 "triangles), --brute-pairs 1..1e11\n";
    return 2;
  }
  if (args.quick)
    args.max_n = std::min(args.max_n, 64), args.max_level = std::min(args.max_level, 4), g_reps = std::min(g_reps, 2);
  return -1;
}

// The CSV folder, made and probed before the sweep: a bad folder is found at once, not after
// minutes. Empty, or the error.
std::string check_csv_dir(const Args& args) {
  if (args.csv_dir.empty()) return {};
  std::error_code ec;
  std::filesystem::create_directories(args.csv_dir, ec);
  if (ec || !std::filesystem::is_directory(args.csv_dir))
    return "--csv " + args.csv_dir + ": " + (ec ? ec.message() : std::string("not a directory"));
  for (const char* name : {"springs.csv", "collision.csv", "collision_speed.csv", "skirt.csv"}) {
    std::ofstream probe(args.path(name), std::ios::app);
    if (!probe) return "--csv: cannot write '" + args.path(name) + "'";
  }
  return {};
}

// Springs and the step without a collider, per N; false when 2 threads differed from one.
bool springs_table(const Args& args) {
  const int max_n = args.max_n;
  bool all_identical = true;
  Csv csv_s(args.path("springs.csv"),
            "n,masses,springs,scatter_ns_per_spring,gather1_ns_per_spring,gather2_ns_per_spring,"
            "step1_ms,step2_ms,speedup2,identical,model_B_per_mass,state_B_per_mass,workspace_B_per_mass");
  std::printf("springs (no collider)                     ns per spring per step       |  step ms (no collider)        | bytes per mass\n");
  std::printf("%5s %8s %8s | %8s %8s %8s %6s | %8s %8s %6s %5s | %6s %6s %6s\n", "N", "masses", "springs",
              "scatter", "gather1", "gather2", "ratio", "1 thr", "2 thr", "x", "same", "model", "state", "work");
  for (int n = 16; n <= max_n; n *= 2) {
    const Model m = perf::grid_model(n);
    State s = make_state(m);
    Workspace ws = make_workspace(m);
    const double sc = static_cast<double>(m.spring_count());
    Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, s.x.cols());
    const double scatter = timed([&] { add_spring_forces(m, s.x, f); });
    ws.threads = 1;
    const double g1 = timed([&] { add_spring_forces(m, s.x, f, ws); });
    ws.threads = 2;
    const double g2 = timed([&] { add_spring_forces(m, s.x, f, ws); });
    ws.threads = 1;
    const double st1 = timed([&] { step(m, s, ws); });
    ws.threads = 2;
    const double st2 = timed([&] { step(m, s, ws); });
    ws.threads = 1;
    const bool same = run_hash(m, 20, 1) == run_hash(m, 20, 2);
    all_identical = all_identical && same;
    const auto mem = perf::memory_per_mass(m, s, ws);
    std::printf("%5d %8zu %8zu | %8.2f %8.2f %8.2f %6.1f | %8.3f %8.3f %6.2f %5s | %6.0f %6.0f %6.0f\n", n,
                m.mass_count(), m.spring_count(), scatter / sc * 1e9, g1 / sc * 1e9, g2 / sc * 1e9, scatter / g1,
                st1 * 1e3, st2 * 1e3, st1 / st2, same ? "yes" : "NO", mem.model, mem.state, mem.workspace);
    csv_s.row(n, m.mass_count(), m.spring_count(), scatter / sc * 1e9, g1 / sc * 1e9, g2 / sc * 1e9, st1 * 1e3,
              st2 * 1e3, st1 / st2, same ? 1 : 0, mem.model, mem.state, mem.workspace);
  }

  return all_identical;
}

// Collision and the full step, per (N, T); false when 2 threads differed from one.
bool collision_table(const Args& args) {
  const int max_n = args.max_n, max_level = args.max_level;
  const double brute_pairs = args.brute_pairs;
  bool all_identical = true;
  Csv csv_c(args.path("collision.csv"),
            "n,masses,triangles,bvh_bytes_per_triangle,bvh_ns_per_mass,cache_ns_per_mass,certified,"
            "brute_ns_per_mass,brute_masses,step1_ms,step2_ms,identical,cache1_ns_per_mass");
  std::printf("\ncollision (cloth 0.05 m over a unit icosphere, eps 0.1; sliding 1 mm per call)  ns per mass  |  step ms\n");
  std::printf("%5s %8s %8s %7s | %9s %9s %5s %9s %10s %8s %8s | %8s %8s %5s\n", "N", "masses", "tris", "B/tri",
              "bvh+hint", "cache", "cert", "cache K=1", "brute", "ratio", "brute_n", "1 thr", "2 thr", "same");
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
      // the search every call from the previous answer (hints), the ContactCache as the step uses
      // it, and a single-triangle certificate (K = 1); sliding 1 mm per call
      const int warm = n >= 256 ? 30 : 60;
      const double bvh = sliding_seconds(*set, s.x, o.epsilon, o.k_rep, 1e-3, 0, warm, 3).first / masses;
      const auto [cache_s, cert] = sliding_seconds(*set, s.x, o.epsilon, o.k_rep, 1e-3,
                                                   ContactCache::kDefaultCandidates, warm, 3);
      const double cached = cache_s / masses;
      const double single = sliding_seconds(*set, s.x, o.epsilon, o.k_rep, 1e-3, 1, warm, 3).first / masses;
      // brute force on every k-th mass (the cost cap)
      const auto cap = static_cast<Eigen::Index>(std::max(1.0, std::min(masses, brute_pairs / tris)));
      const Eigen::Index stride = (s.x.cols() + cap - 1) / cap;
      Eigen::Matrix3Xd xs(3, (s.x.cols() + stride - 1) / stride);
      for (Eigen::Index i = 0; i < xs.cols(); ++i) xs.col(i) = s.x.col(i * stride);
      Eigen::Matrix3Xd fs = Eigen::Matrix3Xd::Zero(3, xs.cols());
      const double brute = timed([&] {
        accumulate_penalty(*set, xs, o.epsilon, o.k_rep, fs, st, {}, QueryMethod::BruteForce);
      }) / static_cast<double>(xs.cols());
      ws.threads = 1;
      const double st1 = timed([&] { step(m, s, ws); });
      ws.threads = 2;
      const double st2 = timed([&] { step(m, s, ws); });
      ws.threads = 1;
      const bool same = run_hash(m, 5, 1) == run_hash(m, 5, 2);
      all_identical = all_identical && same;
      const double bpt = static_cast<double>(set->bvh_bytes()) / tris;
      std::printf("%5d %8zu %8.0f %7.0f | %9.1f %9.1f %4.0f%% %9.1f %10.1f %8.0f %8ld | %8.3f %8.3f %5s\n", n,
                  m.mass_count(), tris, bpt, bvh * 1e9, cached * 1e9, cert * 100, single * 1e9, brute * 1e9, brute / bvh,
                  static_cast<long>(xs.cols()), st1 * 1e3, st2 * 1e3, same ? "yes" : "NO");
      csv_c.row(n, m.mass_count(), tris, bpt, bvh * 1e9, cached * 1e9, cert, brute * 1e9, xs.cols(), st1 * 1e3,
                st2 * 1e3, same ? 1 : 0, single * 1e9);
    }
  }

  return all_identical;
}

// Collision per speed: the N x N cloth (N = 256 or --max-n) sliding over the sphere.
void collision_speed_table(const Args& args) {
  const int max_level = args.max_level;
  const bool quick = args.quick;
  {
    const int n = std::min(args.max_n, 256);
    Csv csv_m(args.path("collision_speed.csv"),
              "n,masses,triangles,step_m_per_call,hints_ns_per_mass,cache1_ns_per_mass,cache1_certified,"
              "cache_ns_per_mass,cache_certified,candidates,cache_bytes_per_mass");
    std::printf("\ncollision per speed (%d x %d cloth sliding over the sphere; ns per mass; K = %zu candidates)\n", n, n,
                ContactCache::kDefaultCandidates);
    std::printf("%8s %9s | %9s | %9s %5s | %9s %5s\n", "tris", "per call", "bvh+hint", "K=1", "cert", "cache", "cert");
    for (int level = 3; level <= max_level; ++level) {
      const auto set = perf::sphere_collider(level);
      const Model m = perf::grid_model(n, set);
      const auto& o = m.options;
      const double masses = static_cast<double>(m.mass_count());
      ContactCache probe;
      probe.resize(1, 1);
      for (const double step : {1e-6, 2e-4, 1e-3}) {
        const int warm = quick ? 5 : 30;
        const double h = sliding_seconds(*set, m.x0, o.epsilon, o.k_rep, step, 0, warm, 3).first / masses;
        const auto [s1, c1] = sliding_seconds(*set, m.x0, o.epsilon, o.k_rep, step, 1, warm, 3);
        const auto [sk, ck] =
            sliding_seconds(*set, m.x0, o.epsilon, o.k_rep, step, ContactCache::kDefaultCandidates, warm, 3);
        std::printf("%8zu %7.1f um | %9.1f | %9.1f %4.0f%% | %9.1f %4.0f%%\n", set->triangle_count(), step * 1e6,
                    h * 1e9, s1 / masses * 1e9, c1 * 100, sk / masses * 1e9, ck * 100);
        csv_m.row(n, m.mass_count(), set->triangle_count(), step, h * 1e9, s1 / masses * 1e9, c1,
                  sk / masses * 1e9, ck, ContactCache::kDefaultCandidates,
                  static_cast<double>(probe.bytes_per_entry() * set->object_count()));
      }
    }
  }

}

// The baked skirts, after a second of simulation.
void baked_table(const Args& args) {
  const bool quick = args.quick;
  Csv csv_k(args.path("skirt.csv"),
            "scene,masses,springs,triangles,step1_us,step2_us,bvh_ns_per_mass,brute_ns_per_mass,realtime_factor");
  const double settle = quick ? 0.2 : 1.0;  // s: on the sphere (first contact at ~0.58 s)
  std::printf("\nbaked scenes (after %.1f s of simulation)   step us           | collision ns per mass       | real time\n",
              settle);
  std::printf("%-12s %7s %8s %7s | %9s %9s %6s | %9s %9s %7s | %7s\n", "scene", "masses", "springs", "tris",
              "1 thr", "2 thr", "x", "bvh+hint", "brute", "ratio", "factor");
  skirt_table("skirt", b2o::gen::skirt::scene, settle, csv_k);
  skirt_table("skirt_hires", b2o::gen::skirt_hires::scene, settle, csv_k);
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  if (const int code = parse_args(argc, argv, args); code >= 0) return code;
  if (const std::string why = check_csv_dir(args); !why.empty()) {
    std::cerr << "perf_sweep: error: " << why << "\n";
    return 2;
  }
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) < 0) load[0] = -1;
  std::printf("perf_sweep: %d repetitions (min), load average %.2f, threads 1 and 2\n\n", g_reps, load[0]);
  const bool springs_same = springs_table(args);  // (each table's CSV file is closed, and a failed write said,
  const bool collision_same = collision_table(args);  // at the end of its function)
  collision_speed_table(args);
  baked_table(args);
  if (!springs_same || !collision_same) {
    std::printf("\nperf_sweep: error: a 2-thread run differed from the 1-thread run\n");
    return 1;
  }
  return g_write_failed ? 1 : 0;
}
