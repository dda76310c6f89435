// XPBD's link updates four at a time in AVX2 give exactly the one-link-at-a-time results:
// pinned ends, a link of length 0, a count that is not a multiple of four. White-box: the
// core's private header.
#include "xpbd_links.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

namespace clothsim::detail {
namespace {

#ifdef CLOTHSIM_AVX2
// One colour of links over 2 n masses (no two share a mass), in a shuffled order, with
// positions, velocities and inverse masses (every fifth mass pinned), and link 3's ends at the
// same point.
struct Colour {
  std::vector<Link> links;
  std::vector<double> x, v, w;
};

Colour random_colour(std::size_t n) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.5, 2.0);
  std::vector<std::uint32_t> ends(2 * n);
  std::iota(ends.begin(), ends.end(), 0u);
  std::shuffle(ends.begin(), ends.end(), rng);
  Colour c;
  for (std::size_t k = 0; k < n; ++k) c.links.push_back(Link{ends[2 * k], ends[2 * k + 1], pos(rng), 1e3 * pos(rng)});
  for (std::size_t i = 0; i < 6 * n; ++i) c.x.push_back(u(rng)), c.v.push_back(u(rng));
  for (std::size_t i = 0; i < 2 * n; ++i) c.w.push_back(i % 5 == 0 ? 0.0 : 100.0 * pos(rng));
  std::copy_n(c.x.begin() + 3 * c.links[3].a, 3, c.x.begin() + 3 * c.links[3].b);
  return c;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

class XpbdLinks : public ::testing::TestWithParam<std::size_t> {
 protected:
  void SetUp() override {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU";
  }
};

TEST_P(XpbdLinks, ProjectFourAtATimeEqualsOneAtATime) {
  const Colour c = random_colour(GetParam());
  std::vector<double> one = c.x, four = c.x;
  for (int pass = 0; pass < 3; ++pass) {
    for (const Link& l : c.links) project(l, c.w.data(), 4e5, one.data());
    project_links_avx2(c.links.data(), c.links.size(), c.w.data(), 4e5, four.data());
  }
  EXPECT_FALSE(same_bits(one, c.x));  // the pass moved something
  EXPECT_TRUE(same_bits(one, four));
}

TEST_P(XpbdLinks, BendFourAtATimeEqualsOneAtATime) {
  const Colour c = random_colour(GetParam());
  std::vector<double> one = c.v, four = c.v;
  for (const Link& l : c.links) bend(l, c.w.data(), 1e-3, c.x.data(), one.data());
  bend_links_avx2(c.links.data(), c.links.size(), c.w.data(), 1e-3, c.x.data(), four.data());
  EXPECT_FALSE(same_bits(one, c.v));
  EXPECT_TRUE(same_bits(one, four));
}

INSTANTIATE_TEST_SUITE_P(Counts, XpbdLinks, ::testing::Values(std::size_t{4}, std::size_t{37}, std::size_t{1000}));
#endif

}  // namespace
}  // namespace clothsim::detail
