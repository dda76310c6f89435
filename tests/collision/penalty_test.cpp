// Penalty response, report eq. 12 with the unit normal: magnitude, direction, sums over
// colliders, closest triangle per object, tunnelling, and the resting depth eps - m g / k_rep.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "clothsim/collision.hpp"
#include "clothsim/collision_meshes.hpp"

using clothsim::accumulate_penalty;
using clothsim::ColliderSet;
using clothsim::PenaltyStats;
using Eigen::Vector3d;

namespace {

constexpr double kEps = 0.1;
constexpr double kRep = 1000.0;

ColliderSet floor_set(double y = 0.0) {
  ColliderSet set;
  const auto m = clothsim::meshes::floor_grid(4, 2.0, y);
  set.add_object("floor", m.vertices, m.indices);
  set.build();
  return set;
}

// Force on one point.
Vector3d force_at(const ColliderSet& set, const Vector3d& p, PenaltyStats* stats = nullptr,
                  double k_rep = kRep) {
  Eigen::Matrix3Xd x(3, 1), f = Eigen::Matrix3Xd::Zero(3, 1);
  x.col(0) = p;
  PenaltyStats s;
  accumulate_penalty(set, x, kEps, k_rep, f, s);
  if (stats) *stats = s;
  return f.col(0);
}

}  // namespace

TEST(CollisionPenalty, MagnitudeAndDirectionInTheBand) {
  const ColliderSet set = floor_set();
  PenaltyStats s;
  // Above the floor inside the band: k (eps - d) along the unit normal +y.
  Vector3d f = force_at(set, Vector3d(0.3, 0.04, -0.7), &s);
  EXPECT_NEAR(f.y(), kRep * (kEps - 0.04), 1e-9);
  EXPECT_EQ(f.x(), 0.0);
  EXPECT_EQ(f.z(), 0.0);
  EXPECT_EQ(s.contacts, 1u);
  EXPECT_EQ(s.max_penetration, 0.0);
  // Behind the floor inside the band: pushed up harder, penetration reported as >= 0.
  f = force_at(set, Vector3d(0.3, -0.06, -0.7), &s);
  EXPECT_NEAR(f.y(), kRep * (kEps + 0.06), 1e-9);
  EXPECT_NEAR(s.max_penetration, 0.06, 1e-15);
  // Outside the band: nothing.
  f = force_at(set, Vector3d(0.3, 0.1000001, -0.7), &s);
  EXPECT_EQ(f, Vector3d::Zero());
  EXPECT_EQ(s.contacts, 0u);
}

TEST(CollisionPenalty, AddsToTheForceAndNeverOverwrites) {
  const ColliderSet set = floor_set();
  Eigen::Matrix3Xd x(3, 2), f(3, 2);
  x.col(0) = Vector3d(0, 0.05, 0);
  x.col(1) = Vector3d(0, 5.0, 0);
  f.col(0) = Vector3d(1, 2, 3);
  f.col(1) = Vector3d(4, 5, 6);
  PenaltyStats s;
  accumulate_penalty(set, x, kEps, kRep, f, s);
  EXPECT_NEAR(f(1, 0), 2 + kRep * 0.05, 1e-9);
  EXPECT_EQ(f(0, 0), 1.0);
  EXPECT_EQ(f.col(1), Vector3d(4, 5, 6));
}

TEST(CollisionPenalty, TunnelledPointsGetNoForceAndAreCounted) {
  const ColliderSet set = floor_set();
  PenaltyStats s;
  const Vector3d f = force_at(set, Vector3d(0.5, -0.15, 0.5), &s);
  EXPECT_EQ(f, Vector3d::Zero());
  EXPECT_EQ(s.tunnelled, 1u);
  EXPECT_EQ(s.contacts, 0u);
  EXPECT_NEAR(s.max_penetration, 0.15, 1e-15);
}

