// The BVH finds exactly what brute force finds: same closest triangle (ties: lowest index),
// same distances and bit-identical penalty forces, with and without hints.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "clothsim/collision.hpp"
#include "clothsim/collision_meshes.hpp"

using clothsim::ColliderHit;
using clothsim::ColliderSet;
using clothsim::PenaltyStats;
using clothsim::QueryMethod;
using Eigen::Vector3d;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A random scene: an icosphere, a noisy floor, a soup of random triangles (some degenerate,
// some duplicated) of varied sizes.
ColliderSet random_scene(std::mt19937_64& rng, const Vector3d& offset = Vector3d::Zero()) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ColliderSet set;
  const auto s = clothsim::meshes::icosphere(2, 0.5 + 0.5 * (u(rng) + 1.0),
                                             offset + Vector3d(u(rng), u(rng), u(rng)));
  set.add_object("sphere", s.vertices, s.indices);

  auto fl = clothsim::meshes::floor_grid(12, 2.0, -1.0);
  for (Eigen::Index i = 0; i < fl.vertices.cols(); ++i) fl.vertices(1, i) += 0.05 * u(rng);
  fl.vertices.colwise() += offset;
  set.add_object("floor", fl.vertices, fl.indices);

  const int nt = 300;
  Eigen::Matrix3Xd v(3, 3 * nt);
  std::vector<std::uint32_t> idx;
  for (int t = 0; t < nt; ++t) {
    const Vector3d c = offset + Vector3d(1.5 * u(rng), 1.5 * u(rng), 1.5 * u(rng));
    const double size = 0.02 + 0.3 * (u(rng) + 1.0);
    for (int k = 0; k < 3; ++k) v.col(3 * t + k) = c + size * Vector3d(u(rng), u(rng), u(rng));
    if (t % 50 == 7) v.col(3 * t + 2) = v.col(3 * t);  // degenerate
    idx.insert(idx.end(), {static_cast<std::uint32_t>(3 * t), static_cast<std::uint32_t>(3 * t + 1),
                           static_cast<std::uint32_t>(3 * t + 2)});
  }
  for (int t = 0; t < nt; t += 25)  // exact duplicates: ties resolved by lowest index
    idx.insert(idx.end(), {static_cast<std::uint32_t>(3 * t), static_cast<std::uint32_t>(3 * t + 1),
                           static_cast<std::uint32_t>(3 * t + 2)});
  set.add_object("soup", v, idx);
  set.build();
  return set;
}

Eigen::Matrix3Xd random_points(std::mt19937_64& rng, int n,
                               const Vector3d& offset = Vector3d::Zero()) {
  std::uniform_real_distribution<double> u(-2.2, 2.2);
  Eigen::Matrix3Xd x(3, n);
  for (int i = 0; i < n; ++i) x.col(i) = offset + Vector3d(u(rng), u(rng) * 0.7, u(rng));
  return x;
}

}  // namespace

TEST(CollisionBvh, SameClosestTriangleAsBruteForceOnRandomScenes) {
  std::mt19937_64 rng(12345);
  std::size_t compared = 0, hits = 0;
  for (int scene = 0; scene < 4; ++scene) {
    // Two scenes far from the origin: float boxes and rounding margins at larger magnitudes.
    const Vector3d offset = scene < 2 ? Vector3d::Zero() : Vector3d(1000.0, -500.0, 20000.0 * scene);
    const ColliderSet set = random_scene(rng, offset);
    EXPECT_GT(set.degenerate_count(2), 0u);
    const Eigen::Matrix3Xd x = random_points(rng, 2000, offset);
    std::vector<ColliderHit> a(set.object_count()), b(set.object_count());
    for (double radius : {0.05, 0.2, 1.0}) {
      for (Eigen::Index i = 0; i < x.cols(); ++i) {
        set.query(x.col(i), radius, a, QueryMethod::Bvh);
        set.query(x.col(i), radius, b, QueryMethod::BruteForce);
        for (std::size_t o = 0; o < a.size(); ++o) {
          ASSERT_EQ(a[o].object, b[o].object) << "point " << i << " object " << o;
          ASSERT_EQ(a[o].triangle, b[o].triangle) << "point " << i << " object " << o;
          ASSERT_TRUE(same_bits(a[o].distance_sq, b[o].distance_sq));
          ASSERT_TRUE(same_bits(a[o].signed_distance, b[o].signed_distance));
          ++compared;
          if (a[o].valid()) ++hits;
        }
      }
    }
  }
  EXPECT_GT(hits, compared / 10);  // the scenes are dense enough to test something
}

