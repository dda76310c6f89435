// triangulate_polygon: the converter's own triangulation of faces with more than 3 corners.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "converter.hpp"

namespace {

using b2o::conv::triangulate_polygon;
using V3 = std::array<double, 3>;

V3 corner(const std::vector<float>& xyz, std::uint32_t i) { return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }

V3 cross(const V3& a, const V3& b, const V3& c) {
  const V3 e{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, f{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return {e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2], e[0] * f[1] - e[1] * f[0]};
}
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double length(const V3& a) { return std::sqrt(dot(a, a)); }

// Newell's normal: its length is twice the polygon's area.
V3 newell(const std::vector<float>& xyz) {
  const std::uint32_t n = static_cast<std::uint32_t>(xyz.size() / 3);
  V3 s{0, 0, 0};
  for (std::uint32_t i = 0; i < n; ++i) {
    const V3 a = corner(xyz, i), b = corner(xyz, (i + 1) % n);
    s[0] += (a[1] - b[1]) * (a[2] + b[2]);
    s[1] += (a[2] - b[2]) * (a[0] + b[0]);
    s[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return s;
}

struct Result {
  std::vector<std::uint32_t> tris;
  bool simple = false;
};

Result triangulate(const std::vector<float>& xyz) {
  Result r;
  r.simple = triangulate_polygon(xyz, r.tris);
  return r;
}

// A correct triangulation of a simple polygon: n - 2 triangles of its corners, every one
// facing the polygon's side (so none has zero area), their areas summing to the polygon's.
// (Ear cutting keeps the signed sum; all positive, no point is covered twice.)
Result expect_triangulated(const std::vector<float>& xyz, const std::string& what) {
  const Result r = triangulate(xyz);
  const std::uint32_t n = static_cast<std::uint32_t>(xyz.size() / 3);
  EXPECT_TRUE(r.simple) << what;
  EXPECT_EQ(r.tris.size(), 3u * (n - 2)) << what;
  const V3 normal = newell(xyz);
  double area = 0.0;
  for (std::size_t t = 0; t + 2 < r.tris.size(); t += 3) {
    for (std::size_t c = 0; c < 3; ++c) EXPECT_LT(r.tris[t + c], n) << what;
    if (r.tris[t] >= n || r.tris[t + 1] >= n || r.tris[t + 2] >= n) return r;
    const V3 c = cross(corner(xyz, r.tris[t]), corner(xyz, r.tris[t + 1]), corner(xyz, r.tris[t + 2]));
    EXPECT_GT(dot(c, normal), 1e-9 * dot(normal, normal))
        << what << ": triangle " << t / 3 << " (" << r.tris[t] << " " << r.tris[t + 1] << " " << r.tris[t + 2]
        << ") faces away from the polygon or has no area";
    area += 0.5 * length(c);
  }
  EXPECT_NEAR(area, 0.5 * length(normal), 1e-5 * length(normal)) << what << ": the triangles' area";
  return r;
}

// Is (x, y) strictly inside a triangle, in the plane of axes `u` and `v`?
bool covered(const std::vector<float>& xyz, const std::vector<std::uint32_t>& tris, double x, double y, int u = 0,
             int v = 2) {
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
    double o[3];
    for (int k = 0; k < 3; ++k) {
      const V3 a = corner(xyz, tris[t + k]), b = corner(xyz, tris[t + (k + 1) % 3]);
      o[k] = (b[u] - a[u]) * (y - a[v]) - (b[v] - a[v]) * (x - a[u]);
    }
    if ((o[0] > 0 && o[1] > 0 && o[2] > 0) || (o[0] < 0 && o[1] < 0 && o[2] < 0)) return true;
  }
  return false;
}

// Corners (x, z) in the y = 0 plane, as Blender exports a floor.
std::vector<float> xz(const std::vector<std::array<float, 2>>& pts) {
  std::vector<float> out;
  for (const auto& p : pts) out.insert(out.end(), {p[0], 0.0f, p[1]});
  return out;
}
std::vector<float> xy(const std::vector<std::array<float, 2>>& pts) {
  std::vector<float> out;
  for (const auto& p : pts) out.insert(out.end(), {p[0], p[1], 0.0f});
  return out;
}

// The L of the report: its reflex corner (1, 1) lies exactly on the diagonal from (2, 0) to
// (0, 2). assimp 5.2.5 makes it 4 triangles of area 4 covering the notch.
const std::vector<std::array<float, 2>> kL = {{0, 0}, {0, 2}, {1, 2}, {1, 1}, {2, 1}, {2, 0}};

TEST(Triangulate, LWithReflexCornerOnTheDiagonal) {
  const auto pts = xz(kL);
  EXPECT_GT(newell(pts)[1], 0.0);  // faces up (+y)
  const Result r = expect_triangulated(pts, "L");
  EXPECT_FALSE(covered(pts, r.tris, 1.5, 1.5)) << "a triangle covers the notch";
}

TEST(Triangulate, LStartingAtItsReflexCorner) {
  const std::vector<std::array<float, 2>> l = {{1, 1}, {2, 1}, {2, 0}, {0, 0}, {0, 2}, {1, 2}};
  const auto pts = xz(l);
  const Result r = expect_triangulated(pts, "L from the reflex corner");
  EXPECT_FALSE(covered(pts, r.tris, 1.5, 1.5));
}

TEST(Triangulate, ThreeWideL) {
  const std::vector<std::array<float, 2>> l = {{0, 0}, {0, 3}, {1, 3}, {1, 1}, {3, 1}, {3, 0}};
  const auto pts = xz(l);
  const Result r = expect_triangulated(pts, "3-wide L");
  EXPECT_FALSE(covered(pts, r.tris, 2.0, 2.0));
  EXPECT_FALSE(covered(pts, r.tris, 1.1, 1.1));
}

TEST(Triangulate, CombWithSeveralReflexCorners) {
  const std::vector<std::array<float, 2>> comb = {{0, 0}, {7, 0}, {7, 3}, {6, 3}, {6, 1}, {5, 1}, {5, 3}, {4, 3},
                                                  {4, 1}, {3, 1}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
  const auto pts = xy(comb);
  const Result r = expect_triangulated(pts, "comb");
  for (double gap : {1.5, 3.5, 5.5}) EXPECT_FALSE(covered(pts, r.tris, gap, 2.0, 0, 1)) << "gap at x = " << gap;
}

TEST(Triangulate, Star) {
  std::vector<std::array<float, 2>> star;
  for (int i = 0; i < 10; ++i) {
    const double a = 3.14159265358979 * i / 5, rad = i % 2 ? 0.4 : 1.0;
    star.push_back({static_cast<float>(rad * std::cos(a)), static_cast<float>(rad * std::sin(a))});
  }
  const auto pts = xz(star);
  const Result r = expect_triangulated(pts, "star");
  for (int i = 1; i < 10; i += 2) {  // between two tips, outside the star
    const double a = 3.14159265358979 * i / 5;
    EXPECT_FALSE(covered(pts, r.tris, 0.6 * std::cos(a), 0.6 * std::sin(a))) << "notch " << i;
  }
}

// Convex polygons: exactly assimp 5.2.5's triangles (its ear loop starts at corner 0 with
// corner n - 1 before it, so a fan from n - 1, the last three corners in index order), so
// existing output is unchanged. (import_test ConvexPolygonsAsAssimp compares with assimp.)
TEST(Triangulate, ConvexPolygonsAsAssimp) {
  std::vector<std::array<float, 2>> pentagon, hexagon;
  for (int i = 0; i < 5; ++i)
    pentagon.push_back({static_cast<float>(std::cos(1.2566370614359172 * i)), static_cast<float>(std::sin(1.2566370614359172 * i))});
  for (int i = 0; i < 6; ++i)
    hexagon.push_back({static_cast<float>(2 * std::cos(1.0471975511965976 * i)), static_cast<float>(std::sin(1.0471975511965976 * i))});
  EXPECT_EQ(expect_triangulated(xy(pentagon), "pentagon").tris,
            (std::vector<std::uint32_t>{4, 0, 1, 4, 1, 2, 2, 3, 4}));
  EXPECT_EQ(expect_triangulated(xy(hexagon), "hexagon").tris,
            (std::vector<std::uint32_t>{5, 0, 1, 5, 1, 2, 5, 2, 3, 3, 4, 5}));
}

TEST(Triangulate, QuadsFanFromTheReflexCorner) {
  EXPECT_EQ(expect_triangulated(xy({{0, 0}, {1, 0}, {1, 1}, {0, 1}}), "square").tris,
            (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  // a dart whose reflex corner is corner 2
  EXPECT_EQ(expect_triangulated(xy({{0, 0}, {2, 1}, {0.7f, 1}, {0, 2}}), "dart").tris,
            (std::vector<std::uint32_t>{2, 3, 0, 2, 0, 1}));
  // the same, clockwise seen from +z
  EXPECT_EQ(expect_triangulated(xy({{0, 2}, {0.7f, 1}, {2, 1}, {0, 0}}), "clockwise dart").tris,
            (std::vector<std::uint32_t>{1, 2, 3, 1, 3, 0}));
}

TEST(Triangulate, CollinearCornersGiveNoZeroAreaTriangle) {
  // a square with corners in the middle of its sides (assimp cuts the first one as an ear
  // with no area)
  expect_triangulated(xz({{1, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}}), "square, corner 0 on a side");
  expect_triangulated(xz({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}), "square, 8 corners");
  expect_triangulated(xz({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}, {2, 1}}), "triangle, 4 corners on a side");
  const Result r = expect_triangulated(xz({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 1}}), "L, 8 corners");
  EXPECT_FALSE(covered(xz({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 1}}), r.tris, 1.5, 1.5));
}

TEST(Triangulate, BowTieIsNotSimpleAndBecomesAFan) {
  // two triangles crossing at (2, 1), a corner in the middle of each upright side
  const auto pts = xy({{0, 0}, {4, 2}, {4, 1}, {4, 0}, {0, 2}, {0, 1}});
  const Result r = triangulate(pts);
  EXPECT_FALSE(r.simple);
  ASSERT_EQ(r.tris.size(), 3u * 4u);
  std::vector<int> used(6, 0);
  for (std::uint32_t c : r.tris) {
    ASSERT_LT(c, 6u);
    used[c] = 1;
  }
  for (int c = 0; c < 6; ++c) EXPECT_EQ(used[c], 1) << "corner " << c << " is in no triangle";
  // one lobe larger than the other
  const Result r2 = triangulate(xy({{0, 0}, {4, 4}, {4, 0}, {0, 2}, {0, 1}}));
  EXPECT_FALSE(r2.simple);
  EXPECT_EQ(r2.tris.size(), 3u * 3u);
}

// Orientation comes from Newell's normal, whatever the plane and the winding; the triangles
// keep the polygon's winding (expect_triangulated: each faces the polygon's side).
TEST(Triangulate, TiltedPlaneAndClockwiseWinding) {
  // the L in the plane x = 0.5 y + 0.75 z (its normal mostly along x; exact in floats)
  std::vector<float> tilted;
  for (const auto& p : kL) tilted.insert(tilted.end(), {0.5f * p[0] + 0.75f * p[1], p[0], p[1]});
  Result r = expect_triangulated(tilted, "tilted L");
  EXPECT_FALSE(covered(tilted, r.tris, 1.5, 1.5, 1, 2));
  // the L clockwise seen from +y: the triangles face down as the polygon does
  std::vector<std::array<float, 2>> reversed(kL.rbegin(), kL.rend());
  const auto cw = xz(reversed);
  EXPECT_LT(newell(cw)[1], 0.0);
  r = expect_triangulated(cw, "clockwise L");
  EXPECT_FALSE(covered(cw, r.tris, 1.5, 1.5));
  // and the other planes (normal along z, then along x) in both windings, from every start
  for (int rot = 0; rot < 6; ++rot) {
    std::vector<std::array<float, 2>> l(kL.begin() + rot, kL.end());
    l.insert(l.end(), kL.begin(), kL.begin() + rot);
    for (int flip = 0; flip < 2; ++flip) {
      if (flip) std::reverse(l.begin(), l.end());
      const auto in_xy = xy(l);
      r = expect_triangulated(in_xy, "L in xy, start " + std::to_string(rot) + (flip ? ", clockwise" : ""));
      EXPECT_FALSE(covered(in_xy, r.tris, 1.5, 1.5, 0, 1));
      std::vector<float> in_yz;
      for (const auto& p : l) in_yz.insert(in_yz.end(), {0.0f, p[0], p[1]});
      r = expect_triangulated(in_yz, "L in yz, start " + std::to_string(rot) + (flip ? ", clockwise" : ""));
      EXPECT_FALSE(covered(in_yz, r.tris, 1.5, 1.5, 1, 2));
    }
  }
}

TEST(Triangulate, LargeConvexPolygonIsAssimpsFan) {
  // 4096 corners on y = x * x (exact in floats, strictly convex): assimp's triangles
  const std::uint32_t n = 4096;
  std::vector<float> pts;
  for (std::uint32_t i = 0; i < n; ++i) pts.insert(pts.end(), {static_cast<float>(i), static_cast<float>(i * i), 0.0f});
  const Result r = triangulate(pts);
  EXPECT_TRUE(r.simple);
  ASSERT_EQ(r.tris.size(), 3u * (n - 2));
  for (std::uint32_t t = 0; t + 1 < n - 2; ++t)
    ASSERT_EQ((std::array<std::uint32_t, 3>{r.tris[3 * t], r.tris[3 * t + 1], r.tris[3 * t + 2]}),
              (std::array<std::uint32_t, 3>{n - 1, t, t + 1}))
        << "triangle " << t;
  EXPECT_EQ((std::array<std::uint32_t, 3>{r.tris[3 * (n - 3)], r.tris[3 * (n - 3) + 1], r.tris[3 * (n - 3) + 2]}),
            (std::array<std::uint32_t, 3>{n - 3, n - 2, n - 1}));
}

TEST(Triangulate, LargeComb) {
  // 2000 teeth, 8002 corners, half of them reflex: correct, and quick (only reflex corners
  // are tested against an ear)
  std::vector<std::array<float, 2>> comb = {{0, 0}, {4000, 0}};
  for (int t = 1999; t >= 0; --t) {
    const float x = static_cast<float>(2 * t);
    comb.insert(comb.end(), {{x + 2, 3}, {x + 1, 3}, {x + 1, 1}, {x, 1}});
  }
  const auto pts = xy(comb);
  const Result r = expect_triangulated(pts, "large comb");
  for (double gap : {0.5, 1998.5, 3998.5}) EXPECT_FALSE(covered(pts, r.tris, gap, 2.0, 0, 1)) << "gap at x = " << gap;
}

// A face that makes the ear search cubic (a thin half ring of 8 000 corners, thinner than its
// sagitta: every candidate ear holds a corner of the other side) stops at the search's budget
// (about a second) and is reported, instead of running for minutes (25 s for this one).
TEST(Triangulate, ThinRingStopsAtTheBudgetAndIsReported) {
  std::vector<std::array<float, 2>> ring;
  const int half = 4000;
  for (int k = 0; k < half; ++k) {
    const double a = 3.141592653589793 * k / (half - 1);
    ring.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))});
  }
  for (int k = half - 1; k >= 0; --k) {
    const double a = 3.141592653589793 * k / (half - 1);
    const double r = 1.0 - 2e-7;
    ring.push_back({static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a))});
  }
  const Result r = triangulate(xy(ring));
  EXPECT_FALSE(r.simple);
  EXPECT_EQ(r.tris.size(), 3u * (2u * half - 2u));  // every corner still in a triangle
}

// A quad whose two triangles cross (a bow-tie) is reported, and gets assimp's fan.
TEST(Triangulate, BowTieQuadIsReported) {
  const Result r = triangulate(xy({{0, 0}, {1, 1}, {1, 0}, {0, 1}}));
  EXPECT_FALSE(r.simple);
  EXPECT_EQ(r.tris.size(), 6u);
  EXPECT_TRUE(triangulate(xy({{0, 0}, {1, 0}, {1, 1}, {0, 1}})).simple);
}

}  // namespace