TEST(CollisionPenalty, PointBetweenFloorAndWallGetsBoth) {
  // The 2016 code zeroed contact forces per collider: the second erased the first.
  ColliderSet set;
  const auto floor = clothsim::meshes::floor_grid(2, 1.0, 0.0);
  set.add_object("floor", floor.vertices, floor.indices);
  // A wall in the plane x = 1 facing -x (towards the floor's centre).
  Eigen::Matrix3Xd w(3, 4);
  w << 1, 1, 1, 1,  //
      -1, -1, 2, 2,  //
      -1, 1, -1, 1;
  set.add_object("wall", w, std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2});
  set.build();
  PenaltyStats s;
  const Vector3d f = force_at(set, Vector3d(0.97, 0.02, 0.3), &s);
  EXPECT_EQ(s.contacts, 2u);
  EXPECT_NEAR(f.y(), kRep * (kEps - 0.02), 1e-9);
  EXPECT_NEAR(f.x(), -kRep * (kEps - 0.03), 1e-9);
  EXPECT_NEAR(f.z(), 0.0, 1e-12);
}

TEST(CollisionPenalty, ClosedMeshPushesOutwardFromInsideAndOutside) {
  ColliderSet set;
  const auto s = clothsim::meshes::icosphere(3, 1.0);
  set.add_object("sphere", s.vertices, s.indices);
  set.build();
  const Vector3d dir = Vector3d(0.3, 0.8, -0.2).normalized();
  for (double r : {0.96, 1.05}) {  // just inside and just outside
    const Vector3d f = force_at(set, r * dir);
    EXPECT_GT(f.dot(dir), 0.0) << "r " << r;
  }
}

// A box [-1, 1]^3, outward faces, the face x = -1 first (lowest triangle indices), then y = +1.
ColliderSet box_set() {
  Eigen::Matrix3Xd v(3, 8);
  for (int i = 0; i < 8; ++i) v.col(i) = Vector3d(i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0);
  const std::vector<std::uint32_t> idx = {0, 4, 6, 0, 6, 2,   // x = -1
                                          2, 6, 7, 2, 7, 3,   // y = +1
                                          1, 3, 7, 1, 7, 5,   // x = +1
                                          0, 1, 5, 0, 5, 4,   // y = -1
                                          0, 2, 3, 0, 3, 1,   // z = -1
                                          4, 5, 7, 4, 7, 6};  // z = +1
  ColliderSet set;
  set.add_object("box", v, std::span<const std::uint32_t>(idx));
  set.build();
  return set;
}

// A point on the box's top exactly (or up to rounding) in the plane of a side face ties between
// the two faces at their shared edge; the side face wins on its index. It is outside: never
// classed as behind, on every query path (a cloth grid aligned with a box's side has such points).
TEST(CollisionPenalty, PointInASideFacesPlaneAboveTheBoxIsNotBehind) {
  const ColliderSet set = box_set();
  for (double dx : {0.0, 1e-12, -1e-12, 1e-10})
    for (double h : {0.05, 0.093}) {
      const Vector3d p(-1.0 + dx, 1.0 + h, 0.3);
      Eigen::Matrix3Xd x(3, 1);
      x.col(0) = p;
      for (int path = 0; path < 3; ++path) {  // brute force, BVH + hints, ContactCache
        Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, 1);
        PenaltyStats st;
        std::vector<std::int32_t> hints(1, -1);
        clothsim::ContactCache cache;
        cache.resize(1, set.object_count());
        for (int call = 0; call < 2; ++call) {  // the second call: hints and certificates in use
          f.setZero();
          if (path == 0) accumulate_penalty(set, x, kEps, kRep, f, st, std::span<std::int32_t>{}, clothsim::QueryMethod::BruteForce);
          else if (path == 1) accumulate_penalty(set, x, kEps, kRep, f, st, hints);
          else accumulate_penalty(set, x, kEps, kRep, f, st, cache);
          EXPECT_EQ(st.max_penetration, 0.0) << "dx " << dx << " h " << h << " path " << path;
          EXPECT_EQ(st.tunnelled, 0u);
          EXPECT_NEAR(f.col(0).norm(), kRep * (kEps - h), 1e-9) << "dx " << dx << " h " << h << " path " << path;
        }
      }
    }
  // Truly behind the side face, inside the box near the edge: still behind.
  PenaltyStats st;
  force_at(set, Vector3d(-1.0 + 0.01, 1.0 - 0.02, 0.3), &st);
  EXPECT_NEAR(st.max_penetration, 0.01, 1e-12);
}

