// The self-contact stage's tests in lanes, plain and AVX2: the joins' leaf pairs answer as
// near() does for each pair of boxes; the lists' check clears the pairs and leaves the least
// room that a test of one pair at a time gives (touching, apart, overlapping, empty lanes and
// NaN alike); an edge pair or a mass and a triangle ruled out in lanes are never nearer than
// pair_gap() says. White-box: the stage's private headers.
#include "self_moves.hpp"

#include <Eigen/Core>

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
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

// Two leaves' random boxes (some NaN; every third round some equal or exactly r apart) and
// their counts, per round.
struct Leaves {
  std::array<Box, 4> a{}, b{};
  std::uint32_t ca = 0, cb = 0;
  SelfBvh::Lanes la{}, lb{};
};
template <class Each>
void random_leaves(double r, Each each) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-1.0, 1.0), size(0.0, 0.5);
  std::uniform_int_distribution<int> pick(0, 9);
  for (int round = 0; round < 20000; ++round) {
    Leaves l;
    for (auto* boxes : {&l.a, &l.b})
      for (Box& box : *boxes)
        for (int k = 0; k < 3; ++k) {
          box[k] = at(rng), box[k + 3] = box[k] + size(rng);
          if (pick(rng) == 0) box[k] = std::nan("");
        }
    if (round % 3 == 0) {  // (the same box; boxes r apart on either side)
      l.b[1] = l.a[0];
      l.b[2] = {l.a[1][3] + r, l.a[1][1], l.a[1][2], l.a[1][3] + 2 * r, l.a[1][4], l.a[1][5]};
      l.b[3] = {l.a[2][0] - 2 * r, l.a[2][1], l.a[2][2], l.a[2][0] - r, l.a[2][4], l.a[2][5]};
    }
    l.ca = 1 + static_cast<std::uint32_t>(round % 4), l.cb = 1 + static_cast<std::uint32_t>((round / 4) % 4);
    l.la = lanes_of(l.a, l.ca), l.lb = lanes_of(l.b, l.cb);
    each(round, l);
  }
}

TEST(SelfLanes, LeafLanesMeetAsNearDoes) {
  const double r = 0.1;
  int some = 0, none = 0;
  random_leaves(r, [&](int round, const Leaves& l) {
    const auto &a = l.a, &b = l.b;
    const auto ca = l.ca, cb = l.cb;
    const auto &la = l.la, &lb = l.lb;
    const std::uint32_t want = by_near(a, ca, b, cb, r);
    ASSERT_EQ(SelfBvh::leaf_meets(la, ca, lb, r), want) << "round " << round;
#ifdef CLOTHSIM_AVX2
    if (__builtin_cpu_supports("avx2")) {
      ASSERT_EQ(SelfBvh::leaf_meets_avx2(la, ca, lb, r), want) << "round " << round;
    }
#endif
    (want != 0 ? some : none)++;
  });
  EXPECT_GT(some, 1000);  // (both answers are common)
  EXPECT_GT(none, 1000);
}

// The check of one pair: cleared when the leaves' move is within the pair's room at xl (its
// boxes' distance less far, at least the skin), the least room of those cleared.
bool clears_one(const Box& p, const Box& q, const LeafCheck& c, double& least_room) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({0.0, p[k] - q[k + 3], q[k] - p[k + 3]});
    s += d * d;
  }
  const double room = std::max(c.skin, std::sqrt(s) - c.far);
  if (!(c.moved <= room)) return false;
  least_room = std::min(least_room, room);
  return true;
}

bool has_nan(const std::array<Box, 4>& boxes) {
  return std::any_of(boxes.begin(), boxes.end(), [](const Box& b) { return std::isnan(b[0] + b[1] + b[2] + b[3] + b[4] + b[5]); });
}

TEST(SelfLanes, LeafLanesClearAsOnePairAtATime) {
  int cleared = 0, left = 0;
  random_leaves(0.1, [&](int round, const Leaves& l) {
    const bool one = round % 5 == 0;
    const std::uint32_t cb = one ? l.ca : l.cb;
    const LeafCheck c{0.05 * (round % 7), 0.1, 0.2, cb, one};
    const SelfBvh::Lanes& lb = c.one ? l.la : l.lb;
    const std::array<Box, 4>& b = c.one ? l.a : l.b;
    double want_room = 1.0;
    std::uint32_t want = 0, pairs = 0;
    for (std::uint32_t i = 0; i < l.ca; ++i)
      for (std::uint32_t j = c.one ? i + 1 : 0; j < cb; ++j) {
        pairs |= std::uint32_t{1} << (4 * i + j);
        if (!clears_one(l.a[i], b[j], c, want_room)) want |= std::uint32_t{1} << (4 * i + j);
      }
    double room = 1.0;
    const std::uint32_t got = leaf_clears(l.la, l.ca, lb, c, room);
    ASSERT_EQ(got & ~pairs, 0u) << "round " << round;  // (only pairs, whatever the boxes)
    if (has_nan(l.a) || has_nan(b)) {  // (a NaN box: the plain and wide answers agree)
      want = got, want_room = room;
    } else {
      ASSERT_EQ(got, want) << "round " << round;
      ASSERT_EQ(room, want_room) << "round " << round;
    }
#ifdef CLOTHSIM_AVX2
    if (__builtin_cpu_supports("avx2")) {
      double wide_room = 1.0;
      ASSERT_EQ(leaf_clears_avx2(l.la, l.ca, lb, c, wide_room), want) << "round " << round;
      ASSERT_EQ(wide_room, want_room) << "round " << round;
    }
#endif
    cleared += std::popcount(~want & 0xffffu) > 0, left += want != 0;
  });
  EXPECT_GT(cleared, 1000);  // (both answers are common)
  EXPECT_GT(left, 1000);
}

