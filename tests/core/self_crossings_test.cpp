// count_self_crossings(): flat and folded sheets have none, sheets pushed through each other
// have some, a hand-counted cross, welded UV seams, vertices shared, and the BVH against a
// brute-force count over every (edge, triangle) pair.
#include <clothsim/self_crossings.hpp>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

namespace {

using clothsim::count_self_crossings;
using clothsim::CrossingCount;
using clothsim::segment_crosses_triangle;
using Vec = Eigen::Vector3d;

struct Mesh {
  std::vector<Vec> v;
  std::vector<std::uint32_t> t;

  Eigen::Matrix3Xd x() const {
    Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = v[i];
    return m;
  }
  CrossingCount count() const { return count_self_crossings(x(), t); }
  void add(const Mesh& o) {
    const auto base = static_cast<std::uint32_t>(v.size());
    v.insert(v.end(), o.v.begin(), o.v.end());
    for (std::uint32_t i : o.t) t.push_back(base + i);
  }
};

// An (n+1) x (n+1) grid of vertices at f(i / n, j / n), two triangles a cell.
template <class F>
Mesh grid(int n, F f) {
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) m.v.push_back(f(static_cast<double>(i) / n, static_cast<double>(j) / n));
  const auto id = [n](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.t.insert(m.t.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.t.insert(m.t.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// The same mesh split at column j0 of an n-grid, as an OBJ with a UV seam is: the vertices of
// that column duplicated (same positions), the cells right of it using the copies.
Mesh split_at_column(const Mesh& g, int n, int j0) {
  Mesh m = g;
  std::vector<std::uint32_t> copy(g.v.size(), 0);
  for (int i = 0; i <= n; ++i) {
    const auto k = static_cast<std::uint32_t>(i * (n + 1) + j0);
    copy[k] = static_cast<std::uint32_t>(m.v.size());
    m.v.push_back(g.v[k]);
  }
  for (std::size_t f = 0; f < m.t.size(); f += 3) {
    bool right = false;  // a cell right of the seam: a corner in a column past j0
    for (std::size_t k = 0; k < 3; ++k) right |= static_cast<int>(g.t[f + k] % static_cast<std::uint32_t>(n + 1)) > j0;
    if (!right) continue;
    for (std::size_t k = 0; k < 3; ++k)
      if (static_cast<int>(g.t[f + k] % static_cast<std::uint32_t>(n + 1)) == j0) m.t[f + k] = copy[g.t[f + k]];
  }
  return m;
}

// The reference: every (edge, triangle) pair over welded vertices, no broad phase.
CrossingCount brute_force(const Mesh& m) {
  std::vector<Vec> pos;
  std::vector<std::uint32_t> id(m.v.size());
  for (std::size_t i = 0; i < m.v.size(); ++i) {
    const Vec p = m.v[i] + Vec::Zero();  // (-0.0 + 0.0 is 0.0)
    const auto it = std::find(pos.begin(), pos.end(), p);
    id[i] = static_cast<std::uint32_t>(it - pos.begin());
    if (it == pos.end()) pos.push_back(p);
  }
  std::vector<std::array<std::uint32_t, 3>> tris;
  for (std::size_t f = 0; f < m.t.size(); f += 3) {
    const std::array<std::uint32_t, 3> t{id[m.t[f]], id[m.t[f + 1]], id[m.t[f + 2]]};
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) tris.push_back(t);
  }
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (const auto& t : tris)
    for (std::size_t k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
  CrossingCount c;
  std::set<std::pair<std::size_t, std::size_t>> pairs;
  for (const auto& [u, w] : edges)
    for (std::size_t t = 0; t < tris.size(); ++t) {
      const auto& T = tris[t];
      if (std::find(T.begin(), T.end(), u) != T.end() || std::find(T.begin(), T.end(), w) != T.end()) continue;
      if (!segment_crosses_triangle(pos[u], pos[w], pos[T[0]], pos[T[1]], pos[T[2]])) continue;
      ++c.crossings;
      for (std::size_t o = 0; o < tris.size(); ++o) {
        const auto& O = tris[o];
        if (std::find(O.begin(), O.end(), u) != O.end() && std::find(O.begin(), O.end(), w) != O.end())
          pairs.insert(std::minmax(o, t));
      }
    }
  c.triangle_pairs = pairs.size();
  return c;
}

TEST(SelfCrossings, FlatGridHasNone) {
  const Mesh g = grid(20, [](double u, double w) { return Vec(u, 0.0, w); });
  const CrossingCount c = g.count();
  EXPECT_EQ(c.crossings, 0u);
  EXPECT_EQ(c.triangle_pairs, 0u);
  // tilted into a general plane, where rounding alone would put a far edge's ends on either
  // side of a triangle's plane (every pair, no broad phase, to see that)
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(0.7, Vec(1, 2, 3).normalized())).toRotationMatrix();
  Mesh tilted = grid(20, [&r](double u, double w) { return Vec(r * Vec(3.0 * u + 0.1, 0.0, 2.0 * w - 0.3)); });
  EXPECT_EQ(tilted.count().crossings, 0u);
  EXPECT_EQ(brute_force(tilted).crossings, 0u);
}

// Square A in the plane z = 0 (x, y in [-1, 1]), split along y = x into A1 = (a0 a1 a2) below
// the diagonal and A2 = (a0 a2 a3) above it. Square B in the plane x = 0.3 (y in [-0.5, 0.5],
// z in [-1, 1]), split along z = 2y into B1 = (b0 b1 b2) below and B2 = (b0 b2 b3) above.
// B's edges that pass z = 0: b1b2 at (0.3, 0.5, 0), above y = x: through A2; b0b3 at
// (0.3, -0.5, 0): through A1; the diagonal b0b2 at (0.3, 0, 0): through A1. A's edges that pass
// x = 0.3: a0a1 and a2a3 at y = -1 and 1, outside B; the diagonal a0a2 at (y, z) = (0.3, 0),
// below z = 2y: through B1. 4 crossings. Triangle pairs: b1b2 (of B1) with A2; b0b3 (of B2)
// with A1; b0b2 (of B1 and B2) with A1; a0a2 (of A1 and A2) with B1: {B1 A2, B2 A1, B1 A1}, 3.
TEST(SelfCrossings, TwoSquaresCrossingCountedByHand) {
  Mesh m;
  m.v = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0},                      // a0..a3
         {0.3, -0.5, -1}, {0.3, 0.5, -1}, {0.3, 0.5, 1}, {0.3, -0.5, 1}};  // b0..b3
  m.t = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  const CrossingCount c = m.count();
  EXPECT_EQ(c.crossings, 4u);
  EXPECT_EQ(c.triangle_pairs, 3u);
  const CrossingCount b = brute_force(m);
  EXPECT_EQ(b.crossings, 4u);
  EXPECT_EQ(b.triangle_pairs, 3u);
}

// A strip folded over itself like a U: layers 0.1 m apart, joined by a half circle.
TEST(SelfCrossings, FoldedSheetWithLayersApartHasNone) {
  const double len = 1.0, r = 0.05, total = 2.0 * len + std::numbers::pi * r;
  const Mesh g = grid(40, [&](double u, double w) {
    const double s = u * total;
    if (s <= len) return Vec(s, 0.0, w);
    if (s >= len + std::numbers::pi * r) return Vec(len - (s - len - std::numbers::pi * r), 2.0 * r, w);
    const double a = (s - len) / r;  // around the half circle
    return Vec(len + r * std::sin(a), r - r * std::cos(a), w);
  });
  EXPECT_EQ(g.count().crossings, 0u);
  EXPECT_EQ(brute_force(g).crossings, 0u);
}

// Two parallel sheets 0.1 m apart have none; with the upper one's middle pushed 0.2 m down,
// through the lower one, they have some.
Mesh two_sheets(bool pushed) {
  Mesh m = grid(12, [](double u, double w) { return Vec(u, 0.0, w); });
  m.add(grid(10, [pushed](double u, double w) {
    const bool middle = std::abs(u - 0.5) < 0.25 && std::abs(w - 0.5) < 0.25;
    return Vec(0.013 + 0.97 * u, middle && pushed ? -0.1 : 0.1, 0.029 + 0.95 * w);
  }));
  return m;
}

TEST(SelfCrossings, SheetPushedThroughAnotherHasSome) {
  EXPECT_EQ(two_sheets(false).count().crossings, 0u);
  const CrossingCount c = two_sheets(true).count();
  EXPECT_GT(c.crossings, 0u);
  EXPECT_GT(c.triangle_pairs, 0u);
  const CrossingCount b = brute_force(two_sheets(true));
  EXPECT_EQ(c.crossings, b.crossings);
  EXPECT_EQ(c.triangle_pairs, b.triangle_pairs);
}

// The closed cases: a segment through a triangle's edge or corner, or ending on it, touches it;
// one through its inside crosses it; one in its plane does neither; one that misses does neither.
TEST(SelfCrossings, SegmentsThatMeetATriangleOnlyAtItsBoundaryTouchIt) {
  using clothsim::Meet;
  using clothsim::segment_meets_triangle;
  const Vec a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_EQ(segment_meets_triangle(Vec(0.2, 0.2, -1), Vec(0.2, 0.2, 1), a, b, c), Meet::Crosses);
  EXPECT_EQ(segment_meets_triangle(Vec(0.5, 0.0, -1), Vec(0.5, 0.0, 1), a, b, c), Meet::Touches);  // through edge ab
  EXPECT_EQ(segment_meets_triangle(Vec(0.5, 0.5, -1), Vec(0.5, 0.5, 1), a, b, c), Meet::Touches);  // through edge bc
  EXPECT_EQ(segment_meets_triangle(Vec(0, 0, -1), Vec(0, 0, 1), a, b, c), Meet::Touches);          // through corner a
  EXPECT_EQ(segment_meets_triangle(Vec(0.2, 0.2, 0), Vec(0.2, 0.2, 1), a, b, c), Meet::Touches);   // ends on it
  EXPECT_EQ(segment_meets_triangle(Vec(0.1, 0.1, 0), Vec(0.3, 0.2, 0), a, b, c), Meet::None);      // in its plane
  EXPECT_EQ(segment_meets_triangle(Vec(0.8, 0.8, -1), Vec(0.8, 0.8, 1), a, b, c), Meet::None);     // past bc
  EXPECT_EQ(segment_meets_triangle(Vec(0.2, 0.2, 0.1), Vec(0.2, 0.2, 1), a, b, c), Meet::None);    // above it
  EXPECT_EQ(segment_crosses_triangle(Vec(0.5, 0.0, -1), Vec(0.5, 0.0, 1), a, b, c), false);
}

// Two grids that pass through each other exactly along grid lines of both (a vertical sheet
// whose row of edges lies in the level one, through its triangles) cross nowhere strictly:
// every meeting is on an edge. They touch, and the count says so; two sheets apart, a flat
// grid and sheets that cross in general position do not touch.
TEST(SelfCrossings, SheetsThroughEachOtherAlongGridLinesTouch) {
  Mesh m = grid(10, [](double u, double w) { return Vec(u, 0.0, w); });
  m.add(grid(10, [](double u, double w) { return Vec(u, w - 0.5, 0.513); }));
  const CrossingCount c = m.count();
  EXPECT_EQ(c.crossings, 0u);
  EXPECT_GT(c.touches, 10u);
  EXPECT_EQ(grid(20, [](double u, double w) { return Vec(u, 0.0, w); }).count().touches, 0u);
  EXPECT_EQ(two_sheets(false).count().touches, 0u);
  EXPECT_EQ(two_sheets(true).count().touches, 0u);
}

// A UV seam duplicates a column of vertices at the same positions: welded, it is the same
// mesh. A flat grid split so has none; a wavy one with a sheet through it along the seam
// has as many as unsplit (no seam edge counted twice), and -0.0 welds with 0.0.
TEST(SelfCrossings, SeamDuplicatesAreWelded) {
  const int n = 16;
  const Mesh flat = grid(n, [](double u, double w) { return Vec(u, 0.0, w); });
  const Mesh flat_split = split_at_column(flat, n, n / 2);
  ASSERT_EQ(flat_split.v.size(), flat.v.size() + static_cast<std::size_t>(n + 1));
  EXPECT_EQ(flat_split.count().crossings, 0u);

  const Mesh wavy = grid(n, [](double u, double w) { return Vec(u, 0.3 * std::sin(7.0 * u) * std::cos(5.0 * w), w); });
  // a level sheet across the seam (z = 0.5), which the waves' seam edges pass through
  const Mesh sheet = grid(9, [](double u, double w) { return Vec(1.2 * u - 0.097, 0.011, 0.3 + 0.4 * w + 0.0007); });
  Mesh through = wavy;
  through.add(sheet);
  Mesh through_split = split_at_column(wavy, n, n / 2);
  through_split.add(sheet);
  const CrossingCount whole = through.count(), split = through_split.count();
  EXPECT_GT(whole.crossings, 0u);
  EXPECT_EQ(split.crossings, whole.crossings);
  EXPECT_EQ(split.triangle_pairs, whole.triangle_pairs);

  Mesh zeros = flat_split;  // the copies at -0.0 where the originals are at 0.0
  for (std::size_t i = flat.v.size(); i < zeros.v.size(); ++i) zeros.v[i].y() = -0.0;
  EXPECT_EQ(zeros.count().crossings, 0u);
}

// An edge that ends at a corner of a triangle never crosses it, however the two lie; two
// triangles that share only a vertex and cut each other count through the edge they do not
// share: T2 = (v c d) stands in the plane y = 0 and its far edge cd passes through
// T1 = (v a b) at (1, 0, 0); T2's edges vc and vd start at T1's corner v.
TEST(SelfCrossings, SharedVerticesNeverCount) {
  Mesh m;
  m.v = {{0, 0, 0}, {2, -1, 0}, {2, 1, 0}, {1, 0, -1}, {1, 0, 1}};  // v a b c d
  m.t = {0, 1, 2, 0, 3, 4};
  const CrossingCount c = m.count();
  EXPECT_EQ(c.crossings, 1u);
  EXPECT_EQ(c.triangle_pairs, 1u);
  // a crumpled fan: every triangle shares the centre, so only rim edges against far triangles
  // can count, and edges with a corner of the triangle never do
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> h(-2.0, 2.0);
  Mesh fan;
  fan.v.push_back(Vec::Zero());
  const int k = 12;
  for (int i = 0; i < k; ++i) {
    const double a = 2.0 * std::numbers::pi * i / k;
    fan.v.push_back(Vec(std::cos(a), h(rng), std::sin(a)));
  }
  for (int i = 0; i < k; ++i)
    fan.t.insert(fan.t.end(), {0u, static_cast<std::uint32_t>(1 + i), static_cast<std::uint32_t>(1 + (i + 1) % k)});
  for (std::size_t f = 0; f < fan.t.size(); f += 3)
    for (std::size_t g = 0; g < fan.t.size(); g += 3)
      for (std::size_t e = 0; e < 3; ++e) {
        const std::uint32_t u = fan.t[g + e], w = fan.t[g + (e + 1) % 3];
        const Vec &a = fan.v[fan.t[f]], &b = fan.v[fan.t[f + 1]], &cc = fan.v[fan.t[f + 2]];
        const bool shares = u == fan.t[f] || u == fan.t[f + 1] || u == fan.t[f + 2] || w == fan.t[f] ||
                            w == fan.t[f + 1] || w == fan.t[f + 2];
        if (shares) {
          EXPECT_FALSE(segment_crosses_triangle(fan.v[u], fan.v[w], a, b, cc));
        }
      }
  EXPECT_EQ(fan.count().crossings, brute_force(fan).crossings);
}

// Random triangle soups and crumpled grids: the BVH finds exactly what every pair finds.
TEST(SelfCrossings, BroadPhaseMatchesBruteForce) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> coord(0.0, 1.0), noise(-0.08, 0.08);
  std::size_t total = 0;
  for (int round = 0; round < 6; ++round) {
    Mesh soup;  // 150 small random triangles in a unit box, some sharing vertices
    for (int i = 0; i < 150; ++i) {
      const double cx = coord(rng), cy = coord(rng), cz = coord(rng);
      const Vec c(cx, cy, cz);
      const auto base = static_cast<std::uint32_t>(soup.v.size());
      for (int k = 0; k < 3; ++k) {
        const double dx = noise(rng), dy = noise(rng), dz = noise(rng);
        soup.v.push_back(c + 2.0 * Vec(dx, dy, dz));
      }
      soup.t.insert(soup.t.end(), {base, base + 1, base + 2});
      if (i > 0 && i % 5 == 0) soup.t.insert(soup.t.end(), {base, base - 1, base + 1});
    }
    const Mesh crumpled = grid(14, [&](double u, double w) {
      const double dx = noise(rng), dy = 3.0 * noise(rng), dz = noise(rng);  // (in this order)
      return Vec(u + dx, dy, w + dz);
    });
    for (const Mesh* m : {&std::as_const(soup), &crumpled}) {
      const CrossingCount fast = m->count(), slow = brute_force(*m);
      EXPECT_EQ(fast.crossings, slow.crossings) << "round " << round;
      EXPECT_EQ(fast.triangle_pairs, slow.triangle_pairs) << "round " << round;
      total += fast.crossings;
    }
  }
  EXPECT_GT(total, 100u);  // the meshes do cross: the comparison is not of zeros
}

TEST(SelfCrossings, DegenerateTrianglesAndBadIndices) {
  Mesh m;
  m.v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}};  // vertex 3 welds with vertex 1
  m.t = {0, 1, 3, 0, 1, 2};                           // the first is degenerate once welded
  EXPECT_EQ(m.count().crossings, 0u);
  const std::vector<std::uint32_t> out_of_range = {0, 1, 4}, not_triples = {0, 1};
  EXPECT_THROW(count_self_crossings(m.x(), out_of_range), std::invalid_argument);
  EXPECT_THROW(count_self_crossings(m.x(), not_triples), std::invalid_argument);
  EXPECT_EQ(count_self_crossings(m.x(), std::span<const std::uint32_t>()).crossings, 0u);
}

// The Model overload counts Model::triangles at the given positions.
TEST(SelfCrossings, ModelOverloadUsesItsTriangles) {
  Mesh m;
  m.v = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0.3, -0.5, -1}, {0.3, 0.5, -1}, {0.3, 0.5, 1}, {0.3, -0.5, 1}};
  m.t = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
  clothsim::Model model;
  model.x0 = m.x();
  model.triangles = m.t;
  EXPECT_EQ(count_self_crossings(model, model.x0).crossings, 4u);
}

}  // namespace