TEST(CollisionPenalty, ClosestTrianglePerObjectOnAnIcosphere) {
  // Summing every triangle within the band would multiply the force at a vertex (5-6 faces).
  ColliderSet set;
  const auto m = clothsim::meshes::icosphere(3, 1.0);
  set.add_object("sphere", m.vertices, m.indices);
  set.build();
  const double h = 0.03;  // distance outside the surface
  // Above vertex 0 (a vertex of the base icosahedron, 5 faces around it).
  const Vector3d v0 = m.vertices.col(0);
  const Vector3d fv = force_at(set, v0 * (1.0 + h));
  // Above the centre of face 0 at the same distance along its normal.
  const Vector3d a = m.vertices.col(m.indices[0]), b = m.vertices.col(m.indices[1]),
                 c = m.vertices.col(m.indices[2]);
  const Vector3d n = (b - a).cross(c - a).normalized();
  const Vector3d ff = force_at(set, (a + b + c) / 3.0 + h * n);
  EXPECT_NEAR(fv.norm(), kRep * (kEps - h), 1e-9);
  EXPECT_NEAR(ff.norm(), kRep * (kEps - h), 1e-9);
  EXPECT_NEAR(fv.norm() / ff.norm(), 1.0, 1e-9);
  // Direction: the face normal, within the small tilt of a level-3 icosphere's faces.
  EXPECT_GT(fv.normalized().dot(v0.normalized()), std::cos(0.1));
}

TEST(CollisionPenalty, RestingDepthIsEpsMinusWeightOverKrep) {
  // A single mass on a floor triangle under gravity with damping, integrated with a tiny
  // symplectic Euler loop (report eqs. 1-7): it settles at d = eps - m g / k_rep.
  ColliderSet set;
  Eigen::Matrix3Xd v(3, 3);
  v << -5, 0, 5,  //
      0, 0, 0,    //
      -5, 5, -5;
  set.add_object("floor", v, std::vector<std::uint32_t>{0, 1, 2});
  set.build();
  ASSERT_GT(set.closest(Vector3d(0, 1, 0), 2.0).normal.y(), 0.0);  // faces up
  const double m = 0.1, g = 9.81, k_rep = 50.0, gamma = 1.0, h = 0.001;
  Eigen::Matrix3Xd x(3, 1), vel = Eigen::Matrix3Xd::Zero(3, 1), f(3, 1);
  x.col(0) = Vector3d(0.0, 0.2, 0.0);  // enters the band at 1.4 m/s < eps sqrt(k/m)
  PenaltyStats s;
  double deepest = 0.0;
  for (int i = 0; i < 20000; ++i) {
    x += h * vel;
    f.col(0) = Vector3d(0, -m * g, 0);
    accumulate_penalty(set, x, kEps, k_rep, f, s);
    deepest = std::max(deepest, s.max_penetration);
    vel += h * (f - gamma * vel) / m;
  }
  const double expected = kEps - m * g / k_rep;  // 0.08038
  EXPECT_NEAR(x(1, 0), expected, 1e-9);
  EXPECT_NEAR(vel.norm(), 0.0, 1e-9);
  EXPECT_EQ(deepest, 0.0);  // dropped from 0.2 m: stopped inside the band, never behind
}

