// The benchmarks' points: n of them in the shell lo <= |x| <= hi, random directions, in the
// order of a Morton curve (as the masses of a cloth are: neighbours in memory are neighbours
// in space) or, with coherent = false, in random order.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace clothsim::bench {

inline Eigen::Matrix3Xd shell_points(int n, double lo, double hi, std::uint64_t seed, bool coherent = true) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> r(lo, hi);
  std::vector<std::pair<std::uint64_t, Eigen::Vector3d>> pts(static_cast<std::size_t>(n));
  for (auto& [key, p] : pts) {
    p = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * r(rng);
    key = 0;
    for (int bit = 0; bit < 21 && coherent; ++bit)
      for (int k = 0; k < 3; ++k) {
        const auto q = static_cast<std::uint64_t>((p[k] + 4.0) / 8.0 * (1 << 21));
        key |= ((q >> bit) & 1u) << (3 * bit + k);
      }
  }
  std::stable_sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  Eigen::Matrix3Xd x(3, n);
  for (int i = 0; i < n; ++i) x.col(i) = pts[static_cast<std::size_t>(i)].second;
  return x;
}

}  // namespace clothsim::bench
