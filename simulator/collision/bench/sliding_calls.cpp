// A fixed amount of contact sliding, for `perf stat -e instructions:u` (a count that does not
// depend on the host's speed, which varies by ~20 % between hours here): 4 096 points in a
// shell lo <= |x| <= hi about an icosphere of radius 1 (level L: 20 * 4^L triangles), turned
// about the x axis so that each moves `step` m per call on average, then `calls` calls of
// accumulate_penalty() with a ContactCache (K = 16, clearances prepared at load). The
// instructions of the calls are those of `calls` = N less those of `calls` = 0.
//   perf stat -e instructions:u build/bin/bench_collision_sliding 7 400
//   perf stat -e instructions:u build/bin/bench_collision_sliding 7 0
// It prints the share of the calls certified without a search and a checksum of the forces.
#include <cmath>
#include <cstdio>
#include <string>
#include <cstdlib>

#include <Eigen/Geometry>

#include "clothsim/collision.hpp"
#include "clothsim/collision_meshes.hpp"
#include "shell_points.hpp"

namespace {

using clothsim::bench::shell_points;

// A finite number, the whole argument.
bool number(const char* text, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(out);
}

// A whole number in [lo, hi], the whole argument.
bool whole(const char* text, double lo, double hi, double& out) {
  return number(text, out) && out == std::floor(out) && out >= lo && out <= hi;
}

}  // namespace

int main(int argc, char** argv) {
  double level = 0.0, calls = 0.0, step = 2e-4, lo = 1.0, hi = 1.1;
  if (argc == 2 && (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help")) {
    std::printf("usage: %s LEVEL CALLS [STEP_M=2e-4 [LO=1.0 [HI=1.1]]]\n"
                "  LEVEL 0-9 (20 * 4^LEVEL triangles), CALLS >= 0, LO <= HI\n"
                "4096 points sliding STEP_M per call at LO..HI from a unit icosphere, CALLS calls of\n"
                "accumulate_penalty() with a ContactCache; run under callgrind (docs/performance.md).\n",
                argv[0]);
    return 0;
  }
  if (argc < 3 || argc > 6 || !whole(argv[1], 0, 9, level) || !whole(argv[2], 0, 1e12, calls) ||
      (argc > 3 && !number(argv[3], step)) || (argc > 4 && !number(argv[4], lo)) ||
      (argc > 5 && !number(argv[5], hi)) || !(hi >= lo)) {
    std::fprintf(stderr, "usage: %s LEVEL CALLS [STEP_M=2e-4 [LO=1.0 [HI=1.1]]]\n"
                 "  LEVEL 0-9 (20 * 4^LEVEL triangles), CALLS 0..1e12, whole; finite numbers, LO <= HI\n", argv[0]);
    return 2;
  }
  const auto mesh = clothsim::meshes::icosphere(static_cast<int>(level), 1.0);
  clothsim::ColliderSet set;
  set.add_object("sphere", mesh.vertices, mesh.indices);
  set.build();
  set.prepare_clearances();
  const int n = 4096;
  Eigen::Matrix3Xd x = shell_points(n, lo, hi, 42);
  const double mean_rho = x.bottomRows(2).colwise().norm().mean();
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(step / mean_rho, Eigen::Vector3d::UnitX()).toRotationMatrix();
  clothsim::ContactCache cache;
  cache.resize(static_cast<std::size_t>(n), set.object_count(), 16);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, n);
  clothsim::PenaltyStats stats;
  std::size_t certified = 0, pairs = 0;
  // 20 calls of warm-up in both runs, so that N - 0 counts N calls in their steady mix.
  const long total = 20 + static_cast<long>(calls);
  for (long c = 0; c < total; ++c) {
    x = rot * x;
    clothsim::accumulate_penalty(set, x, 0.1, 1000.0, f, stats, cache);
    if (c >= 20) certified += stats.certified, pairs += static_cast<std::size_t>(n);
  }
  std::printf("%d triangles, %ld calls: %.4f certified, force checksum %.17g\n",
              static_cast<int>(set.triangle_count()), static_cast<long>(calls),
              pairs > 0 ? static_cast<double>(certified) / static_cast<double>(pairs) : 0.0, f.sum());
  return 0;
}