TEST(CollisionPenalty, NonFinitePointsAreCountedNotPassedOn) {
  const ColliderSet set = floor_set();
  Eigen::Matrix3Xd x(3, 2), f = Eigen::Matrix3Xd::Zero(3, 2);
  x.col(0) = Vector3d(NAN, 0.05, 0);
  x.col(1) = Vector3d(0, 0.05, 0);
  PenaltyStats s;
  accumulate_penalty(set, x, kEps, kRep, f, s);
  EXPECT_EQ(s.nonfinite_points, 1u);
  EXPECT_TRUE(f.allFinite());
  EXPECT_EQ(s.contacts, 1u);
}

TEST(CollisionPenalty, MisuseThrows) {
  ColliderSet unbuilt;
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 2), f = Eigen::Matrix3Xd::Zero(3, 2);
  PenaltyStats s;
  EXPECT_THROW(accumulate_penalty(unbuilt, x, kEps, kRep, f, s), std::logic_error);
  const ColliderSet set = floor_set();
  Eigen::Matrix3Xd f1 = Eigen::Matrix3Xd::Zero(3, 1);
  EXPECT_THROW(accumulate_penalty(set, x, kEps, kRep, f1, s), std::invalid_argument);
  std::vector<std::int32_t> hints(3, -1);  // needs 2 points * 1 object
  EXPECT_THROW(accumulate_penalty(set, x, kEps, kRep, f, s, hints), std::invalid_argument);
  EXPECT_THROW(accumulate_penalty(set, x, -0.1, kRep, f, s), std::invalid_argument);
  EXPECT_THROW(accumulate_penalty(set, x, kEps, NAN, f, s), std::invalid_argument);
  EXPECT_THROW(set.closest(Vector3d::Zero(), -1.0), std::invalid_argument);
}

TEST(CollisionPenalty, EmptySetGivesNoForce) {
  ColliderSet set;
  set.build();
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 3), f = Eigen::Matrix3Xd::Zero(3, 3);
  PenaltyStats s;
  accumulate_penalty(set, x, kEps, kRep, f, s);
  EXPECT_EQ(f, Eigen::Matrix3Xd::Zero(3, 3));
  EXPECT_EQ(s.contacts, 0u);
}

// Beyond an edge or a corner of a box (outside it) the push is along P - Q, Q the closest
// point, with k_rep (eps - |P - Q|): the gradient of the distance, so the same whichever face
// wins the tie. (The lower-index face's normal would make a cloth centred on a box drift off the
// side listed first, and off the other side with the faces in the other order.)
// The unit cube [0, 1]^3, faces outwards.
clothsim::meshes::Mesh unit_box() {
  clothsim::meshes::Mesh m;
  m.vertices.resize(3, 8);
  for (int i = 0; i < 8; ++i) m.vertices.col(i) = Vector3d((i & 1) ? 1 : 0, (i & 2) ? 1 : 0, (i & 4) ? 1 : 0);
  m.indices = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
               2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return m;
}

TEST(CollisionPenalty, EdgeAndCornerPushIsAlongTheClosestPointWhateverTheFaceOrder) {
  const auto box = unit_box();
  std::vector<std::uint32_t> reversed;  // the same triangles, listed last to first
  for (std::size_t t = box.indices.size(); t >= 3; t -= 3)
    reversed.insert(reversed.end(), box.indices.begin() + static_cast<std::ptrdiff_t>(t - 3),
                    box.indices.begin() + static_cast<std::ptrdiff_t>(t));
  const double a = 0.03;
  struct Case {
    Vector3d p, q;
  } cases[] = {{{1 + a, 1 + a, 0.5}, {1, 1, 0.5}},     // beyond the edge x = 1, y = 1
               {{0.5, 1 + a, -a}, {0.5, 1, 0}},        // beyond the edge y = 1, z = 0
               {{1 + a, 1 + a, 1 + a}, {1, 1, 1}}};    // beyond the corner (1, 1, 1)
  for (const auto& indices : {box.indices, reversed}) {
    ColliderSet set;
    set.add_object("box", box.vertices, indices);
    set.build();
    for (const Case& c : cases) {
      const Vector3d e = c.p - c.q;
      const Vector3d want = kRep * (kEps - e.norm()) * e.normalized();
      PenaltyStats s;
      EXPECT_LT((force_at(set, c.p, &s) - want).norm(), 1e-9 * want.norm()) << c.p.transpose();
      EXPECT_EQ(s.contacts, 1u);
      // the cached path (a search, then a certified call) gives the same bits
      Eigen::Matrix3Xd x(3, 1), f = Eigen::Matrix3Xd::Zero(3, 1);
      x.col(0) = c.p;
      clothsim::ContactCache cache;
      cache.resize(1, set.object_count());
      for (int call = 0; call < 3; ++call) {
        f.setZero();
        accumulate_penalty(set, x, kEps, kRep, f, s, cache);
        EXPECT_EQ(Vector3d(f.col(0)), force_at(set, c.p)) << "call " << call << " at " << c.p.transpose();
      }
    }
  }
}

