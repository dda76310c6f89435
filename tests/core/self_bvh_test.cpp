// The self-contact trees on threads: the bottom-up passes' shares hold every node once; a
// build and a refit on two threads give the tree one thread gives, every node's box the union
// of its children's or its primitives' boxes. White-box: the stage's private headers.
#include "self_bvh.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace clothsim::detail {
namespace {

// A jittered grid of n x n masses, two triangles per square, at coordinates 3 i .. 3 i + 2.
struct Sheet {
  std::vector<double> x;
  std::vector<std::uint32_t> triangles;
};
Sheet sheet(std::uint32_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  Sheet s;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; j < n; ++j) s.x.insert(s.x.end(), {i + jitter(rng), jitter(rng), j + jitter(rng)});
  for (std::uint32_t i = 0; i + 1 < n; ++i)
    for (std::uint32_t j = 0; j + 1 < n; ++j) {
      const std::uint32_t a = i * n + j, b = a + 1, c = a + n, d = c + 1;
      s.triangles.insert(s.triangles.end(), {a, b, d, a, d, c});
    }
  return s;
}

TEST(SelfBvh, PartsAndTopsHoldEveryNodeOnce) {
  for (const std::uint32_t n : {2u, 3u, 9u, 60u}) {
    const Sheet s = sheet(n, n);
    SelfBvh t;
    t.build(s.x.data(), s.triangles, 3);
    std::vector<int> seen(t.nodes.size(), 0);
    for (const auto& [begin, end] : t.parts)
      for (std::uint32_t i = begin; i < end; ++i) ++seen[i];
    for (const std::uint32_t i : t.tops) {
      ++seen[i];
      EXPECT_EQ(t.nodes[i].count, 0u) << "a top is an inner node";
    }
    for (std::size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], 1) << "node " << i << " of " << n << "^2 masses";
  }
}

TEST(SelfBvh, BuildAndRefitOnTwoThreadsGiveOneThreadsTreeWithEveryNodeTheUnionOfItsParts) {
  const Sheet s = sheet(120, 1);  // (28 322 triangles: kPartDepth levels of parts)
  SelfBvh one, two;
  one.build(s.x.data(), s.triangles, 3);
  two.build(s.x.data(), s.triangles, 3, 2);
  std::vector<double> moved = s.x;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> step(-2.0, 2.0);
  for (double& c : moved) c += step(rng);
  one.refit(moved.data(), 1);
  two.refit(moved.data(), 2);
  ASSERT_EQ(one.nodes.size(), two.nodes.size());
  ASSERT_EQ(one.order, two.order);
  for (std::size_t i = 0; i < one.nodes.size(); ++i) {
    const SelfBvh::Node &a = one.nodes[i], &b = two.nodes[i];
    ASSERT_EQ(a.next, b.next) << "node " << i;
    ASSERT_EQ(a.first, b.first) << "node " << i;
    ASSERT_EQ(a.count, b.count) << "node " << i;
    ASSERT_EQ(std::memcmp(a.lo.data(), b.lo.data(), sizeof a.lo), 0) << "node " << i;
    ASSERT_EQ(std::memcmp(a.hi.data(), b.hi.data(), sizeof a.hi), 0) << "node " << i;
    std::array<double, 3> lo, hi;
    lo.fill(std::numeric_limits<double>::infinity()), hi.fill(-std::numeric_limits<double>::infinity());
    const auto join = [&](const double* l, const double* h) {
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], l[k]), hi[k] = std::max(hi[k], h[k]);
    };
    if (b.count > 0) {
      for (std::uint32_t j = b.first; j < b.first + b.count; ++j)
        for (int c = 0; c < 3; ++c) {
          const double* p = &moved[3 * std::size_t{s.triangles[3 * std::size_t{two.order[j]} + c]}];
          join(p, p);
        }
    } else {
      join(two.nodes[i + 1].lo.data(), two.nodes[i + 1].hi.data());
      join(two.nodes[b.next].lo.data(), two.nodes[b.next].hi.data());
    }
    ASSERT_EQ(lo, b.lo) << "node " << i;
    ASSERT_EQ(hi, b.hi) << "node " << i;
  }
}

}  // namespace
}  // namespace clothsim::detail