TEST(CollisionBvh, PenaltyForcesBitIdenticalWithAndWithoutHints) {
  std::mt19937_64 rng(777);
  std::size_t contacts = 0;
  for (int scene = 0; scene < 3; ++scene) {
    const ColliderSet set = random_scene(rng);
    Eigen::Matrix3Xd x = random_points(rng, 3000);
    std::vector<std::int32_t> hints(static_cast<std::size_t>(x.cols()) * set.object_count(), -1);
    std::uniform_int_distribution<std::int32_t> junk(-3, 400);
    std::normal_distribution<double> jitter(0.0, 0.02);
    for (int round = 0; round < 4; ++round) {
      if (round == 3)
        for (auto& h : hints) h = junk(rng);  // stale or nonsense hints change nothing
      Eigen::Matrix3Xd fb = Eigen::Matrix3Xd::Zero(3, x.cols()), fh = fb, fn = fb;
      PenaltyStats sb, sh, sn;
      accumulate_penalty(set, x, 0.1, 1000.0, fb, sb, {}, QueryMethod::BruteForce);
      accumulate_penalty(set, x, 0.1, 1000.0, fh, sh, hints, QueryMethod::Bvh);
      accumulate_penalty(set, x, 0.1, 1000.0, fn, sn, {}, QueryMethod::Bvh);
      ASSERT_EQ(std::memcmp(fb.data(), fh.data(), sizeof(double) * 3 * static_cast<std::size_t>(x.cols())), 0);
      ASSERT_EQ(std::memcmp(fb.data(), fn.data(), sizeof(double) * 3 * static_cast<std::size_t>(x.cols())), 0);
      EXPECT_EQ(sb.contacts, sh.contacts);
      EXPECT_EQ(sb.tunnelled, sh.tunnelled);
      EXPECT_TRUE(same_bits(sb.max_penetration, sh.max_penetration));
      EXPECT_EQ(sb.contacts, sn.contacts);
      contacts += sb.contacts;
      // Move the points a little, as a step would, so the hints are close but not exact.
      for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] += jitter(rng);
    }
  }
  EXPECT_GT(contacts, 1000u);
}

TEST(CollisionBvh, TiesGoToTheLowestTriangleIndex) {
  // 40 copies of the same triangle, plus others: every method must answer index 0.
  Eigen::Matrix3Xd v(3, 3);
  v << 0, 1, 0,  //
      0, 0, 1,   //
      0, 0, 0;
  std::vector<std::uint32_t> idx;
  for (int i = 0; i < 40; ++i) idx.insert(idx.end(), {0, 1, 2});
  ColliderSet set;
  set.add_object("copies", v, idx);
  set.build();
  std::vector<ColliderHit> out(1);
  for (auto m : {QueryMethod::Bvh, QueryMethod::BruteForce}) {
    std::vector<std::int32_t> hint = {31};  // a hint on a tie must not win over index 0
    set.query(Vector3d(0.2, 0.2, 0.05), 0.1, out, m, hint);
    EXPECT_EQ(out[0].triangle, 0);
    EXPECT_EQ(hint[0], 0);
  }
}

TEST(CollisionBvh, LargeSphereAgreesAndIsShallow) {
  const auto m = clothsim::meshes::icosphere(5, 1.0);  // 20480 triangles
  ColliderSet set;
  set.add_object("sphere", m.vertices, m.indices);
  set.build();
  EXPECT_EQ(set.triangle_count(), 20480u);
  EXPECT_LT(set.bvh_node_count(), 20480u);  // leaves of up to 4 triangles
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> r(0.9, 1.1);
  std::vector<ColliderHit> a(1), b(1);
  for (int i = 0; i < 500; ++i) {
    const Vector3d p = Vector3d(g(rng), g(rng), g(rng)).normalized() * r(rng);
    set.query(p, 0.1, a, QueryMethod::Bvh);
    set.query(p, 0.1, b, QueryMethod::BruteForce);
    ASSERT_EQ(a[0].triangle, b[0].triangle);
    ASSERT_TRUE(same_bits(a[0].distance_sq, b[0].distance_sq));
  }
}

TEST(CollisionBvh, ContactCacheGivesTheSearchResultBitForBit) {
  // Points that move a little (certificates hold) and a lot (they fail): always the same
  // forces and stats as brute force; the certificate must be used when points barely move.
  std::mt19937_64 rng(99);
  std::size_t certified = 0, contacts = 0;
  for (int scene = 0; scene < 2; ++scene) {
    const ColliderSet set = random_scene(rng);
    Eigen::Matrix3Xd x = random_points(rng, 1500);
    clothsim::ContactCache cache;
    cache.resize(static_cast<std::size_t>(x.cols()), set.object_count());
    for (int round = 0; round < 8; ++round) {
      Eigen::Matrix3Xd fb = Eigen::Matrix3Xd::Zero(3, x.cols()), fc = fb;
      PenaltyStats sb, sc;
      accumulate_penalty(set, x, 0.1, 1000.0, fb, sb, {}, QueryMethod::BruteForce);
      accumulate_penalty(set, x, 0.1, 1000.0, fc, sc, cache);
      ASSERT_EQ(std::memcmp(fb.data(), fc.data(),
                            sizeof(double) * 3 * static_cast<std::size_t>(x.cols())), 0)
          << "round " << round;
      EXPECT_EQ(sb.contacts, sc.contacts);
      EXPECT_EQ(sb.tunnelled, sc.tunnelled);
      EXPECT_TRUE(same_bits(sb.max_penetration, sc.max_penetration));
      if (round > 0 && round < 4) certified += sc.certified;
      contacts += sb.contacts;
      std::normal_distribution<double> jitter(0.0, round < 4 ? 1e-5 : 0.03);
      for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] += jitter(rng);
    }
  }
  EXPECT_GT(contacts, 500u);
  EXPECT_GT(certified, contacts / 8);
  clothsim::ContactCache wrong;
  wrong.resize(2, 1);
  const ColliderSet set = random_scene(rng);
  Eigen::Matrix3Xd x = random_points(rng, 5), f = Eigen::Matrix3Xd::Zero(3, 5);
  PenaltyStats s;
  EXPECT_THROW(accumulate_penalty(set, x, 0.1, 1000.0, f, s, wrong), std::invalid_argument);
}