// Beside the rim of an open plate, a point below its level is not behind it: it is pushed away
// from the rim (a push up by k_rep (eps + d) has no potential: a cloth draped over a plate
// smaller than itself would gain energy). Under the plate it is behind.
TEST(CollisionPenalty, BesideAnOpenRimThePushIsAwayFromTheRim) {
  const ColliderSet set = floor_set();  // the plate [-2, 2]^2 at y = 0, facing up
  const Vector3d beside(2.04, -0.03, 0.3), under(1.96, -0.03, 0.3);
  const Vector3d e(0.04, -0.03, 0.0);
  const Vector3d want = kRep * (kEps - e.norm()) * e.normalized();
  EXPECT_LT((force_at(set, beside) - want).norm(), 1e-9 * want.norm()) << force_at(set, beside).transpose();
  PenaltyStats s;
  const Vector3d f = force_at(set, under, &s);
  EXPECT_NEAR(f.y(), kRep * (kEps + 0.03), 1e-9);  // behind: up, k_rep (eps - d) with d = -0.03
  EXPECT_NEAR(s.max_penetration, 0.03, 1e-12);
  // in front of the rim, the force has a potential: no work around a loop that stays in front
  // of the plane and beside the rim (a square in the x-y plane, 400 steps a side)
  double work = 0.0;
  const Vector3d corners[4] = {{2.01, 0.01, 0.3}, {2.08, 0.01, 0.3}, {2.08, 0.06, 0.3}, {2.01, 0.06, 0.3}};
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 400; ++i) {
      const Vector3d a = corners[k] + (corners[(k + 1) % 4] - corners[k]) * (i / 400.0);
      const Vector3d b = corners[k] + (corners[(k + 1) % 4] - corners[k]) * ((i + 1) / 400.0);
      work += force_at(set, 0.5 * (a + b)).dot(b - a);
    }
  EXPECT_NEAR(work, 0.0, 1e-4);  // (the midpoint rule's error: ~1e-6; the face's push up would give ~-2 J)
}

