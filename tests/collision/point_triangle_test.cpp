// Point-triangle query: report eqs. 8-11 with a unit normal, a true distance and the closest
// point (so edges and vertices count).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "clothsim/collision.hpp"

using clothsim::point_triangle;
using clothsim::TriangleRegion;
using Eigen::Vector3d;

namespace {
// Right triangle in the z = 0 plane, CCW seen from +z: normal +z.
const Vector3d A(0, 0, 0), B(1, 0, 0), C(0, 1, 0);
}  // namespace

TEST(CollisionPointTriangle, InsideAboveIsFaceWithPositiveDistance) {
  const auto r = point_triangle(Vector3d(0.25, 0.25, 0.3), A, B, C);
  EXPECT_EQ(r.region, TriangleRegion::Face);
  EXPECT_DOUBLE_EQ(r.signed_distance, 0.3);
  EXPECT_DOUBLE_EQ(r.distance_sq, 0.09);
  EXPECT_TRUE(r.closest.isApprox(Vector3d(0.25, 0.25, 0.0)));
  EXPECT_TRUE(r.normal.isApprox(Vector3d(0, 0, 1)));
  EXPECT_FALSE(r.degenerate);
}

TEST(CollisionPointTriangle, InsideBelowIsNegative) {
  const auto r = point_triangle(Vector3d(0.2, 0.1, -0.05), A, B, C);
  EXPECT_EQ(r.region, TriangleRegion::Face);
  EXPECT_DOUBLE_EQ(r.signed_distance, -0.05);
}

TEST(CollisionPointTriangle, WindingDecidesTheFrontSide) {
  // The same triangle wound clockwise faces -z: the point above is now behind.
  const auto r = point_triangle(Vector3d(0.25, 0.25, 0.3), A, C, B);
  EXPECT_DOUBLE_EQ(r.signed_distance, -0.3);
  EXPECT_TRUE(r.normal.isApprox(Vector3d(0, 0, -1)));
}

TEST(CollisionPointTriangle, OutsideNearAnEdgeUsesTheTrueDistanceToTheEdge) {
  // Beside edge AB (y < 0), above the plane: distance to the edge, not to the plane.
  const auto r = point_triangle(Vector3d(0.5, -0.3, 0.4), A, B, C);
  EXPECT_EQ(r.region, TriangleRegion::EdgeAB);
  EXPECT_NEAR(r.signed_distance, 0.5, 1e-15);  // sqrt(0.3^2 + 0.4^2)
  EXPECT_TRUE(r.closest.isApprox(Vector3d(0.5, 0, 0)));
  // Beside the hypotenuse BC, below the plane.
  const auto h = point_triangle(Vector3d(0.6, 0.6, -0.1), A, B, C);
  EXPECT_EQ(h.region, TriangleRegion::EdgeBC);
  const double in_plane = (0.6 + 0.6 - 1.0) / std::sqrt(2.0);
  EXPECT_NEAR(h.signed_distance, -std::sqrt(in_plane * in_plane + 0.01), 1e-15);
  EXPECT_TRUE(h.closest.isApprox(Vector3d(0.5, 0.5, 0)));
  // Beside edge CA (x < 0).
  const auto c = point_triangle(Vector3d(-0.2, 0.5, 0.0), A, B, C);
  EXPECT_EQ(c.region, TriangleRegion::EdgeCA);
  EXPECT_NEAR(c.signed_distance, 0.2, 1e-15);
}

TEST(CollisionPointTriangle, NearAVertexUsesTheVertex) {
  const auto r = point_triangle(Vector3d(1.3, -0.4, 0.0), A, B, C);
  EXPECT_EQ(r.region, TriangleRegion::VertexB);
  EXPECT_NEAR(r.signed_distance, 0.5, 1e-15);
  EXPECT_TRUE(r.closest.isApprox(B));
  const auto a = point_triangle(Vector3d(-0.3, -0.4, -1.2), A, B, C);
  EXPECT_EQ(a.region, TriangleRegion::VertexA);
  EXPECT_NEAR(a.signed_distance, -1.3, 1e-15);
  const auto c = point_triangle(Vector3d(-0.1, 1.2, 0.0), A, B, C);
  EXPECT_EQ(c.region, TriangleRegion::VertexC);
}

TEST(CollisionPointTriangle, ExactlyOnThePlaneIsZeroAndFront) {
  const auto r = point_triangle(Vector3d(0.25, 0.5, 0.0), A, B, C);
  EXPECT_EQ(r.region, TriangleRegion::Face);
  EXPECT_EQ(r.signed_distance, 0.0);
  EXPECT_FALSE(std::signbit(r.signed_distance));
}