#ifdef CLOTHSIM_AVX2
// What rule_out_rounds saw: the pairs in general position farther than 1.01 r, and how many of
// them the lanes ruled out.
struct RuledOut {
  int far = 0, ruled_out = 0;
};

// 50 000 rounds of four pairs, each placed by place(rng, its four points), which says whether
// it is in general position, and ruled out in lanes by apart(): none ruled out may be nearer
// than r by pair_gap().
template <class Place>
RuledOut rule_out_rounds(unsigned seed, bool vertex_triangle, decltype(&edges_apart_avx2) apart, double r, Place place) {
  std::mt19937 rng(seed);
  Eigen::Matrix3Xd x(3, 16);
  RuledOut seen;
  std::array<bool, 4> general{};
  for (int round = 0; round < 50000; ++round) {
    std::array<std::array<std::uint32_t, 4>, 4> pairs;
    for (std::uint32_t k = 0; k < 4; ++k) {
      pairs[k] = {4 * k, 4 * k + 1, 4 * k + 2, 4 * k + 3};
      std::array<Eigen::Vector3d, 4> p;
      general[k] = place(rng, p);
      for (std::uint32_t m = 0; m < 4; ++m) x.col(4 * k + m) = p[m];
    }
    const std::uint32_t ruled = apart(x.data(), pairs.data(), r);
    for (std::uint32_t k = 0; k < 4; ++k) {
      double coef[4];
      const double gap = pair_gap(x, pairs[k].data(), vertex_triangle, coef).norm();
      if ((ruled >> k & 1u) && !(gap >= r)) {
        ADD_FAILURE() << "round " << round << " pair " << k << " ruled out at " << gap;
        return seen;
      }
      if (general[k] && gap > 1.01 * r) ++seen.far, seen.ruled_out += ruled >> k & 1u;
    }
  }
  return seen;
}

// Random edge pairs around a distance of r, many of them parallel, crossing, sharing a line or
// of zero length: none ruled out is nearer than r by pair_gap(), and nearly every pair in
// general position that is farther than 1.01 r is ruled out.
TEST(SelfLanes, EdgePairsRuledOutInLanesAreFartherThanTheirReach) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2";
  std::uniform_real_distribution<double> at(-0.02, 0.02), unit(-1.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 5);
  const RuledOut seen = rule_out_rounds(11, false, edges_apart_avx2, 0.009, [&](std::mt19937& rng, auto& p) {
    const Eigen::Vector3d p0(at(rng), at(rng), at(rng)), d(unit(rng), unit(rng), unit(rng));
    Eigen::Vector3d p1 = p0 + 0.012 * d.normalized(), p2(at(rng), at(rng), at(rng)), p3(at(rng), at(rng), at(rng));
    const int shape = kind(rng);
    switch (shape) {
      case 0: p3 = p2 + (p1 - p0) * (0.5 + std::abs(unit(rng))); break;  // (parallel)
      case 1: p2 = p0 + 0.3 * (p1 - p0), p3 = p0 + 1.7 * (p1 - p0); break;  // (on one line)
      case 2: p1 = p0; break;  // (zero length)
      case 3: p3 = p2 + (p1 - p0) + Eigen::Vector3d(1e-9, 0, 0); break;  // (nearly parallel)
      default: break;
    }
    p = {p0, p1, p2, p3};
    return shape > 3;
  });
  EXPECT_GT(seen.far, 10000);
  EXPECT_GE(seen.ruled_out, seen.far * 99 / 100);
}

// Random masses around random triangles, within about 2 r of them, some triangles slivers or
// points, some masses in the triangle's plane: none ruled out is nearer than r by pair_gap(),
// and nine in ten in general position farther than 1.01 r are ruled out (the bound is the
// distance itself but beyond a corner, where a sharp corner weakens it; 95 % here).
TEST(SelfLanes, MassTrianglePairsRuledOutInLanesAreFartherThanTheirReach) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2";
  std::uniform_real_distribution<double> at(-0.01, 0.01);
  std::uniform_int_distribution<int> kind(0, 5);
  const RuledOut seen = rule_out_rounds(13, true, masses_apart_avx2, 0.009, [&](std::mt19937& rng, auto& p) {
    const Eigen::Vector3d a(at(rng), at(rng), at(rng));
    Eigen::Vector3d b = a + Eigen::Vector3d(at(rng), at(rng), at(rng)), c = a + Eigen::Vector3d(at(rng), at(rng), at(rng));
    Eigen::Vector3d v = a + 2.0 * Eigen::Vector3d(at(rng), at(rng), at(rng));
    const int shape = kind(rng);
    switch (shape) {
      case 0: c = a + 0.4 * (b - a) + Eigen::Vector3d(0, 1e-12, 0); break;  // (a sliver)
      case 1: b = a, c = a; break;  // (a point)
      case 2: c = b; break;  // (a segment)
      case 3: v = a + 0.7 * (b - a) + 0.9 * (c - a); break;  // (in the plane, beyond an edge)
      default: break;
    }
    p = {v, a, b, c};
    return shape > 2;
  });
  EXPECT_GT(seen.far, 10000);
  EXPECT_GE(seen.ruled_out, seen.far * 9 / 10);
}
#endif

}  // namespace
}  // namespace clothsim::detail