// In a closed solid, a point sunk near a reflex edge (behind both faces, its closest point on
// the edge) is still behind: pushed out along a face's normal, not along P - Q, which points
// deeper in. (The L-shaped prism: (0,0), (2,0), (2,1), (1,1), (1,2), (0,2) in x-y, z in [0, 1];
// the reflex edge at x = y = 1.)
TEST(CollisionPenalty, InsideASolidNearAReflexEdgeThePushIsStillOutwards) {
  const double xy[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  Eigen::Matrix3Xd v(3, 12);
  for (int k = 0; k < 6; ++k) {
    v.col(k) = Vector3d(xy[k][0], xy[k][1], 0.0);
    v.col(k + 6) = Vector3d(xy[k][0], xy[k][1], 1.0);
  }
  std::vector<std::uint32_t> idx;
  for (std::uint32_t k = 1; k + 1 < 6; ++k) {  // the caps: fans from (0, 0), which sees every corner
    idx.insert(idx.end(), {0u, k + 1, k});        // z = 0, facing -z
    idx.insert(idx.end(), {6u, k + 6, k + 7});    // z = 1, facing +z
  }
  for (std::uint32_t k = 0; k < 6; ++k) {  // the sides, facing out (the outline runs counter-clockwise)
    const std::uint32_t a = k, b = (k + 1) % 6;
    idx.insert(idx.end(), {a, b, b + 6, a, b + 6, a + 6});
  }
  ColliderSet set;
  set.add_object("L", v, idx);
  set.build();
  const Vector3d p(0.97, 0.97, 0.5);
  const Vector3d f = force_at(set, p);
  EXPECT_GT(f.dot(Vector3d(1, 1, 0)), 0.0) << f.transpose();  // out of the notch side, not in
  EXPECT_GE(f.norm(), kRep * kEps) << f.transpose();          // behind: k_rep (eps - d), d < 0
  // outside, beyond the solid's convex edge at (2, 1): along P - Q
  const Vector3d q(2.03, 1.04, 0.5), e(0.03, 0.04, 0.0);
  EXPECT_LT((force_at(set, q) - kRep * (kEps - e.norm()) * e.normalized()).norm(), 1e-9 * kRep) << force_at(set, q).transpose();
}

namespace {

// A closed prism along z in [0, 1] whose cross-section is the triangle (-w/2, 0), (w/2, 0),
// (0, h) with a sharp ridge at the top; each side cut into `s` x `layers` quads (shared
// vertices: watertight), the caps fans from the centroid. Faces outwards.
clothsim::meshes::Mesh knife_prism(double w, double h, int s, int layers) {
  const Vector3d corner[3] = {{-w / 2, 0, 0}, {w / 2, 0, 0}, {0, h, 0}};  // counter-clockwise seen from +z
  std::vector<Vector3d> ring;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < s; ++i) ring.push_back(corner[k] + (corner[(k + 1) % 3] - corner[k]) * (double(i) / s));
  const auto n = static_cast<std::uint32_t>(ring.size());
  clothsim::meshes::Mesh m;
  m.vertices.resize(3, static_cast<Eigen::Index>(n * (layers + 1) + 2));
  for (int l = 0; l <= layers; ++l)
    for (std::uint32_t i = 0; i < n; ++i)
      m.vertices.col(static_cast<Eigen::Index>(l * n + i)) = ring[i] + Vector3d(0, 0, double(l) / layers);
  const std::uint32_t c0 = n * (layers + 1), c1 = c0 + 1;
  m.vertices.col(c0) = Vector3d(0, h / 3, 0);
  m.vertices.col(c1) = Vector3d(0, h / 3, 1);
  for (std::uint32_t l = 0; l < static_cast<std::uint32_t>(layers); ++l)
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t a = l * n + i, b = l * n + (i + 1) % n;
      m.indices.insert(m.indices.end(), {a, b, b + n, a, b + n, a + n});
    }
  const std::uint32_t top = static_cast<std::uint32_t>(layers) * n;
  for (std::uint32_t i = 0; i < n; ++i) {
    m.indices.insert(m.indices.end(), {c0, (i + 1) % n, i});              // z = 0, facing -z
    m.indices.insert(m.indices.end(), {c1, top + i, top + (i + 1) % n});  // z = 1, facing +z
  }
  return m;
}

}  // namespace