TEST(CollisionPointTriangle, DegenerateTrianglesAreFlagged) {
  EXPECT_TRUE(point_triangle(Vector3d(0, 0, 1), A, A, C).degenerate);          // repeated vertex
  EXPECT_TRUE(point_triangle(Vector3d(0, 0, 1), A, B, Vector3d(2, 0, 0)).degenerate);  // collinear
  EXPECT_TRUE(clothsim::triangle_is_degenerate(A, B, Vector3d(3, 1e-14, 0)));  // sliver
  EXPECT_FALSE(clothsim::triangle_is_degenerate(A, B, Vector3d(3, 1e-3, 0)));
  EXPECT_TRUE(clothsim::triangle_is_degenerate(A, B, Vector3d(NAN, 0, 0)));
}

TEST(CollisionPointTriangle, DistanceDoesNotScaleWithArea) {
  // With the unnormalized normal (the 2016 code's) d grows with 2*area; a true distance does not.
  for (double s : {0.01, 1.0, 37.0}) {
    const auto r = point_triangle(Vector3d(0.2 * s, 0.2 * s, 0.07), A * s, B * s, C * s);
    EXPECT_NEAR(r.signed_distance, 0.07, 1e-12) << "scale " << s;
    EXPECT_NEAR(r.normal.norm(), 1.0, 1e-15);
  }
}

TEST(CollisionPointTriangle, ColliderSetSkipsAndCountsDegenerateTriangles) {
  Eigen::Matrix3Xd v(3, 5);
  v << 0, 1, 0, 2, 0,  //
      0, 0, 1, 0, 0,   //
      0, 0, 0, 0, 0;
  // Triangle 0 is good, 1 collinear (0,1,3), 2 has a repeated vertex (0,0,2 -> 0,4 same point).
  const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 1, 3, 0, 4, 2};
  clothsim::ColliderSet set;
  set.add_object("plate", v, idx);
  set.build();
  EXPECT_EQ(set.input_triangle_count(0), 3u);
  EXPECT_EQ(set.triangle_count(0), 1u);
  EXPECT_EQ(set.degenerate_count(0), 2u);
  const auto hit = set.closest(Vector3d(0.2, 0.2, 0.05), 1.0);
  ASSERT_TRUE(hit.valid());
  EXPECT_EQ(hit.triangle, 0);
  EXPECT_DOUBLE_EQ(hit.signed_distance, 0.05);
}

TEST(CollisionPointTriangle, BadInputIsRefusedNamingTheObject) {
  Eigen::Matrix3Xd v(3, 3);
  v << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  clothsim::ColliderSet set;
  try {
    set.add_object("Grid", v, std::vector<std::uint32_t>{0, 1, 3});
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Grid"), std::string::npos) << e.what();
  }
  EXPECT_THROW(set.add_object("short", v, std::vector<std::uint32_t>{0, 1}), std::invalid_argument);
  Eigen::Matrix3Xd bad = v;
  bad(1, 2) = NAN;
  EXPECT_THROW(set.add_object("nan", bad, std::vector<std::uint32_t>{0, 1, 2}),
               std::invalid_argument);
  EXPECT_EQ(set.object_count(), 0u);
  set.add_object("ok", v, std::vector<std::uint32_t>{0, 1, 2});
  set.build();
  EXPECT_THROW(set.add_object("late", v, std::vector<std::uint32_t>{0, 1, 2}), std::logic_error);
  EXPECT_THROW(set.build(), std::logic_error);
}

TEST(CollisionPointTriangle, ObjectWithOnlyDegenerateTrianglesIsHarmless) {
  Eigen::Matrix3Xd line(3, 3);
  line << 0, 1, 2, 0, 0, 0, 0, 0, 0;
  Eigen::Matrix3Xd v(3, 3);
  v << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  clothsim::ColliderSet set;
  set.add_object("line", line, std::vector<std::uint32_t>{0, 1, 2});
  set.add_object("tri", v, std::vector<std::uint32_t>{0, 1, 2});
  set.build();
  EXPECT_EQ(set.triangle_count(0), 0u);
  EXPECT_EQ(set.triangle_count(), 1u);
  std::vector<clothsim::ColliderHit> out(2);
  std::vector<std::int32_t> hints = {0, 0};
  EXPECT_EQ(set.query(Vector3d(0.1, 0.1, 0.02), 0.1, out, clothsim::QueryMethod::Bvh, hints), 1u);
  EXPECT_FALSE(out[0].valid());
  EXPECT_EQ(out[1].object, 1);
  EXPECT_EQ(hints[0], -1);
}
