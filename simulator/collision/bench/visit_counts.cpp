// Work per query, independent of the machine: triangle tests and box tests per point for
// points at distance d from an icosphere of T triangles (the library's sources built with
// CLOTHSIM_COLLISION_COUNTERS). A search that grows as log T adds a constant per 4x T.
#include <cstdio>
#include <string>
#include <random>
#include <vector>

#include "clothsim/collision.hpp"
#include "clothsim/collision_meshes.hpp"

namespace clothsim {
extern std::uint64_t g_tri_tests, g_box_tests;  // defined in bvh_query.cpp with the counters
}

int main(int argc, char** argv) {
  // no options: a table of the BVH's visits per query (docs/collision.md)
  if (argc > 1) {
    const bool help = std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help";
    std::fprintf(help ? stdout : stderr,
                 "usage: %s (no options): the BVH's triangle and box tests per query on icospheres of\n"
                 "levels 3-8, nearest and 16-nearest, as a markdown table\n",
                 argv[0]);
    return help ? 0 : 2;
  }
  std::printf("| triangles | d | triangle tests / query | box tests / query | 16-nearest: triangle tests | box tests |\n"
              "|---|---|---|---|---|---|\n");
  for (int level = 3; level <= 8; ++level) {
    const auto m = clothsim::meshes::icosphere(level, 1.0);
    clothsim::ColliderSet set;
    set.add_object("sphere", m.vertices, m.indices);
    set.build();
    std::mt19937_64 rng(1);
    std::normal_distribution<double> g(0.0, 1.0);
    for (double d : {-0.05, 0.099}) {
      const int n = 2000;
      Eigen::Matrix3Xd x(3, n), f = Eigen::Matrix3Xd::Zero(3, n);
      for (int i = 0; i < n; ++i)
        x.col(i) = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * (1.0 + d);
      std::vector<std::int32_t> hints(n, -1);
      clothsim::PenaltyStats stats;
      clothsim::accumulate_penalty(set, x, 0.1, 1000.0, f, stats, hints);  // fills the hints
      clothsim::g_tri_tests = clothsim::g_box_tests = 0;
      clothsim::accumulate_penalty(set, x, 0.1, 1000.0, f, stats, hints);
      const double tri1 = static_cast<double>(clothsim::g_tri_tests) / n;
      const double box1 = static_cast<double>(clothsim::g_box_tests) / n;
      // A ContactCache list renewal: the 16 nearest, seeded with the list made 1 mm away.
      std::uint64_t tri16 = 0, box16 = 0;
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d p = x.col(i), q = p + 1e-3 * p.unitOrthogonal();
        std::uint32_t seed[16], slots[16];
        double d2[16], lb = 0.0;
        const std::size_t k = set.query_nearest(0, p.data(), 0.04, clothsim::QueryMethod::Bvh, 16, {},
                                                seed, d2, lb);
        clothsim::g_tri_tests = clothsim::g_box_tests = 0;
        set.query_nearest(0, q.data(), 0.04, clothsim::QueryMethod::Bvh, 16,
                          std::span<const std::uint32_t>(seed, k), slots, d2, lb);
        tri16 += clothsim::g_tri_tests, box16 += clothsim::g_box_tests;
      }
      std::printf("| %zu | %+.3f | %.1f | %.1f | %.1f | %.1f |\n", set.triangle_count(), d, tri1, box1,
                  static_cast<double>(tri16) / n, static_cast<double>(box16) / n);
    }
  }
}