// Beside a sharp ridge (30 degrees) a point outside the solid can be behind the plane of one
// of the two faces there; if that face wins the tie the point is "behind" by |P - Q|, counted as
// a penetration and pushed by k_rep (eps + |P - Q|) along that face's normal: a force with no
// potential (a cloth dropped on a knife-edge prism gains 10x its energy). The angle-weighted
// pseudonormal at the edge tells it is outside: pushed along P - Q, k_rep (eps - |P - Q|), in
// both face orders, on the plain, cached and copied (> 4096 triangles) paths alike. Inside
// under the ridge it is still behind.
TEST(CollisionPenalty, BesideASharpRidgeThePointIsOutside) {
  const double w = 0.2, h = 0.1 / std::tan(15.0 * M_PI / 180.0);
  for (const auto& [s, layers] : {std::pair{1, 1}, std::pair{20, 60}}) {
    const auto prism = knife_prism(w, h, s, layers);
    std::vector<std::uint32_t> reversed;
    for (std::size_t t = prism.indices.size(); t >= 3; t -= 3)
      reversed.insert(reversed.end(), prism.indices.begin() + static_cast<std::ptrdiff_t>(t - 3),
                      prism.indices.begin() + static_cast<std::ptrdiff_t>(t));
    for (const auto& indices : {prism.indices, reversed}) {
      ColliderSet set;
      set.add_object("prism", prism.vertices, indices);
      set.build();
      for (const double side : {1.0, -1.0}) {
        const Vector3d p(0.02 * side, h + 0.03, 0.5 + 0.5 / 120), q(0.0, h, p.z());
        const Vector3d e = p - q, want = kRep * (kEps - e.norm()) * e.normalized();
        PenaltyStats st;
        const Vector3d f = force_at(set, p, &st);
        EXPECT_LT((f - want).norm(), 1e-9 * want.norm()) << "s " << s << " side " << side << ": " << f.transpose();
        EXPECT_EQ(st.max_penetration, 0.0);
        // the start-up checks' distance (count_launched()) agrees with the force
        EXPECT_NEAR(set.contact_distance(p, set.closest(p, 1.0)), e.norm(), 1e-12) << "s " << s << " side " << side;
        Eigen::Matrix3Xd x(3, 1), fc = Eigen::Matrix3Xd::Zero(3, 1);
        x.col(0) = p;
        clothsim::ContactCache cache;
        cache.resize(1, set.object_count());
        for (int call = 0; call < 3; ++call) {
          fc.setZero();
          accumulate_penalty(set, x, kEps, kRep, fc, st, cache);
          EXPECT_EQ(Vector3d(fc.col(0)), f) << "s " << s << " call " << call;
        }
      }
      // inside, just under the ridge: behind, pushed out
      PenaltyStats st;
      const Vector3d f = force_at(set, Vector3d(0.0, h - 0.02, 0.5), &st);
      EXPECT_GT(st.max_penetration, 0.0);
      EXPECT_GT(f.y(), 0.0) << f.transpose();
      const Vector3d under(0.0, h - 0.02, 0.5);
      EXPECT_LT(set.contact_distance(under, set.closest(under, 1.0)), 0.0);
    }
  }
}

// The same at the tip of a sharp pyramid (a corner: the pseudonormal weights each face by its
// angle there): a point above the tip, off to a side, behind one face's plane, is outside.
TEST(CollisionPenalty, BesideASharpTipThePointIsOutside) {
  Eigen::Matrix3Xd v(3, 5);
  v << -0.1, 0.1, 0.1, -0.1, 0.0,  //
      0.0, 0.0, 0.0, 0.0, 1.0,     //
      -0.1, -0.1, 0.1, 0.1, 0.0;
  const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 2, 3,                          // base, facing -y
                                          0, 4, 1, 1, 4, 2, 2, 4, 3, 3, 4, 0};       // sides, outwards
  ColliderSet set;
  set.add_object("pyramid", v, idx);
  set.build();
  for (const Vector3d& off : {Vector3d(0.03, 0.02, 0.0), Vector3d(0.0, 0.02, -0.03), Vector3d(-0.02, 0.02, 0.02)}) {
    const Vector3d p = Vector3d(0, 1, 0) + off;
    const Vector3d want = kRep * (kEps - off.norm()) * off.normalized();
    PenaltyStats st;
    const Vector3d f = force_at(set, p, &st);
    EXPECT_LT((f - want).norm(), 1e-9 * want.norm()) << off.transpose() << ": " << f.transpose();
    EXPECT_EQ(st.max_penetration, 0.0) << off.transpose();
  }
}
