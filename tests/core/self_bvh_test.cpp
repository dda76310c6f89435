// The self-contact BVH's leaf pair tests: the lanes (plain and AVX2) answer as near() does for
// each pair of boxes, touching, apart, overlapping, empty lanes and NaN alike. White-box: the
// stage's private header.
#include "self_bvh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace clothsim::detail {
namespace {

using Box = std::array<double, 6>;

// Four boxes in lanes (the first `count`; the rest empty, as SelfBvh::fill_lanes leaves them).
SelfBvh::Lanes lanes_of(const std::array<Box, 4>& boxes, std::uint32_t count) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  SelfBvh::Lanes l{};
  for (std::uint32_t j = 0; j < 4; ++j)
    for (int a = 0; a < 3; ++a) l.lo[a][j] = j < count ? boxes[j][a] : inf, l.hi[a][j] = j < count ? boxes[j][a + 3] : -inf;
  return l;
}

// The bits near() gives: 4 i + j for a's i-th box grown by r meeting b's j-th.
std::uint32_t by_near(const std::array<Box, 4>& a, std::uint32_t ca, const std::array<Box, 4>& b, std::uint32_t cb,
                      double r) {
  std::uint32_t hits = 0;
  for (std::uint32_t i = 0; i < ca; ++i)
    for (std::uint32_t j = 0; j < cb; ++j) hits |= std::uint32_t{SelfBvh::near(a[i], b[j], r)} << (4 * i + j);
  return hits;
}

TEST(SelfBvh, LeafLanesMeetAsNearDoes) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-1.0, 1.0), size(0.0, 0.5);
  std::uniform_int_distribution<int> pick(0, 9);
  const double r = 0.1;
  int some = 0, none = 0;
  for (int round = 0; round < 20000; ++round) {
    std::array<Box, 4> a{}, b{};
    for (auto* boxes : {&a, &b})
      for (Box& box : *boxes)
        for (int k = 0; k < 3; ++k) {
          box[k] = at(rng), box[k + 3] = box[k] + size(rng);
          if (pick(rng) == 0) box[k] = std::nan("");  // (a NaN position meets nothing)
        }
    if (round % 3 == 0) {  // (the same box; boxes r apart on either side: they meet)
      b[1] = a[0];
      b[2] = {a[1][3] + r, a[1][1], a[1][2], a[1][3] + 2 * r, a[1][4], a[1][5]};
      b[3] = {a[2][0] - 2 * r, a[2][1], a[2][2], a[2][0] - r, a[2][4], a[2][5]};
    }
    const std::uint32_t ca = 1 + static_cast<std::uint32_t>(round % 4), cb = 1 + static_cast<std::uint32_t>((round / 4) % 4);
    const SelfBvh::Lanes la = lanes_of(a, ca), lb = lanes_of(b, cb);
    const std::uint32_t want = by_near(a, ca, b, cb, r);
    ASSERT_EQ(SelfBvh::leaf_meets(la, ca, lb, r), want) << "round " << round;
#ifdef CLOTHSIM_AVX2
    if (__builtin_cpu_supports("avx2")) {
      ASSERT_EQ(SelfBvh::leaf_meets_avx2(la, ca, lb, r), want) << "round " << round;
    }
#endif
    (want != 0 ? some : none)++;
  }
  EXPECT_GT(some, 1000);  // (both answers are common)
  EXPECT_GT(none, 1000);
}

}  // namespace
}  // namespace clothsim::detail
