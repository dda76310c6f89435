#include "clothsim/collision.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "kernel.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CLOTHSIM_AVX2 1
#endif

namespace clothsim {

#ifdef CLOTHSIM_COLLISION_COUNTERS
std::uint64_t g_tri_tests = 0, g_box_tests = 0;  // profiling builds only
#endif

namespace {

Eigen::Vector3d unit_normal(const Eigen::Vector3d& ab, const Eigen::Vector3d& ac) {
  return ab.cross(ac).normalized();
}

// Squared distance from p to a node's box (0 inside), in float: cheap, branch-free, and made
// a safe lower bound by the caller's margin (see prune_bound()).
inline float box_dist_sq(const ColliderSet::Node& n, const float p[3]) {
  const float q0 = p[0] - n.c[0], q1 = p[1] - n.c[1], q2 = p[2] - n.c[2];
  const float e0 = std::max(std::abs(n.a[0] * q0 + n.a[1] * q1 + n.a[2] * q2) - n.h[0], 0.0f);
  const float e1 = std::max(std::abs(n.a[3] * q0 + n.a[4] * q1 + n.a[5] * q2) - n.h[1], 0.0f);
  const float e2 = std::max(std::abs(n.a[6] * q0 + n.a[7] * q1 + n.a[8] * q2) - n.h[2], 0.0f);
#ifdef CLOTHSIM_COLLISION_COUNTERS
  ++g_box_tests;
#endif
  return e0 * e0 + e1 * e1 + e2 * e2;
}

// 4 floats for the 4-wide node test (GCC/Clang vector extension, no intrinsics).
typedef float v4f __attribute__((vector_size(16)));
inline v4f load4(const float* p) {
  v4f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline v4f vabs(v4f x) { return x < 0.0f ? -x : x; }
inline v4f pos(v4f x) { return x > 0.0f ? x : v4f{0.0f, 0.0f, 0.0f, 0.0f}; }

// A box may hold a triangle at squared distance <= best only if its float distance is <= the
// returned bound: float rounding in box_dist_sq() is below `margin` (4e-6 of the magnitudes
// involved; float epsilon is 6e-8), and the axes' norm is <= 1 + 1e-6 (checked at build).
inline float prune_bound(double best, double margin) {
  const double r = std::sqrt(best) + margin;
  return static_cast<float>(r * r * (1.0 + 1e-5)) * (1.0f + 1e-6f);
}

// A BVH traversal's stack entry: a node or leaf (Node::packed form) and its box distance^2.
struct StackEntry {
  std::uint32_t ref;
  float d2;
};

// One visit of a 4-wide node: its 4 oriented boxes against the point in one 128-bit vector
// (SSE on x86-64, NEON on ARM); the children within `bound` are pushed farthest first, so the
// nearest is popped next; the smallest distance of a real box pruned goes into pruned_f.
inline void visit4(const ColliderSet::Node4& n, const float pf[3], float bound, StackEntry* stack,
                   int& top, float& pruned_f) {
  const v4f q0 = pf[0] - load4(n.c[0]), q1 = pf[1] - load4(n.c[1]), q2 = pf[2] - load4(n.c[2]);
  const v4f t0 = load4(n.a[0]) * q0 + load4(n.a[1]) * q1 + load4(n.a[2]) * q2;
  const v4f t1 = load4(n.a[3]) * q0 + load4(n.a[4]) * q1 + load4(n.a[5]) * q2;
  const v4f t2 = load4(n.a[6]) * q0 + load4(n.a[7]) * q1 + load4(n.a[8]) * q2;
  const v4f e0 = pos(vabs(t0) - load4(n.h[0])), e1 = pos(vabs(t1) - load4(n.h[1])),
            e2 = pos(vabs(t2) - load4(n.h[2]));
  const v4f d2 = e0 * e0 + e1 * e1 + e2 * e2;
#ifdef CLOTHSIM_COLLISION_COUNTERS
  g_box_tests += 4;
#endif
  StackEntry pass[4];
  int np = 0;
  for (int k = 0; k < 4; ++k)
    if (d2[k] <= bound) {
      int j = np++;
      for (; j > 0 && pass[j - 1].d2 < d2[k]; --j) pass[j] = pass[j - 1];
      pass[j] = StackEntry{n.child[k], d2[k]};
    } else if (n.h[0][k] >= 0.0f) {  // a real box (empty lanes have h < 0)
      pruned_f = std::min(pruned_f, static_cast<float>(d2[k]));
    }
  for (int k = 0; k < np; ++k) stack[top++] = pass[k];
}

// Depth-first over one object's 4-wide tree, nearer boxes first. Boxes strictly farther than
// the current bound are pruned (an equal distance may hide a lower-index tie); `test(slot)` is
// called for every triangle slot of each leaf reached, and `bound_sq()` is the distance^2 a
// triangle must beat, which shrinks as test() finds closer ones. Returns the smallest float
// box distance^2 pruned (+inf if none): with the tested triangles, a bound of the rest.
template <class BoundSq, class Test>
float traverse(const std::vector<ColliderSet::Node4>& nodes4, const ColliderSet::Node& root_box,
               std::uint32_t root4, const float pf[3], double margin, BoundSq bound_sq,
               Test& test) {
  double bound_for = bound_sq();
  float bound = prune_bound(bound_for, margin);
  const float root_d2 = box_dist_sq(root_box, pf);
  if (root_d2 > bound) return root_d2;
  float pruned_f = std::numeric_limits<float>::infinity();
  StackEntry stack[128];  // each visit pops 1, pushes <= 4; depth <= 26 for 2^28 triangles
  int top = 0;
  stack[top++] = StackEntry{root4, 0.0f};
  while (top > 0) {
    const StackEntry e = stack[--top];
    if (e.d2 > bound) {
      pruned_f = std::min(pruned_f, e.d2);
      continue;
    }
    if ((e.ref & 7u) != 0) {  // leaf
      for (std::uint32_t slot = e.ref >> 3, end = slot + (e.ref & 7u); slot < end; ++slot)
        test(slot);
      if (bound_sq() != bound_for) bound_for = bound_sq(), bound = prune_bound(bound_for, margin);
      continue;
    }
    visit4(nodes4[e.ref >> 3], pf, bound, stack, top, pruned_f);
  }
  return pruned_f;
}

inline double box_dist_sq(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const double p[3]) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double e = p[k] < lo[k] ? lo[k] - p[k] : (p[k] > hi[k] ? p[k] - hi[k] : 0.0);
    d2 += e * e;
  }
  return d2;
}

float round_up(double v) {
  auto f = static_cast<float>(v);
  if (static_cast<double>(f) < v) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Triangle slots come in blocks of 4 (one leaf each), component-major inside a block.
// (Slot-major, 96 contiguous bytes per triangle, made the searches 4-7 % slower.)
constexpr std::uint32_t kBlock = 4;
// Edge answers: only over the edge's middle (all but kEdgeEnds of its length at either end),
// and every other triangle at least kEdgeZeta of its length from there. (A fan triangle at an
// end that leaves it at an angle phi is kEdgeEnds sin(phi) of the length from the middle part:
// any phi above 14.5 degrees.)
constexpr double kEdgeEnds = 0.02, kEdgeZeta = 0.005;
// Clearances: the looser depth (of the coordinates) allowed far from a face or an edge, so that
// boxes of a plane's own triangles (a floor, a roof's slope: float boxes cannot tell tau) need
// not be opened; and the largest reach or distance (of the coordinates' scale, 2) it holds for.
constexpr double kLooseDepth = 2e-5;
// tau, of the coordinates' scale: how far behind a plane a triangle out of the way must be, and
// the gap by which clear faces and edge answers win. The certificates' rounding margin m (1e-12
// of the coordinates) must not exceed it; both are far above the kernel's rounding (~1e-15 of
// the coordinates). (1e-9 until stop 17: on a 5 mm mesh an edge answer then held only for
// points within ~10 cm, zeta^2 >= 6 d tau; now within ~10 m.)
constexpr double kTau = 1e-11;

// Total order for "closest": distance, then lowest input triangle index.
inline bool better(double d2, std::int32_t tri, double best_d2, std::int32_t best_tri) {
  return d2 < best_d2 || (d2 == best_d2 && tri < best_tri);
}

}  // namespace

PointTriangle point_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  PointTriangle r;
  if (triangle_is_degenerate(a, b, c)) {
    r.degenerate = true;
    return r;
  }
  const Eigen::Vector3d ab = b - a, ac = c - a, n = unit_normal(ab, ac);
  const detail::Tri t{a.x(), a.y(), a.z(), ab.x(), ab.y(), ab.z(),
                      ac.x(), ac.y(), ac.z(), n.x(), n.y(), n.z()};
  const double pp[3] = {p.x(), p.y(), p.z()};
  double s = 0, v = 0, w = 0;
  r.distance_sq = detail::closest_sq(pp, t, s, v, w, r.region);
  r.signed_distance = detail::signed_distance(r.distance_sq, s);
  r.closest = a + v * ab + w * ac;
  r.normal = n;
  return r;
}

inline detail::Tri ColliderSet::tri_at(std::uint32_t slot) const {
  static_assert(sizeof(detail::Tri) == 12 * sizeof(double));
  const double* b = &tri_[12 * std::size_t{slot & ~(kBlock - 1)} + (slot & (kBlock - 1))];
  return detail::Tri{b[0],          b[kBlock],      b[2 * kBlock],  b[3 * kBlock],
                     b[4 * kBlock], b[5 * kBlock],  b[6 * kBlock],  b[7 * kBlock],
                     b[8 * kBlock], b[9 * kBlock],  b[10 * kBlock], b[11 * kBlock]};
}

inline const double* ColliderSet::tri_ptr(std::uint32_t slot) const {
  return &tri_[12 * std::size_t{slot & ~(kBlock - 1)} + (slot & (kBlock - 1))];
}

bool triangle_is_degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  if (!a.allFinite() || !b.allFinite() || !c.allFinite()) return true;
  const Eigen::Vector3d ab = b - a, ac = c - a, bc = c - b;
  const double longest_sq = std::max({ab.squaredNorm(), ac.squaredNorm(), bc.squaredNorm()});
  const double cross = ab.cross(ac).norm();
  // |AB x AC| = 2 area; relative to the longest edge so that slivers count as degenerate.
  return !(cross > 1e-12 * longest_sq) || !std::isfinite(cross);
}

std::uint32_t ColliderSet::add_object(std::string name, const Eigen::Matrix3Xd& vertices,
                                      std::span<const std::uint32_t> indices) {
  if (built_)
    throw std::logic_error("collider '" + name + "': add_object() after build()");
  if (indices.size() % 3 != 0)
    throw std::invalid_argument("collider '" + name + "': index count " +
                                std::to_string(indices.size()) + " is not a multiple of 3");
  for (Eigen::Index i = 0; i < vertices.cols(); ++i)
    if (!vertices.col(i).allFinite())
      throw std::invalid_argument("collider '" + name + "': vertex " + std::to_string(i) +
                                  " is not finite");
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= static_cast<std::uint64_t>(vertices.cols()))
      throw std::invalid_argument("collider '" + name + "': triangle " + std::to_string(i / 3) +
                                  " uses vertex " + std::to_string(indices[i]) + " of " +
                                  std::to_string(vertices.cols()));
  if (indices.size() / 3 > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("collider '" + name + "': too many triangles");
  Object o;
  o.name = std::move(name);
  o.vertices = vertices;
  o.indices.assign(indices.begin(), indices.end());
  objects_.push_back(std::move(o));
  return static_cast<std::uint32_t>(objects_.size() - 1);
}

std::uint32_t ColliderSet::add_object(
    std::string name, const Eigen::Matrix3Xd& vertices,
    const Eigen::Matrix<std::uint32_t, 3, Eigen::Dynamic>& triangles) {
  return add_object(std::move(name), vertices,
                    std::span<const std::uint32_t>(triangles.data(),
                                                   static_cast<std::size_t>(triangles.size())));
}

std::size_t ColliderSet::triangle_count(std::size_t o) const {
  return objects_.at(o).kept;
}

void ColliderSet::triangle(std::size_t o, std::size_t t, Eigen::Vector3d& a, Eigen::Vector3d& b,
                           Eigen::Vector3d& c) const {
  const Object& ob = objects_.at(o);
  if (t >= ob.indices.size() / 3) throw std::out_of_range("collider triangle index out of range");
  a = ob.vertices.col(ob.indices[3 * t]);
  b = ob.vertices.col(ob.indices[3 * t + 1]);
  c = ob.vertices.col(ob.indices[3 * t + 2]);
}

void ColliderSet::build() {
  if (built_) throw std::logic_error("ColliderSet::build() called twice");
  std::size_t total = 0;
  for (const Object& o : objects_) total += o.indices.size() / 3;
  if (total >= (std::size_t{1} << 28))  // leaf triangle slots are packed in 29 bits
    throw std::invalid_argument("colliders: " + std::to_string(total) +
                                " triangles, at most 2^28 supported");
  tri_.reserve(12 * 2 * total);
  orig_.reserve(2 * total);
  nodes_.reserve(total / 2 + 2 * objects_.size() + 1);
  nodes4_.reserve(total / 6 + objects_.size() + 1);

  lo_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  hi_ = -lo_;
  double max_pad = 0.0;
  for (Object& ob : objects_) {
    const std::size_t nt = ob.indices.size() / 3;
    ob.input_to_kept.assign(nt, -1);
    std::vector<std::uint32_t> kept;
    kept.reserve(nt);
    double scale = 1e-300;
    for (std::size_t t = 0; t < nt; ++t) {
      Eigen::Vector3d a, b, c;
      triangle(static_cast<std::size_t>(&ob - objects_.data()), t, a, b, c);
      if (triangle_is_degenerate(a, b, c)) {
        ++ob.degenerate;
        continue;
      }
      kept.push_back(static_cast<std::uint32_t>(t));
      scale = std::max({scale, a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(),
                        c.cwiseAbs().maxCoeff()});
    }
    ob.tri_begin = static_cast<std::uint32_t>(orig_.size());
    ob.tri_end = ob.tri_begin;
    if (kept.empty()) continue;

    // Per kept triangle: corners and centroid, then a median-split BVH over a permutation.
    std::vector<double> corners(9 * kept.size()), cent(3 * kept.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const std::uint32_t t = kept[i];
      for (std::size_t j = 0; j < 3; ++j)
        for (std::size_t k = 0; k < 3; ++k) {
          const double x = ob.vertices(static_cast<Eigen::Index>(k), ob.indices[3 * t + j]);
          corners[9 * i + 3 * j + k] = x;
          cent[3 * i + k] += x / 3.0;
          lo_[static_cast<Eigen::Index>(k)] = std::min(lo_[static_cast<Eigen::Index>(k)], x);
          hi_[static_cast<Eigen::Index>(k)] = std::max(hi_[static_cast<Eigen::Index>(k)], x);
          if (i == 0 && j == 0) ob.lo[static_cast<Eigen::Index>(k)] = ob.hi[static_cast<Eigen::Index>(k)] = x;
          ob.lo[static_cast<Eigen::Index>(k)] = std::min(ob.lo[static_cast<Eigen::Index>(k)], x);
          ob.hi[static_cast<Eigen::Index>(k)] = std::max(ob.hi[static_cast<Eigen::Index>(k)], x);
        }
    }
    std::vector<std::uint32_t> perm(kept.size());
    for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = static_cast<std::uint32_t>(i);
    // Pad: many orders of magnitude above double rounding in the kernel (~1e-15 scale).
    const double pad = 1e-9 * scale;
    max_pad = std::max(max_pad, pad);
    ob.lo.array() -= pad;
    ob.hi.array() += pad;
    ob.scale = scale;
    ob.root = build_node(0, static_cast<std::uint32_t>(perm.size()), cent, perm, corners, pad);

    // Store the triangles leaf by leaf, each leaf in its own block of 4 slots (384 bytes, one
    // contiguous run per leaf; unused slots have orig_ = -1). Leaves get global slots.
    for (std::size_t ni = ob.root; ni < nodes_.size(); ++ni) {
      Node& leaf = nodes_[ni];
      if (!leaf.leaf()) continue;
      const std::uint32_t first = leaf.index(), count = leaf.count();
      const auto slot0 = static_cast<std::uint32_t>(orig_.size());
      tri_.resize(tri_.size() + kBlock * 12, 0.0);
      orig_.resize(orig_.size() + kBlock, -1);
      for (std::uint32_t j = 0; j < count; ++j) {
        const std::uint32_t t = kept[perm[first + j]];
        const Eigen::Vector3d a = ob.vertices.col(ob.indices[3 * t]);
        const Eigen::Vector3d ab = ob.vertices.col(ob.indices[3 * t + 1]) - a;
        const Eigen::Vector3d ac = ob.vertices.col(ob.indices[3 * t + 2]) - a;
        const Eigen::Vector3d n = unit_normal(ab, ac);
        const double comp[12] = {a.x(),  a.y(),  a.z(),  ab.x(), ab.y(), ab.z(),
                                 ac.x(), ac.y(), ac.z(), n.x(),  n.y(),  n.z()};
        for (std::size_t k = 0; k < 12; ++k) tri_[12 * slot0 + kBlock * k + j] = comp[k];
        ob.input_to_kept[t] = static_cast<std::int32_t>(slot0 + j);
        orig_[slot0 + j] = static_cast<std::int32_t>(t);
      }
      leaf.packed = (slot0 << 3) | count;
    }
    ob.tri_end = static_cast<std::uint32_t>(orig_.size());
    ob.kept = kept.size();
    kept_total_ += kept.size();
    ob.root4 = nodes_[ob.root].leaf() ? nodes_[ob.root].packed : collapse(ob.root) << 3;
  }
  // Queries need only each root's box and the 4-wide tree.
  for (Object& ob : objects_)
    if (ob.tri_end > ob.tri_begin) ob.root_box = nodes_[ob.root];
  // Clearances are computed when first needed (clear_at(), eclear_at()): NaN until then.
  clear_.assign(orig_.size(), std::numeric_limits<float>::quiet_NaN());
  eclear_.assign(3 * orig_.size(), std::numeric_limits<float>::quiet_NaN());
  adj_.assign(3 * orig_.size(), -1);
  for (std::size_t o = 0; o < objects_.size(); ++o)
    if (objects_[o].tri_end > objects_[o].tri_begin) compute_adjacency(o);
  adj_.shrink_to_fit();
  nodes_.clear();
  nodes_.shrink_to_fit();
  nodes4_.shrink_to_fit();
  tri_.shrink_to_fit();
  orig_.shrink_to_fit();
  // Padded, so the early-out never rejects what a query would find.
  lo_.array() -= max_pad;
  hi_.array() += max_pad;
  if (orig_.empty()) lo_.setZero(), hi_.setZero();
  built_ = true;
}

namespace {

// Half extents of the corners about centre c along float axes a (rows), padded, rounded up.
void extents(const float a[9], const float c[3], const std::vector<double>& corners,
             const std::vector<std::uint32_t>& perm, std::uint32_t begin, std::uint32_t end,
             double pad, float h[3]) {
  double m[3] = {0.0, 0.0, 0.0};
  for (std::uint32_t i = begin; i < end; ++i)
    for (std::size_t j = 0; j < 3; ++j) {
      const double* v = &corners[9 * perm[i] + 3 * j];
      const double q[3] = {v[0] - static_cast<double>(c[0]), v[1] - static_cast<double>(c[1]),
                           v[2] - static_cast<double>(c[2])};
      for (int k = 0; k < 3; ++k)
        m[k] = std::max(m[k], std::abs(static_cast<double>(a[3 * k]) * q[0] +
                                       static_cast<double>(a[3 * k + 1]) * q[1] +
                                       static_cast<double>(a[3 * k + 2]) * q[2]));
    }
  for (int k = 0; k < 3; ++k) h[k] = round_up(m[k] + pad);
}

// |A|_2 <= 1 + 1e-6 for the float axes, as box_dist_sq() assumes.
bool nearly_orthonormal(const float a[9]) {
  Eigen::Matrix3d A;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) A(r, k) = static_cast<double>(a[3 * r + k]);
  return ((A * A.transpose()) - Eigen::Matrix3d::Identity()).norm() < 1e-6;
}

}  // namespace

std::uint32_t ColliderSet::build_node(std::uint32_t begin, std::uint32_t end,
                                      std::vector<double>& cent, std::vector<std::uint32_t>& perm,
                                      const std::vector<double>& corners, double pad) {
  const auto self = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(Node{});
  // Axis-aligned box, and an oriented one: normal = area-weighted mean normal, first tangent =
  // the principal direction of the corners in that plane. Keep the smaller volume.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
                  hi = -lo, clo = lo, chi = hi, area = Eigen::Vector3d::Zero(),
                  mean = Eigen::Vector3d::Zero();
  for (std::uint32_t i = begin; i < end; ++i) {
    const double* v = &corners[9 * perm[i]];
    const Eigen::Vector3d A(v[0], v[1], v[2]), B(v[3], v[4], v[5]), C(v[6], v[7], v[8]);
    lo = lo.cwiseMin(A).cwiseMin(B).cwiseMin(C);
    hi = hi.cwiseMax(A).cwiseMax(B).cwiseMax(C);
    area += (B - A).cross(C - A);
    mean += A + B + C;
    const Eigen::Vector3d c(cent[3 * perm[i]], cent[3 * perm[i] + 1], cent[3 * perm[i] + 2]);
    clo = clo.cwiseMin(c);
    chi = chi.cwiseMax(c);
  }
  mean /= 3.0 * (end - begin);

  Node best{};
  for (int k = 0; k < 3; ++k) {
    best.c[k] = static_cast<float>(0.5 * (lo[k] + hi[k]));
    best.a[4 * k] = 1.0f;
  }
  extents(best.a, best.c, corners, perm, begin, end, pad, best.h);
  if (area.norm() > 0.0) {
    const Eigen::Vector3d n = area.normalized();
    Eigen::Vector3d u = n.unitOrthogonal(), w = n.cross(u);
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (std::uint32_t i = begin; i < end; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const double* v = &corners[9 * perm[i] + 3 * j];
        const Eigen::Vector3d q = Eigen::Vector3d(v[0], v[1], v[2]) - mean;
        const Eigen::Vector2d r(q.dot(u), q.dot(w));
        cov += r * r.transpose();
      }
    const double angle = 0.5 * std::atan2(2.0 * cov(0, 1), cov(0, 0) - cov(1, 1));
    const Eigen::Vector3d u2 = std::cos(angle) * u + std::sin(angle) * w;
    const Eigen::Vector3d w2 = n.cross(u2);
    Node o{};
    for (int k = 0; k < 3; ++k) {
      o.a[k] = static_cast<float>(n[k]);
      o.a[3 + k] = static_cast<float>(u2[k]);
      o.a[6 + k] = static_cast<float>(w2[k]);
    }
    // Centre: the middle of the corners' span along each axis.
    Eigen::Vector3d tmin = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
                    tmax = -tmin;
    const Eigen::Matrix3d R = (Eigen::Matrix3d() << n.transpose(), u2.transpose(), w2.transpose()).finished();
    for (std::uint32_t i = begin; i < end; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const double* v = &corners[9 * perm[i] + 3 * j];
        const Eigen::Vector3d t = R * Eigen::Vector3d(v[0], v[1], v[2]);
        tmin = tmin.cwiseMin(t);
        tmax = tmax.cwiseMax(t);
      }
    const Eigen::Vector3d centre = R.transpose() * (0.5 * (tmin + tmax));
    for (int k = 0; k < 3; ++k) o.c[k] = static_cast<float>(centre[k]);
    extents(o.a, o.c, corners, perm, begin, end, pad, o.h);
    const auto volume = [](const Node& x) {
      return static_cast<double>(x.h[0]) * static_cast<double>(x.h[1]) * static_cast<double>(x.h[2]);
    };
    if (nearly_orthonormal(o.a) && volume(o) < volume(best)) best = o;
  }

  constexpr std::uint32_t kLeafSize = kBlock;  // a leaf fills at most one block of slots
  if (end - begin <= kLeafSize) {
    best.packed = (begin << 3) | (end - begin);  // local slot, made global by build()
    nodes_[self] = best;
    return self;
  }
  // Split near the median along the longest centroid extent; ties in position broken by index so the
  // tree does not depend on the standard library's nth_element.
  int axis = 0;
  const Eigen::Vector3d ext = chi - clo;
  if (ext[1] > ext[axis]) axis = 1;
  if (ext[2] > ext[axis]) axis = 2;
  // Left gets a multiple of the leaf size, so leaves are full (blocks of 4 slots well used).
  const std::uint32_t mid = begin + kLeafSize * ((end - begin + 2 * kLeafSize - 1) / (2 * kLeafSize));
  std::nth_element(perm.begin() + begin, perm.begin() + mid, perm.begin() + end,
                   [&](std::uint32_t x, std::uint32_t y) {
                     const double cx = cent[3 * x + static_cast<std::uint32_t>(axis)];
                     const double cy = cent[3 * y + static_cast<std::uint32_t>(axis)];
                     return cx < cy || (cx == cy && x < y);
                   });
  build_node(begin, mid, cent, perm, corners, pad);  // left = self + 1
  const std::uint32_t right = build_node(mid, end, cent, perm, corners, pad);
  best.packed = right << 3;
  nodes_[self] = best;
  return self;
}

std::uint32_t ColliderSet::collapse(std::uint32_t b) {
  // Open the inner child with the largest box until there are 4 children (or only leaves).
  std::uint32_t kids[4] = {b + 1, nodes_[b].index(), 0, 0};
  std::uint32_t n = 2;
  const auto size = [&](std::uint32_t i) {
    const Node& x = nodes_[i];
    return static_cast<double>(x.h[0]) + static_cast<double>(x.h[1]) + static_cast<double>(x.h[2]);
  };
  while (n < 4) {
    int open = -1;
    for (std::uint32_t k = 0; k < n; ++k)
      if (!nodes_[kids[k]].leaf() && (open < 0 || size(kids[k]) > size(kids[open])))
        open = static_cast<int>(k);
    if (open < 0) break;
    const std::uint32_t i = kids[open];
    kids[open] = i + 1;
    kids[n++] = nodes_[i].index();
  }
  const auto self = static_cast<std::uint32_t>(nodes4_.size());
  nodes4_.push_back(Node4{});
  Node4 q{};
  for (std::uint32_t k = 0; k < 4; ++k) {
    if (k >= n) {  // an empty lane: an inverted box, infinitely far
      for (int j = 0; j < 3; ++j) q.h[j][k] = -std::numeric_limits<float>::max();
      q.child[k] = 0;
      continue;
    }
    const Node& x = nodes_[kids[k]];
    for (int j = 0; j < 3; ++j) q.c[j][k] = x.c[j], q.h[j][k] = x.h[j];
    for (int j = 0; j < 9; ++j) q.a[j][k] = x.a[j];
    q.child[k] = x.leaf() ? x.packed : collapse(kids[k]) << 3;
  }
  nodes4_[self] = q;
  return self;
}

ColliderHit ColliderSet::query_object(std::size_t o, const double p[3], double radius_sq,
                                      QueryMethod method, std::int32_t hint,
                                      double* others_lb) const {
  const Object& ob = objects_[o];
  ColliderHit hit;
  if (others_lb) *others_lb = std::numeric_limits<double>::infinity();
  if (ob.tri_end == ob.tri_begin) return hit;
  // For others_lb: the smallest distance^2 of a tested triangle that is not the answer, and the
  // smallest float box distance^2 of a pruned subtree.
  double other_d2 = std::numeric_limits<double>::infinity();
  float pruned_f = std::numeric_limits<float>::infinity();
  double margin = 0.0;
  double best = radius_sq;
  std::int32_t best_tri = std::numeric_limits<std::int32_t>::max();
  std::uint32_t best_slot = 0;
  double best_s = 0.0;
  bool found = false;

  const auto test = [&](std::uint32_t slot) {
#ifdef CLOTHSIM_COLLISION_COUNTERS
    ++g_tri_tests;
#endif
    double s;
    const double d2 = detail::closest_sq<kBlock>(p, tri_ptr(slot), s);
    const std::int32_t idx = orig_[slot];
    if (found && idx == best_tri) return;  // the hint, met again in the tree
    if (d2 <= radius_sq && better(d2, idx, best, best_tri)) {
      if (found) other_d2 = std::min(other_d2, best);
      best = d2, best_tri = idx, best_slot = slot, best_s = s, found = true;
    } else {
      other_d2 = std::min(other_d2, d2);
    }
  };

  if (method == QueryMethod::BruteForce) {
    for (std::uint32_t slot = ob.tri_begin; slot < ob.tri_end; ++slot)
      if (orig_[slot] >= 0) test(slot);
  } else {
    if (hint >= 0 && static_cast<std::size_t>(hint) < ob.input_to_kept.size()) {
      const std::int32_t slot = ob.input_to_kept[static_cast<std::size_t>(hint)];
      if (slot >= 0) test(static_cast<std::uint32_t>(slot));
    }
    const float pf[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                         static_cast<float>(p[2])};
    margin = 4e-6 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + ob.scale);
    pruned_f = traverse(nodes4_, ob.root_box, ob.root4, pf, margin, [&] { return best; }, test);
  }
  if (others_lb) {
    // Float box distances back to a safe lower bound of true distances (see prune_bound()).
    const double box_lb =
        std::isinf(pruned_f)
            ? std::numeric_limits<double>::infinity()
            : std::max(0.0, std::sqrt(static_cast<double>(pruned_f)) * (1.0 - 1e-5) - margin);
    *others_lb = std::min(std::sqrt(other_d2), box_lb);
  }
  if (!found) return hit;
  hit.object = static_cast<std::int32_t>(o);
  hit.triangle = best_tri;
  hit.distance_sq = best;
  hit.signed_distance = detail::signed_distance(best, best_s);
  const detail::Tri bt = tri_at(best_slot);
  hit.normal = Eigen::Vector3d(bt.nx, bt.ny, bt.nz);
  return hit;
}

std::size_t ColliderSet::query(const Eigen::Vector3d& p, double radius,
                               std::span<ColliderHit> out, QueryMethod method,
                               std::span<std::int32_t> hints) const {
  if (!built_) throw std::logic_error("ColliderSet::query() before build()");
  if (out.size() != objects_.size())
    throw std::invalid_argument("ColliderSet::query(): out needs one entry per object");
  if (!(radius >= 0.0)) throw std::invalid_argument("ColliderSet::query(): radius < 0 or NaN");
  if (!hints.empty() && hints.size() != objects_.size())
    throw std::invalid_argument("ColliderSet::query(): hints need one entry per object");
  const double pp[3] = {p.x(), p.y(), p.z()};
  const double r2 = radius * radius;
  std::size_t hits = 0;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    out[o] = query_object(o, pp, r2, method, hints.empty() ? -1 : hints[o]);
    if (out[o].valid()) ++hits;
    if (!hints.empty()) hints[o] = out[o].triangle;
  }
  return hits;
}

ColliderHit ColliderSet::closest(const Eigen::Vector3d& p, double radius,
                                 QueryMethod method) const {
  if (!built_) throw std::logic_error("ColliderSet::closest() before build()");
  if (!(radius >= 0.0)) throw std::invalid_argument("ColliderSet::closest(): radius < 0 or NaN");
  const double pp[3] = {p.x(), p.y(), p.z()};
  ColliderHit best;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    const ColliderHit h = query_object(o, pp, radius * radius, method, -1);
    if (h.valid() && (!best.valid() || h.distance_sq < best.distance_sq)) best = h;
  }
  return best;
}

namespace {

// A float that is <= v (the stored lower bounds of the candidates' distances).
float round_down(double v) {
  auto f = static_cast<float>(v);
  if (static_cast<double>(f) > v) {  // one float step down (f is finite here: v is)
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    if (f > 0.0f) --bits;
    else if (f < 0.0f) ++bits;
    else bits = 0x80000001u;  // the negative float nearest 0
    std::memcpy(&f, &bits, sizeof f);
  }
  return f;
}

constexpr std::size_t kMaxCandidates = ContactCache::kMaxCandidates;

}  // namespace

std::size_t ColliderSet::query_nearest(std::size_t o, const double p[3], double radius_sq,
                                       QueryMethod method, std::size_t k,
                                       std::span<const std::uint32_t> seed, std::uint32_t* slots,
                                       double* d2s, double& others_lb) const {
  const Object& ob = objects_[o];
  others_lb = std::numeric_limits<double>::infinity();
  if (ob.tri_end == ob.tri_begin || k == 0) return 0;
  // The list: the k best (distance^2, input index) within radius found so far, ascending.
  // other_d2: the smallest distance^2 of a tested triangle not in the list; pruned_f: the
  // smallest float box distance^2 of a pruned subtree. Together they bound everything else.
  std::int32_t idxs[kMaxCandidates];
  std::size_t n = 0;
  double other_d2 = std::numeric_limits<double>::infinity();
  float pruned_f = std::numeric_limits<float>::infinity();
  double margin = 0.0;
  std::uint64_t in_list = 0;  // bit (slot mod 64) set for every slot ever put in the list

  const auto test = [&](std::uint32_t slot) {
#ifdef CLOTHSIM_COLLISION_COUNTERS
    ++g_tri_tests;
#endif
    if ((in_list >> (slot & 63u)) & 1u)  // perhaps in the list already (a seed, met again)
      for (std::size_t j = 0; j < n; ++j)
        if (slots[j] == slot) return;
    double s;
    const double d2 = detail::closest_sq<kBlock>(p, tri_ptr(slot), s);
    const std::int32_t idx = orig_[slot];
    if (d2 > radius_sq || (n == k && !better(d2, idx, d2s[k - 1], idxs[k - 1]))) {
      other_d2 = std::min(other_d2, d2);
      return;
    }
    if (n == k) other_d2 = std::min(other_d2, d2s[--n]);  // the last one drops out
    std::size_t j = n++;
    for (; j > 0 && better(d2, idx, d2s[j - 1], idxs[j - 1]); --j)
      d2s[j] = d2s[j - 1], idxs[j] = idxs[j - 1], slots[j] = slots[j - 1];
    d2s[j] = d2, idxs[j] = idx, slots[j] = slot;
    in_list |= std::uint64_t{1} << (slot & 63u);  // never cleared: a filter, not a set
  };
  // Nothing farther than this can enter the list or lower the bound of the rest.
  const auto bound_sq = [&] { return std::min(radius_sq, other_d2); };

  if (method == QueryMethod::BruteForce) {
    for (std::uint32_t slot = ob.tri_begin; slot < ob.tri_end; ++slot)
      if (orig_[slot] >= 0) test(slot);
  } else {
    for (const std::uint32_t slot : seed)
      if (slot >= ob.tri_begin && slot < ob.tri_end && orig_[slot] >= 0) test(slot);
    const float pf[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                         static_cast<float>(p[2])};
    margin = 4e-6 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + ob.scale);
    pruned_f = traverse(nodes4_, ob.root_box, ob.root4, pf, margin, bound_sq, test);
  }
  const double box_lb =
      std::isinf(pruned_f)
          ? std::numeric_limits<double>::infinity()
          : std::max(0.0, std::sqrt(static_cast<double>(pruned_f)) * (1.0 - 1e-5) - margin);
  others_lb = std::min(std::sqrt(other_d2), box_lb);
  return n;
}

namespace {
// A list that survived fewer certified calls than this did not pay for its K-nearest search
// (measured: it costs 3-5 plain searches); after kRetry 1-nearest searches (times
// 2^backoff), a list is tried again.
constexpr std::uint16_t kMinAge = 8;
constexpr std::uint8_t kRetry = 8;
// Objects with more triangles than this keep a copy of each entry's first candidate in the
// cache (a small collider stays in cache; the copy would only add memory traffic).
constexpr std::size_t kCopyAbove = 4096;

// A certificate's rounding margin at p (far below any useful gap) and how far p is from where
// the certificate was made: every check of it computes both this way, so that they all make
// the same decisions.
inline double certificate_margin(const double p[3], double scale) {
  return 1e-12 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + scale);
}
inline double moved_from(const double p[3], const double x0[3]) {
  const double dx = p[0] - x0[0], dy = p[1] - x0[1], dz = p[2] - x0[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Stores the plane certificate "within r of p the answer stays" (see ContactCache::Plane)
// and returns true, if r > 0 survives the roundings: x0 is kept in float (r shrinks by how
// far that moved it) and r^2 in the upper half of a float, both rounded towards 0.
inline bool store_plane(ContactCache::Plane& pl, std::uint16_t epoch, const double p[3],
                        double r, bool face) {
  const float x0[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                       static_cast<float>(p[2])};
  const double ex = p[0] - x0[0], ey = p[1] - x0[1], ez = p[2] - x0[2];
  r -= std::sqrt(ex * ex + ey * ey + ez * ez) * (1.0 + 1e-6) + 1e-6 * r;
  if (!(r > 0.0)) return false;
  const float r2 = round_down(r * r * (1.0 - 1e-6));
  std::uint32_t bits;
  std::memcpy(&bits, &r2, sizeof bits);
  bits >>= 16;  // a positive float cut to its upper half: rounded down
  if (!(r2 > 0.0f) || bits == 0) return false;
  pl.x0[0] = x0[0], pl.x0[1] = x0[1], pl.x0[2] = x0[2];
  pl.r2 = static_cast<std::uint16_t>(face ? bits : (bits | 0x8000u));
  pl.born = epoch;
  return true;
}

// Whether entry e may make a plane certificate now (called where the plane check failed or
// there was none): a certificate that lived fewer than 4 calls (or could not be made) makes
// the next attempts wait 1, 3, 7 .. 63 calls.
constexpr std::uint16_t kPlaneMinLife = 4;
inline bool plane_due(ContactCache& cache, ContactCache::Entry& e, ContactCache::Plane& pl) {
  if (pl.r2 != 0) {  // the last one no longer holds: judge how long it lived, once
    if (static_cast<std::uint16_t>(cache.epoch - pl.born) < kPlaneMinLife) {
      if (e.plane_backoff < 6) ++e.plane_backoff;
      e.plane_wait = static_cast<std::uint8_t>((1u << e.plane_backoff) - 1u);
    } else {
      e.plane_backoff = 0;
    }
    pl.r2 = 0;
  }
  if (e.plane_wait > 0) {
    --e.plane_wait;
    return false;
  }
  return true;
}
inline void plane_failed(ContactCache::Entry& e) {
  if (e.plane_backoff < 6) ++e.plane_backoff;
  e.plane_wait = static_cast<std::uint8_t>((1u << e.plane_backoff) - 1u);
}
// How far the foot of p (plane distance s) is inside each edge of triangle t (component k at
// t[k * stride]; edge 0: A-B, 1: B-C, 2: C-A), in `in`, and `margin` (1e-6 of the
// coordinates), far beyond the kernel's rounding: every point within in[k] - margin (> 0) of p
// takes the kernel's face branch, whose distance is |n.(p - a)|; the foot of a point with
// in[k] < -margin is beyond edge k. False on a sliver (sine of the smallest angle < 1e-2).
bool face_insides(const double p[3], const double* t, std::size_t stride, double s, double in[3],
                  double& margin) {
  const auto T = [t, stride](int k) { return t[static_cast<std::size_t>(k) * stride]; };
  const double n[3] = {T(9), T(10), T(11)};
  const double ab[3] = {T(3), T(4), T(5)}, ac[3] = {T(6), T(7), T(8)};
  const double bc[3] = {ac[0] - ab[0], ac[1] - ab[1], ac[2] - ab[2]};
  const auto len = [](const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
  const double lab = len(ab), lac = len(ac), lbc = len(bc);
  const double cx = ab[1] * ac[2] - ab[2] * ac[1], cy = ab[2] * ac[0] - ab[0] * ac[2],
               cz = ab[0] * ac[1] - ab[1] * ac[0];
  const double longest = std::max({lab, lac, lbc});
  if (!(std::sqrt(cx * cx + cy * cy + cz * cz) >= 1e-2 * longest * longest)) return false;
  // The foot of p relative to A, and its distance inside each edge's line (in the plane).
  const double q[3] = {p[0] - T(0) - s * n[0], p[1] - T(1) - s * n[1], p[2] - T(2) - s * n[2]};
  const auto inside = [&n](const double e[3], const double w[3], double l) {
    // ((e x w) . n) / |e|: > 0 on the triangle's side of the edge (counter-clockwise)
    return ((e[1] * w[2] - e[2] * w[1]) * n[0] + (e[2] * w[0] - e[0] * w[2]) * n[1] +
            (e[0] * w[1] - e[1] * w[0]) * n[2]) / l;
  };
  const double qb[3] = {q[0] - ab[0], q[1] - ab[1], q[2] - ab[2]};
  const double qc[3] = {q[0] - ac[0], q[1] - ac[1], q[2] - ac[2]};
  const double ca[3] = {-ac[0], -ac[1], -ac[2]};
  in[0] = inside(ab, q, lab), in[1] = inside(bc, qb, lbc), in[2] = inside(ca, qc, lac);
  margin = 1e-6 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + longest);
  return true;
}
// The edge whose in[] is least.
int least_edge(const double in[3]) {
  return in[0] <= in[1] ? (in[0] <= in[2] ? 0 : 2) : (in[1] <= in[2] ? 1 : 2);
}
// The least of face_insides() less the margin (-infinity on a sliver).
double inside_face(const double p[3], const double* t, std::size_t stride, double s) {
  double in[3], margin;
  if (!face_insides(p, t, stride, s, in, margin)) return -std::numeric_limits<double>::infinity();
  return in[least_edge(in)] - margin;
}
}  // namespace

// face_insides() of one face at one point, computed once for the checks that need it.
[[gnu::always_inline]] inline bool ColliderSet::Feet::of(const double p[3], const double* t, std::size_t stride, double s) {
  if (!known) known = true, sliver = !face_insides(p, t, stride, s, in, margin);
  return !sliver;
}

bool ColliderSet::out_of_reach(std::size_t o, const double p[3], double radius_sq) const {
  const Object& ob = objects_[o];
  return ob.kept == 0 || box_dist_sq(ob.lo, ob.hi, p) > radius_sq;
}

namespace {
// The edge of triangle t that p's foot (`feet`, known) is beyond by the margin with p over its
// middle (all but kEdgeEnds at either end), else the one it is farthest beyond or nearest to.
int edge_over(const double p[3], const double* t, std::size_t stride, const ColliderSet::Feet& feet) {
  const double* in = feet.in;
  const double margin = feet.margin;
  const auto T = [t, stride](int c) { return t[static_cast<std::size_t>(c) * stride]; };
  const auto corner = [&](int j, int i) { return T(i) + (j == 1 ? T(3 + i) : (j == 2 ? T(6 + i) : 0.0)); };
  for (int k = 0; k < 3; ++k) {
    if (!(in[k] < -margin)) continue;
    double ee = 0.0, ew = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double e = corner((k + 1) % 3, i) - corner(k, i);
      ee += e * e, ew += e * (p[i] - corner(k, i));
    }
    if (ew >= kEdgeEnds * ee && ew <= (1.0 - kEdgeEnds) * ee) return k;
  }
  return least_edge(in);
}
}  // namespace

// Why an edge answer holds (see edge_clearance_of()): p is in front of both faces at the
// edge, with its feet beyond the edge on both (by the margin), so p - Q, Q its nearest point
// on the edge's line, lies in the cone of the two normals: p - Q = x n1 + y n2, x, y >= 0,
// x + y <= 2 d (normals within 120 degrees), d = |p - Q| the distance of both faces. Q is in
// the edge's middle (kEdgeEnds). A triangle out of the way of the edge has every point X behind both
// planes up to tau and >= zeta = kEdgeZeta of the edge's length from Q: |p - X|^2 >= d^2 + |X - Q|^2 -
// 2 (x + y) tau >= d^2 + zeta^2 - 4 d tau >= (d + tau)^2 when zeta^2 >= 6 d tau + tau^2. Every
// other triangle within d + tau of p is within the clearance of the edge's midpoint.
// Or p is over the strip along the edge: its foot F on one face's plane (height h <= d) is within
// mu of the edge's line (either side), so |p - Q|^2 = h^2 + mu^2 bounds the two faces' distance,
// and |p - X|^2 = |F - X|^2 + h^2 - 2 h n.(X - F) >= (zeta - mu)^2 + h^2 - 2 h tau, which is
// >= (sqrt(h^2 + mu^2) + tau)^2 when (zeta - mu)^2 >= 4 d tau + mu^2 + 2 mu tau + tau^2. (This
// is where a point crossing the edge is: its foot just past the edge on one face and a few
// microns inside the other, where the clear face's mu_min does not let that face answer.)
// So the answer is one of the two faces (m <= tau is far above the kernel's rounding): the
// better of their computed distances, then the lower index, as the search picks.
bool ColliderSet::edge_answer(std::size_t o, std::uint32_t slot, int k, const double p[3],
                              const double* t1, std::size_t stride1, double s1, double d1,
                              Feet& feet1, std::uint32_t nb, const double* t2, double s2,
                              double d2, Feet& feet2, double m) const {
  const double tau = kTau * objects_[o].scale;
  if (!(m <= tau) || !(s1 > 0.0) || !(s2 > 0.0)) return false;
  const double rho = static_cast<double>(eclear_at(o, slot, k, nb));
  if (!(rho > 0.0)) return false;
  int k2 = 0;
  while (k2 < 3 && adj_[3 * static_cast<std::size_t>(nb) + static_cast<std::size_t>(k2)] != static_cast<std::int32_t>(slot)) ++k2;
  if (k2 == 3) return false;
  if (!feet1.of(p, t1, stride1, s1) || !feet2.of(p, t2, kBlock, s2)) return false;
  const bool cone = feet1.in[k] < -feet1.margin && feet2.in[k2] < -feet2.margin;
  // The strip's mu: the nearer foot's distance from the edge's line, and its rounding.
  const double mu = std::min(std::abs(feet1.in[k]) + feet1.margin, std::abs(feet2.in[k2]) + feet2.margin);
  const auto T = [t1, stride1](int c) { return t1[static_cast<std::size_t>(c) * stride1]; };
  const auto corner = [&](int j, int i) {  // coordinate i of corner j of the first face
    return T(i) + (j == 1 ? T(3 + i) : (j == 2 ? T(6 + i) : 0.0));
  };
  const int j0 = k, j1 = (k + 1) % 3;
  double e[3], w[3], mid[3], ee = 0.0, ew = 0.0;
  for (int i = 0; i < 3; ++i) {
    e[i] = corner(j1, i) - corner(j0, i), w[i] = p[i] - corner(j0, i);
    mid[i] = 0.5 * (corner(j0, i) + corner(j1, i));
    ee += e[i] * e[i], ew += e[i] * w[i];
  }
  const double u = ew / ee, len = std::sqrt(ee), zeta = kEdgeZeta * len;
  if (!(u >= kEdgeEnds + 1e-9 && u <= 1.0 - kEdgeEnds - 1e-9)) return false;
  const double d = std::max(d1, d2) + m;
  if (!(d <= 2.0 * objects_[o].scale)) return false;
  const bool in_cone = cone && zeta * zeta >= 6.0 * d * tau + tau * tau;
  if (!in_cone && !(mu < zeta && (zeta - mu) * (zeta - mu) >= 4.0 * d * tau + mu * mu + 2.0 * mu * tau + tau * tau))
    return false;
  const double pm = std::sqrt((p[0] - mid[0]) * (p[0] - mid[0]) + (p[1] - mid[1]) * (p[1] - mid[1]) +
                              (p[2] - mid[2]) * (p[2] - mid[2]));
  return pm + d + tau + m < rho;
}

namespace {
// Whether triangle g (corners g[0..2]) stays out of the way of points over the face of T (corner
// a, unit normal n, corners t2[0..2] in the plane frame u, w at a) and in front of it: g lies
// behind T's plane by at least tau (case a: a point at height h is >= h + tau from it), or
// within tau of it but on no part of it in front by more than tau, with its shadow on the plane
// separated from T by a line up to tau (case b: a point over the face, whose foot is mu inside
// T, is >= sqrt((h - tau)^2 + (mu - tau)^2) from it). See ColliderSet::clear_radius().
bool out_of_the_way(const double a[3], const double n[3], const double u[3], const double w[3],
                    const double t2[3][2], const Eigen::Vector3d g[3], double tau) {
  double g2[3][2], lowest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const double v[3] = {g[i].x() - a[0], g[i].y() - a[1], g[i].z() - a[2]};
    const double h = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    lowest = std::min(lowest, -h);
    g2[i][0] = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    g2[i][1] = w[0] * v[0] + w[1] * v[1] + w[2] * v[2];
  }
  if (lowest >= tau) return true;    // (a) behind the plane
  if (lowest < -tau) return false;   // in front of it somewhere
  // (b): a separating line among the edge normals of both (the separating axis theorem).
  const auto separated = [&](const double e0[2], const double e1[2]) {
    const double ex = e1[0] - e0[0], ey = e1[1] - e0[1], l = std::hypot(ex, ey);
    if (!(l > tau)) return false;
    const double nx = -ey / l, ny = ex / l;
    double t_lo = std::numeric_limits<double>::infinity(), t_hi = -t_lo, g_lo = t_lo, g_hi = -t_lo;
    for (int i = 0; i < 3; ++i) {
      const double pt = nx * t2[i][0] + ny * t2[i][1], pg = nx * g2[i][0] + ny * g2[i][1];
      t_lo = std::min(t_lo, pt), t_hi = std::max(t_hi, pt);
      g_lo = std::min(g_lo, pg), g_hi = std::max(g_hi, pg);
    }
    return t_hi <= g_lo + tau || g_hi <= t_lo + tau;
  };
  for (int i = 0; i < 3; ++i)
    if (separated(t2[i], t2[(i + 1) % 3]) || separated(g2[i], g2[(i + 1) % 3])) return true;
  return false;
}
constexpr int kClearanceTests = 512;  // triangles tested per triangle at most
}  // namespace


// The smallest distance from `centre` of a triangle of object o that `in_the_way(slot)`
// calls in the way (less tau and a rounding margin), nearest boxes first; +infinity when none.
// A box is not opened when it lies wholly behind every plane n.x <= tight of `planes` (n,
// tight, loose), or behind every n.x <= loose and at least `far_loose` from the centre: then
// none of its triangles can be in the way, the callers' tests say. After kClearanceTests
// triangles, the distance reached.
template <class InTheWay>
double ColliderSet::scan_in_the_way(std::size_t o, const double centre[3],
                                    const double (*planes)[5], int nplanes, double far_loose,
                                    InTheWay in_the_way) const {
  const Object& ob = objects_[o];
  const double tau = kTau * ob.scale;
  // Boxes in float (axes orthonormal to 1e-6): a margin far above float rounding both ways.
  const float cmax = static_cast<float>(std::max({std::abs(centre[0]), std::abs(centre[1]), std::abs(centre[2])}));
  const float slack = 4e-6f * (cmax + static_cast<float>(ob.scale));
  const float pf[3] = {static_cast<float>(centre[0]), static_cast<float>(centre[1]), static_cast<float>(centre[2])};
  double rho = std::numeric_limits<double>::infinity();
  int tested = 0;
  // Nearest first (a heap by box distance), so that after the budget the distance reached is
  // the radius that was searched.
  // A fixed heap (queries never allocate): when full, what cannot be pushed bounds rho.
  constexpr int kHeap = 1024;
  StackEntry heap[kHeap];
  int size = 0;
  const auto farther = [](const StackEntry& x, const StackEntry& y) { return x.d2 > y.d2; };
  heap[size++] = StackEntry{ob.root4, 0.0f};
  while (size > 0) {
    std::pop_heap(heap, heap + size, farther);
    const StackEntry it = heap[--size];
    const double it_d = static_cast<double>(it.d2);  // here: a distance, not squared
    if (it_d >= rho) break;
    if ((it.ref & 7u) != 0) {  // a leaf
      if (tested >= kClearanceTests) {  // every untested triangle is at least this far
        rho = it_d;
        break;
      }
      for (std::uint32_t g = it.ref >> 3, end = g + (it.ref & 7u); g < end; ++g) {
        if (orig_[g] < 0) continue;
        ++tested;
        if (!in_the_way(g)) continue;
        double s_unused;
        const double dist = std::sqrt(detail::closest_sq<kBlock>(centre, tri_ptr(g), s_unused));
        rho = std::min(rho, dist * (1.0 - 1e-9) - tau);
      }
      continue;
    }
    const Node4& nd = nodes4_[it.ref >> 3];
    const v4f q0 = pf[0] - load4(nd.c[0]), q1 = pf[1] - load4(nd.c[1]), q2 = pf[2] - load4(nd.c[2]);
    const v4f h0 = load4(nd.h[0]), h1 = load4(nd.h[1]), h2 = load4(nd.h[2]);
    const v4f a0 = load4(nd.a[0]), a1 = load4(nd.a[1]), a2 = load4(nd.a[2]);
    const v4f a3 = load4(nd.a[3]), a4 = load4(nd.a[4]), a5 = load4(nd.a[5]);
    const v4f a6 = load4(nd.a[6]), a7 = load4(nd.a[7]), a8 = load4(nd.a[8]);
    const v4f e0 = pos(vabs(a0 * q0 + a1 * q1 + a2 * q2) - h0);
    const v4f e1 = pos(vabs(a3 * q0 + a4 * q1 + a5 * q2) - h1);
    const v4f e2 = pos(vabs(a6 * q0 + a7 * q1 + a8 * q2) - h2);
    const v4f d2 = e0 * e0 + e1 * e1 + e2 * e2;
    const v4f margin = slack + 1e-5f * (h0 + h1 + h2);
    v4f tight = {1.0f, 1.0f, 1.0f, 1.0f}, loose = tight;
    for (int pl = 0; pl < nplanes; ++pl) {
      const float nf[3] = {static_cast<float>(planes[pl][0]), static_cast<float>(planes[pl][1]),
                           static_cast<float>(planes[pl][2])};
      const v4f support = nf[0] * load4(nd.c[0]) + nf[1] * load4(nd.c[1]) + nf[2] * load4(nd.c[2]) +
                          h0 * vabs(a0 * nf[0] + a1 * nf[1] + a2 * nf[2]) +
                          h1 * vabs(a3 * nf[0] + a4 * nf[1] + a5 * nf[2]) +
                          h2 * vabs(a6 * nf[0] + a7 * nf[1] + a8 * nf[2]);
      tight = support + margin <= static_cast<float>(planes[pl][3]) ? tight : v4f{};
      loose = support + margin <= static_cast<float>(planes[pl][4]) ? loose : v4f{};
    }
    for (int k = 0; k < 4; ++k) {
      if (nd.h[0][k] < 0.0f) continue;  // an empty lane
      const float dk = std::max(std::sqrt(d2[k]) * (1.0f - 1e-5f) - margin[k], 0.0f);
      if (tight[k] > 0.0f || (loose[k] > 0.0f && static_cast<double>(dk) >= far_loose))
        continue;  // none in the way
      if (static_cast<double>(dk) >= rho) continue;
      if (size == kHeap) {
        rho = std::min(rho, static_cast<double>(dk));
        continue;
      }
      heap[size++] = StackEntry{nd.child[k], dk};
      std::push_heap(heap, heap + size, farther);
    }
  }
  return rho;
}

namespace {
float clearance_float(double rho) {
  return rho == std::numeric_limits<double>::infinity() ? std::numeric_limits<float>::infinity()
                                                        : std::max(round_down(rho), 0.0f);
}
// The corners of a stored triangle (A, A + AB, A + AC).
void stored_corners(const detail::Tri& t, Eigen::Vector3d c[3]) {
  c[0] = Eigen::Vector3d(t.ax, t.ay, t.az);
  c[1] = c[0] + Eigen::Vector3d(t.bx, t.by, t.bz);
  c[2] = c[0] + Eigen::Vector3d(t.cx, t.cy, t.cz);
}
// Distance between segments p0-p1 and q0-q1 (Ericson, Real-Time Collision Detection 5.1.9).
double segment_distance(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                        const Eigen::Vector3d& q0, const Eigen::Vector3d& q1) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 1e-300 && e <= 1e-300) return r.norm();
  if (a <= 1e-300) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-300) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) t = 0.0, s = std::clamp(-c / a, 0.0, 1.0);
      else if (t > 1.0) t = 1.0, s = std::clamp((b - c) / a, 0.0, 1.0);
    }
  }
  return ((p0 + s * d1) - (q0 + t * d2)).norm();
}
}  // namespace

float ColliderSet::clearance_of(std::size_t o, std::uint32_t slot) const {
  const double tau = kTau * objects_[o].scale;
  const detail::Tri tri = tri_at(slot);
  Eigen::Vector3d c[3];
  stored_corners(tri, c);
  const double a[3] = {tri.ax, tri.ay, tri.az}, n[3] = {tri.nx, tri.ny, tri.nz};
  const Eigen::Vector3d uu = (c[1] - c[0]).normalized();
  const Eigen::Vector3d ww = Eigen::Vector3d(n[0], n[1], n[2]).cross(uu);
  const double u[3] = {uu.x(), uu.y(), uu.z()}, w[3] = {ww.x(), ww.y(), ww.z()};
  double t2[3][2];
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = c[i] - c[0];
    t2[i][0] = uu.dot(v), t2[i][1] = ww.dot(v);
  }
  // A box wholly behind the plane by tau holds only triangles out of the way by case (a). One
  // behind it up to loose = kLooseDepth of the coordinates and far from A holds only triangles
  // whose points within loose of the plane cast their shadows >= lambda beside the face (the
  // face is within `longest` of A): a point over the face at height h in [loose, 2 scale] is
  // >= sqrt((h - loose)^2 + lambda^2) >= h + tau from them (clear_radius() keeps h there).
  const double scale = objects_[o].scale, loose = kLooseDepth * scale;
  const double longest = std::max({(c[1] - c[0]).norm(), (c[2] - c[0]).norm(), (c[2] - c[1]).norm()});
  const double far = longest + std::sqrt(2.0 * (2.0 * scale) * (tau + loose)) + loose;
  const double na = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
  const double planes[1][5] = {{n[0], n[1], n[2], na - tau, na + loose}};
  return clearance_float(scan_in_the_way(o, a, planes, 1, far, [&](std::uint32_t g) {
    if (g == slot) return false;
    Eigen::Vector3d gc[3];
    stored_corners(tri_at(g), gc);
    if (out_of_the_way(a, n, u, w, t2, gc, tau)) return false;
    for (int i = 0; i < 3; ++i)
      if (n[0] * gc[i].x() + n[1] * gc[i].y() + n[2] * gc[i].z() > na + loose) return true;
    double s_unused;
    return !(std::sqrt(detail::closest_sq<kBlock>(a, tri_ptr(g), s_unused)) >= far);
  }));
}

// The clearance of the edge between slot's corners k, k + 1 and its neighbour nb, around the
// edge's midpoint: every other triangle that reaches within it lies behind both faces' planes
// (up to tau) and at least kEdgeZeta of the edge's length from its middle (kEdgeEnds). 0 when the edge is
// not convex (a face in front of the other's plane, or normals more than 120 degrees apart).
// See ColliderSet::edge_answer().
float ColliderSet::edge_clearance_of(std::size_t o, std::uint32_t slot, int k, std::uint32_t nb) const {
  const double tau = kTau * objects_[o].scale;
  const detail::Tri t1 = tri_at(slot), t2 = tri_at(nb);
  Eigen::Vector3d c1[3], c2[3];
  stored_corners(t1, c1);
  stored_corners(t2, c2);
  const Eigen::Vector3d n1(t1.nx, t1.ny, t1.nz), n2(t2.nx, t2.ny, t2.nz);
  const double o1 = n1.dot(c1[0]), o2 = n2.dot(c2[0]);
  if (n1.dot(n2) < -0.5) return 0.0f;
  for (int i = 0; i < 3; ++i)
    if (n1.dot(c2[i]) > o1 + tau || n2.dot(c1[i]) > o2 + tau) return 0.0f;
  const Eigen::Vector3d v0 = c1[k], v1 = c1[(k + 1) % 3], mid = 0.5 * (v0 + v1);
  const double len = (v1 - v0).norm(), zeta = kEdgeZeta * len;
  const Eigen::Vector3d s0 = v0 + kEdgeEnds * (v1 - v0), s1 = v1 - kEdgeEnds * (v1 - v0);
  // Far from the edge a looser depth does: behind both planes up to loose and >= lambda from
  // the edge, |p - X|^2 >= d^2 + lambda^2 - 4 d loose >= (d + tau)^2 for d <= 2 scale.
  const double scale = objects_[o].scale, loose = kLooseDepth * scale;
  const double lambda = std::max(zeta, std::sqrt(4.0 * (2.0 * scale) * loose + 2.0 * (2.0 * scale) * tau + tau * tau));
  const double far = 0.5 * len + lambda;
  // A box behind both planes by zeta holds only triangles out of the way (|X - Q| >= a depth).
  const double planes[2][5] = {{n1.x(), n1.y(), n1.z(), o1 - zeta, o1 + loose},
                               {n2.x(), n2.y(), n2.z(), o2 - zeta, o2 + loose}};
  const double centre[3] = {mid.x(), mid.y(), mid.z()};
  return clearance_float(scan_in_the_way(o, centre, planes, 2, far, [&](std::uint32_t g) {
    if (g == slot || g == nb) return false;
    Eigen::Vector3d gc[3];
    stored_corners(tri_at(g), gc);
    double deep1 = std::numeric_limits<double>::infinity(), deep2 = deep1;
    for (int i = 0; i < 3; ++i) {
      const double h1 = n1.dot(gc[i]) - o1, h2 = n2.dot(gc[i]) - o2;
      deep1 = std::min(deep1, -h1), deep2 = std::min(deep2, -h2);
    }
    if (deep1 < -loose || deep2 < -loose) return true;
    if (deep1 < -tau || deep2 < -tau) {  // only the looser depth: far from the edge?
      double s_far;
      return !(std::sqrt(detail::closest_sq<kBlock>(centre, tri_ptr(g), s_far)) >= far);
    }
    // Cheap first: a point of the edge is on both planes, so |X - Q| >= either depth of X;
    // and every point of the edge is within half its length of the midpoint.
    if (std::max(deep1, deep2) >= zeta) return false;
    double s_unused;
    if (std::sqrt(detail::closest_sq<kBlock>(centre, tri_ptr(g), s_unused)) >= 0.5 * len + zeta)
      return false;
    const double e0[3] = {s0.x(), s0.y(), s0.z()}, e1[3] = {s1.x(), s1.y(), s1.z()};
    double dist = std::min(std::sqrt(detail::closest_sq<kBlock>(e0, tri_ptr(g), s_unused)),
                    std::sqrt(detail::closest_sq<kBlock>(e1, tri_ptr(g), s_unused)));
    for (int i = 0; i < 3; ++i) dist = std::min(dist, segment_distance(s0, s1, gc[i], gc[(i + 1) % 3]));
    return !(dist >= zeta);
  }));
}

void ColliderSet::prepare_clearances() const {
  for (std::size_t o = 0; o < objects_.size(); ++o)
    for (std::uint32_t slot = objects_[o].tri_begin; slot < objects_[o].tri_end; ++slot) {
      if (orig_[slot] < 0) continue;
      clear_at(o, slot);
      for (int k = 0; k < 3; ++k) {
        const std::int32_t nb = adj_[3 * static_cast<std::size_t>(slot) + static_cast<std::size_t>(k)];
        if (nb >= 0) eclear_at(o, slot, k, static_cast<std::uint32_t>(nb));
      }
    }
}

float ColliderSet::clear_at(std::size_t o, std::uint32_t slot) const {
  std::atomic_ref<float> c(clear_[slot]);
  float v = c.load(std::memory_order_relaxed);
  if (std::isnan(v)) {  // first use: compute (two threads may both; they store the same)
    v = clearance_of(o, slot);
    c.store(v, std::memory_order_relaxed);
  }
  return v;
}

float ColliderSet::eclear_at(std::size_t o, std::uint32_t slot, int k, std::uint32_t nb) const {
  std::atomic_ref<float> c(eclear_[3 * static_cast<std::size_t>(slot) + static_cast<std::size_t>(k)]);
  float v = c.load(std::memory_order_relaxed);
  if (std::isnan(v)) {
    // One figure per edge, computed from its lower slot's side (the same whichever side
    // asks first), stored on both sides.
    std::size_t k2 = 0;
    while (k2 < 3 && adj_[3 * static_cast<std::size_t>(nb) + k2] != static_cast<std::int32_t>(slot)) ++k2;
    v = slot < nb || k2 == 3 ? edge_clearance_of(o, slot, k, nb)
                             : edge_clearance_of(o, nb, static_cast<int>(k2), slot);
    c.store(v, std::memory_order_relaxed);
    if (k2 < 3) std::atomic_ref<float>(eclear_[3 * static_cast<std::size_t>(nb) + k2]).store(v, std::memory_order_relaxed);
  }
  return v;
}


void ColliderSet::compute_adjacency(std::size_t o) {
  const Object& ob = objects_[o];
  // Vertices by position: equal coordinates get one id.
  const auto nv = static_cast<std::size_t>(ob.vertices.cols());
  std::vector<std::uint32_t> order(nv), id(nv);
  for (std::size_t i = 0; i < nv; ++i) order[i] = static_cast<std::uint32_t>(i);
  const auto less = [&](std::uint32_t a, std::uint32_t b) {
    const auto va = ob.vertices.col(a), vb = ob.vertices.col(b);
    return std::lexicographical_compare(va.data(), va.data() + 3, vb.data(), vb.data() + 3);
  };
  std::sort(order.begin(), order.end(), less);
  for (std::size_t i = 0, next = 0; i < nv; ++i) {
    if (i > 0 && less(order[i - 1], order[i])) ++next;
    id[order[i]] = static_cast<std::uint32_t>(next);
  }
  objects_[o].weld = id;  // (corners of a closed object's sharp features: outside_at_feature())
  // Every edge of every kept triangle, keyed by its two corner ids; an edge of exactly two
  // triangles joins them.
  struct Half {
    std::uint32_t lo, hi, slot, edge;
  };
  std::vector<Half> halves;
  halves.reserve(3 * ob.kept);
  for (std::uint32_t slot = ob.tri_begin; slot < ob.tri_end; ++slot) {
    if (orig_[slot] < 0) continue;
    const auto t = static_cast<std::size_t>(orig_[slot]);
    for (std::uint32_t e = 0; e < 3; ++e) {
      const std::uint32_t a = id[ob.indices[3 * t + e]], b = id[ob.indices[3 * t + (e + 1) % 3]];
      halves.push_back(Half{std::min(a, b), std::max(a, b), slot, e});
    }
  }
  std::sort(halves.begin(), halves.end(), [](const Half& x, const Half& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.slot < y.slot);
  });
  for (std::size_t i = 0; i < halves.size();) {
    std::size_t j = i + 1;
    while (j < halves.size() && halves[j].lo == halves[i].lo && halves[j].hi == halves[i].hi) ++j;
    if (j - i != 2) objects_[o].open = true;  // a rim (or a non-manifold edge)
    if (j - i == 2 && halves[i].slot != halves[i + 1].slot) {
      adj_[3 * halves[i].slot + halves[i].edge] = static_cast<std::int32_t>(halves[i + 1].slot);
      adj_[3 * halves[i + 1].slot + halves[i + 1].edge] = static_cast<std::int32_t>(halves[i].slot);
    }
    i = j;
  }
}

double ColliderSet::contact_distance(const Eigen::Vector3d& p, const ColliderHit& h) const {
  if (!h.valid() || h.object < 0 || static_cast<std::size_t>(h.object) >= objects_.size())
    return std::numeric_limits<double>::quiet_NaN();
  const auto o = static_cast<std::size_t>(h.object);
  const Object& ob = objects_[o];
  if (!(h.signed_distance < 0.0) || ob.open) return h.signed_distance;
  const std::int32_t slot = ob.input_to_kept.at(static_cast<std::size_t>(h.triangle));
  if (slot < 0) return h.signed_distance;
  // as accumulate_penalty()'s respond_at() decides it
  const double* t = tri_ptr(static_cast<std::uint32_t>(slot));
  double d = 0.0, dir[3];
  TriangleRegion region;
  if (detail::edge_contact(p.data(), t, kBlock, false, d, dir, region) == 2 &&
      outside_at_feature(o, p.data(), t, kBlock, region, dir))
    return d;
  return h.signed_distance;
}

bool ColliderSet::outside_at_feature(std::size_t o, const double p[3], const double* t, std::size_t stride,
                                     TriangleRegion region, const double dir[3]) const {
  const Object& ob = objects_[o];
  if (ob.open || ob.weld.empty() || region == TriangleRegion::Face) return false;
  // The answer's slot: from where its data is, or (a cache's copy) among the nearest
  // triangles, the one with the same 12 numbers.
  std::uint32_t slot = std::numeric_limits<std::uint32_t>::max();
  const auto same = [&](std::uint32_t sl) {
    const double* u = tri_ptr(sl);
    for (std::size_t k = 0; k < 12; ++k)
      if (!(u[k * kBlock] == t[k * stride])) return false;
    return true;
  };
  if (stride == kBlock && t >= tri_.data() && t < tri_.data() + tri_.size()) {
    const auto off = static_cast<std::size_t>(t - tri_.data());
    if (off % (12 * kBlock) < kBlock)
      slot = static_cast<std::uint32_t>(off / (12 * kBlock) * kBlock + off % (12 * kBlock));
  } else {
    double s;
    const double d2 = detail::closest_sq<1>(p, t, s);
    std::uint32_t slots[kMaxCandidates];
    double d2s[kMaxCandidates], others = 0.0;
    const std::size_t n =
        query_nearest(o, p, d2 * (1.0 + 1e-9) + 1e-300, QueryMethod::Bvh, kMaxCandidates, {}, slots, d2s, others);
    for (std::size_t j = 0; j < n; ++j)
      if (same(slots[j])) slot = slots[j];
  }
  if (slot < ob.tri_begin || slot >= ob.tri_end || orig_[slot] < 0) return false;
  const auto normal = [&](std::uint32_t sl, double n[3]) {
    const double* u = tri_ptr(sl);
    for (std::size_t k = 0; k < 3; ++k) n[k] = u[(9 + k) * kBlock];
  };
  // The angle-weighted pseudonormal N at the closest point Q (Baerentzen and Aanaes, 2005): on
  // an edge the sum of its two faces' normals, at a corner the sum over the faces around it of
  // each face's angle there times its normal. P is outside the closed mesh iff (P - Q).N > 0.
  double N[3] = {0.0, 0.0, 0.0}, n[3];
  const auto add = [&](std::uint32_t sl, double weight) {
    normal(sl, n);
    for (std::size_t k = 0; k < 3; ++k) N[k] += weight * n[k];
  };
  const auto corner_id = [&](std::uint32_t sl, std::uint32_t c) {
    return ob.weld[ob.indices[3 * static_cast<std::size_t>(orig_[sl]) + c]];
  };
  const auto angle = [&](std::uint32_t sl, std::uint32_t c) {
    const detail::Tri tr = tri_at(sl);
    const Eigen::Vector3d a(tr.ax, tr.ay, tr.az), ab(tr.bx, tr.by, tr.bz), ac(tr.cx, tr.cy, tr.cz);
    const Eigen::Vector3d corners[3] = {a, a + ab, a + ac};
    const Eigen::Vector3d u = corners[(c + 1) % 3] - corners[c], w = corners[(c + 2) % 3] - corners[c];
    return std::atan2(u.cross(w).norm(), u.dot(w));
  };
  if (region == TriangleRegion::EdgeAB || region == TriangleRegion::EdgeBC || region == TriangleRegion::EdgeCA) {
    const std::uint32_t k = region == TriangleRegion::EdgeAB ? 0u : region == TriangleRegion::EdgeBC ? 1u : 2u;
    const std::int32_t nb = adj_[3 * std::size_t{slot} + k];
    if (nb < 0) return false;
    add(slot, 1.0);
    add(static_cast<std::uint32_t>(nb), 1.0);
  } else {
    // Around the corner: across the edge leaving it, into the neighbour, and on across that
    // neighbour's other edge at the corner, until back at the start.
    const std::uint32_t c0 = region == TriangleRegion::VertexA ? 0u : region == TriangleRegion::VertexB ? 1u : 2u;
    const std::uint32_t v = corner_id(slot, c0);
    std::uint32_t sl = slot, c = c0, edge = c0;  // edge c joins corners c and c + 1
    for (int steps = 0;; ++steps) {
      if (steps > 4096) return false;
      add(sl, angle(sl, c));
      const std::uint32_t w = corner_id(sl, edge == c ? (c + 1) % 3 : (c + 2) % 3);  // the edge's other end
      const std::int32_t nb = adj_[3 * std::size_t{sl} + edge];
      if (nb < 0) return false;
      sl = static_cast<std::uint32_t>(nb);
      if (sl == slot) break;
      c = 3;
      for (std::uint32_t j = 0; j < 3; ++j)
        if (corner_id(sl, j) == v) c = j;
      if (c == 3) return false;
      // the shared edge is edge c (c -> c + 1) when its other end is w; leave by the other one
      edge = corner_id(sl, (c + 1) % 3) == w ? (c + 2) % 3 : c;
    }
  }
  const double dot = dir[0] * N[0] + dir[1] * N[1] + dir[2] * N[2];
  return dot > 1e-12 * std::sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
}

double ColliderSet::clearance(std::size_t o, std::size_t t) const {
  const std::int32_t slot = objects_.at(o).input_to_kept.at(t);
  return slot < 0 ? 0.0 : static_cast<double>(clear_at(o, static_cast<std::uint32_t>(slot)));
}

// Why a clear face certificate holds (see clearance()): within r of p, a point P stays over
// the face with its foot at least mu_min inside every edge, at a height h in [tau, reach], and
// every triangle that could be as near as the face (within h + tau of P) lies within the
// clearance of corner A, so it is out of the way: (a) it is >= h + tau from P; (b)
// sqrt((h - tau)^2 + (mu - tau)^2) >= h + tau when (mu - tau)^2 >= 4 h tau, which mu_min
// below gives for h <= reach. tau = kTau of the coordinates >= the rounding margin m (checked)
// is far above the kernel's rounding, so the face strictly wins the computed comparison too,
// and its computed distance is the face branch's |n.(P - A)|: the same bits as the search.
double ColliderSet::clear_radius(std::size_t o, std::uint32_t slot, const double p[3],
                                 const double* t, std::size_t stride, double d, double s,
                                 double m, double reach, Feet& feet) const {
  const double tau = kTau * objects_[o].scale, loose = kLooseDepth * objects_[o].scale;
  if (!(m <= tau) || !(s > 0.0) || !(reach <= 2.0 * objects_[o].scale)) return -1.0;
  const double rho = static_cast<double>(clear_at(o, slot));
  if (!(rho > 0.0)) return -1.0;
  const double mu_min = tau + 2.0 * std::sqrt(reach * tau);
  if (!feet.of(p, t, stride, s)) return -1.0;
  const double inside = std::min({feet.in[0], feet.in[1], feet.in[2]}) - feet.margin;
  const double r = std::min(inside - mu_min, std::min(s - 2.0 * loose, reach - d - m));
  if (!(r > 0.0)) return r;
  const auto T = [t, stride](int k) { return t[static_cast<std::size_t>(k) * stride]; };
  const double pa = std::sqrt((p[0] - T(0)) * (p[0] - T(0)) + (p[1] - T(1)) * (p[1] - T(1)) +
                              (p[2] - T(2)) * (p[2] - T(2)));
  // Every P within r: |P - A| + h(P) + tau <= |p - A| + d + 2 r + tau must stay within rho.
  return std::min(r, 0.5 * (rho - pa - d - tau - m));
}

// The plane certificate of the answer, triangle t (component k at t[k * stride]) at distance
// d (= |s|, s the plane distance) from p. Made only when p is over the face's inside, by a
// margin (1e-6 of the coordinates) far beyond the kernel's rounding, on a triangle that is
// not a sliver: then every point within r of p takes the kernel's face branch, whose
// distance is |n.(p - a)|. r also keeps the answer within reach and strictly nearer than
// every other triangle: `loser`, the other evaluated candidate's distance (or infinity);
// the next (up to 3) candidates from `next` on by their exact distance where their bound
// (less `moved`, as the certificate says) is too close to tell, then by that bound; the
// rest by the entry's bound of all others. m: the certificates' rounding margin.
bool ColliderSet::make_plane(const double p[3], ContactCache& cache,
                             std::size_t ei, const double* t, std::size_t stride, double d,
                             double s, std::int32_t next, double loser, double moved, double m,
                             double reach) const {
  ContactCache::Plane& pl = cache.entries[ei].plane;
  const auto T = [t, stride](int k) { return t[static_cast<std::size_t>(k) * stride]; };
  const double n[3] = {T(9), T(10), T(11)};
  double r = std::min(inside_face(p, t, stride, s), reach - d - m);
  if (!(r > 0.0)) return false;
  // Every other triangle must stay farther than d + 2 r (+ margins).
  const ContactCache::Entry& e = cache.entries[ei];
  const std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
  const float* cl = cache.lower.data() + ei * cache.candidates();
  double others = std::min(loser, e.others_lb - moved) - m;
  std::int32_t c = next;
  for (; c < std::min(e.count, next + 3); ++c) {  // at most 3: near many ties it cannot last
    const double lb = static_cast<double>(cl[c]) - moved - m;
    if (lb >= d + 2.0 * (r + m) || lb >= others) break;  // the rest are bounded by lb
    double s_c;
    others = std::min(others, std::sqrt(detail::closest_sq<kBlock>(p, tri_ptr(cs[c]), s_c)) - m);
  }
  if (c < e.count) others = std::min(others, static_cast<double>(cl[c]) - moved - m);
  r = std::min(r, (others - d) * 0.5 - m);
  if (!(r > 0.0)) return false;
  pl.a[0] = T(0), pl.a[1] = T(1), pl.a[2] = T(2);
  pl.n[0] = n[0], pl.n[1] = n[1], pl.n[2] = n[2];
  return store_plane(pl, cache.epoch, p, r, true);
}

bool ColliderSet::make_far(const double p[3], ContactCache& cache, std::size_t ei, double d, double s,
                           std::int32_t next, double loser, double loser_s, double moved, double m,
                           double band) const {
  // Within r of p every distance and plane distance changes by at most r. The answer stays
  // farther than band, and a triangle can become the nearest only if it is now within
  // d + 2 r: each such one must keep p in front of its plane (s_T > r), or be kept out
  // (r < (d_T - d) / 2). With the rounding margin m on every figure.
  double r = std::min(d - band, s) - 2.0 * m;
  const auto keep = [&](double d_t, double s_t) { r = std::min(r, std::max(s_t, 0.5 * (d_t - d)) - 2.0 * m); };
  if (loser < std::numeric_limits<double>::infinity()) keep(loser, loser_s);
  const ContactCache::Entry& e = cache.entries[ei];
  const std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
  const float* cl = cache.lower.data() + ei * cache.candidates();
  double others = e.others_lb - moved - m;  // every triangle not in the list
  std::int32_t c = next;
  for (; c < std::min(e.count, next + 3); ++c) {  // at most 3 more, by their exact figures
    const double lb = static_cast<double>(cl[c]) - moved - m;
    if (!(r > 0.0) || lb >= d + 2.0 * (r + m)) break;  // the rest are bounded by lb
    double s_c;
    const double d_c = std::sqrt(detail::closest_sq<kBlock>(p, tri_ptr(cs[c]), s_c));
    keep(d_c - m, s_c);
  }
  if (c < e.count) others = std::min(others, static_cast<double>(cl[c]) - moved - m);
  r = std::min(r, 0.5 * (others - d) - m);
  if (!(r > 0.0)) return false;
  return store_plane(cache.entries[ei].plane, cache.epoch, p, r, false);
}

ColliderHit ColliderSet::query_cached(std::size_t o, const double p[3], double radius_sq,
                                      QueryMethod method, ContactCache& cache, std::size_t ei,
                                      bool& certified) const {
  return query_cached_from(o, p, radius_sq, method, cache, ei, certified, Evaluated{});
}

ColliderHit ColliderSet::query_cached_from(std::size_t o, const double p[3], double radius_sq,
                                           QueryMethod method, ContactCache& cache,
                                           std::size_t ei, bool& certified,
                                           const Evaluated& pre) const {
  ContactCache::Entry& e = cache.entries[ei];
  certified = false;
  if (e.count < 0) return renew_cached(o, p, radius_sq, method, cache, ei);
  const Object& ob = objects_[o];
  std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
  float* cl = cache.lower.data() + ei * cache.candidates();
  const bool use_copy = ob.kept > kCopyAbove;
  const double* first = cache.firsts.data() + 12 * ei;
  // Rounding of the computed distances, far below any useful gap.
  const double m = certificate_margin(p, ob.scale);
  const double moved = moved_from(p, e.x0);
  // Every candidate is now >= lower - moved away, every other triangle >= others_lb - moved.
  // Evaluate the candidates nearest first until the rest cannot win or tie (or reach).
  double best = std::numeric_limits<double>::infinity(), best_s = 0.0, stop = std::sqrt(radius_sq);
  double best_n[3] = {0.0, 0.0, 0.0};
  std::int32_t best_tri = std::numeric_limits<std::int32_t>::max();
  double dist[kMaxCandidates];  // distances of the evaluated candidates
  std::int32_t evaluated = 0;
  for (; evaluated < e.count; ++evaluated) {
    const std::int32_t c = evaluated;
    if (static_cast<double>(cl[c]) - moved - m > stop) break;
    double s, d2;
    const double* n;  // the normal's components at n[0], n[stride], n[2 stride]
    std::size_t stride;
    const bool known = c < pre.count;  // evaluated by certify_inline(), the same way
    if (c == 0 && use_copy) {
      d2 = known ? (s = pre.s[c], pre.d2[c]) : detail::closest_sq<1>(p, first, s);
      n = first + 9, stride = 1;
    } else {
      const double* t = tri_ptr(cs[c]);
      d2 = known ? (s = pre.s[c], pre.d2[c]) : detail::closest_sq<kBlock>(p, t, s);
      n = t + 9 * kBlock, stride = kBlock;
    }
    dist[c] = std::sqrt(d2);
    const std::int32_t idx = c == 0 ? e.tri_index : orig_[cs[c]];
    if (d2 <= radius_sq && better(d2, idx, best, best_tri)) {
      best = d2, best_tri = idx, best_s = s;
      best_n[0] = n[0], best_n[1] = n[stride], best_n[2] = n[2 * stride];
      stop = dist[c];
    }
  }
  if (!(stop + moved + m < e.others_lb)) return renew_cached(o, p, radius_sq, method, cache, ei);
  certified = true;
  ColliderHit hit;
  if (best_tri != std::numeric_limits<std::int32_t>::max()) {
    hit.object = static_cast<std::int32_t>(o);
    hit.triangle = best_tri;
    hit.distance_sq = best;
    hit.signed_distance = detail::signed_distance(best, best_s);
    hit.normal = Eigen::Vector3d(best_n[0], best_n[1], best_n[2]);
  }
  if (e.age < kMinAge) ++e.age;
  if (evaluated > e.settled && moved > 0.0) {
    // Move the certificate here: the same facts, measured from p. The evaluated candidates
    // get their distances now (so the next call evaluates only the near-ties), the others
    // and L lose what the point moved (and a rounding margin). Kept ascending. Only when
    // more candidates than the near-ties of the last move (`settled`) had to be evaluated:
    // a point at rest writes nothing, even on an edge between two triangles.
    e.x0[0] = p[0], e.x0[1] = p[1], e.x0[2] = p[2];
    e.others_lb -= moved + m;
    const std::uint32_t first_slot = e.count > 0 ? cs[0] : 0;
    for (std::int32_t c = 0; c < e.count; ++c) {
      const float lo = round_down(c < evaluated ? dist[c] - m
                                                : static_cast<double>(cl[c]) - moved - m);
      const std::uint32_t sl = cs[c];
      std::int32_t j = c;
      for (; j > 0 && cl[j - 1] > lo; --j) cl[j] = cl[j - 1], cs[j] = cs[j - 1];
      cl[j] = lo, cs[j] = sl;
    }
    std::int32_t ties = 0;
    while (ties < e.count && static_cast<double>(cl[ties]) - m <= stop) ++ties;
    e.settled = static_cast<std::uint8_t>(std::clamp(ties, 1, 255));
    if (e.count > 0 && cs[0] != first_slot) {
      e.tri_index = orig_[cs[0]];
      if (use_copy) {
        const detail::Tri t = tri_at(cs[0]);
        std::memcpy(cache.firsts.data() + 12 * ei, &t, sizeof t);
      }
    }
  }
  return hit;
}

[[gnu::always_inline]] inline bool ColliderSet::certify_inline(
    std::size_t o, const double p[3], double radius_sq, ContactCache& cache, std::size_t ei,
    bool& hit, double& signed_distance, double normal[3], Evaluated* pre, Answer* answer) const {
  ContactCache::Entry& e = cache.entries[ei];
  if (e.count < 0) return false;
  const bool records = radius_sq == cache.band_reach_sq;  // plane records hold for this reach
  const double band = cache.band;
  const Object& ob = objects_[o];
  // The same m, moved and comparisons as query_cached(): the same decisions.
  const double m = certificate_margin(p, ob.scale);
  const double moved = moved_from(p, e.x0);
  const double reach = std::sqrt(radius_sq);
  if (e.count == 0) {  // nothing was in reach: still none while L - moved stays beyond reach
    if (!(reach + moved + m < e.others_lb)) return false;
    hit = false;
    ContactCache::Plane& pl = cache.entries[ei].plane;
    if (records && plane_due(cache, e, pl) &&
        !store_plane(pl, cache.epoch, p, e.others_lb - moved - m - reach - m, false))
      plane_failed(e);
  } else {
    const float* cl = cache.lower.data() + ei * cache.candidates();
    if (static_cast<double>(cl[0]) - moved - m > reach) return false;
    // The corners are read in place (a Tri filled from either source was spilled to the
    // stack and read back, stalling).
    double s, d2;
    const double* n;
    std::size_t stride;
    bool face;  // the closest point is inside the face (else neither a clear face nor a plane)
    if (ob.kept > kCopyAbove) {
      const double* t = cache.firsts.data() + 12 * ei;
      d2 = detail::closest_sq<1>(p, t, s, face);
      n = t + 9, stride = 1;
    } else {
      const double* t = tri_ptr(cache.slots[ei * cache.candidates()]);
      d2 = detail::closest_sq<kBlock>(p, t, s, face);
      n = t + 9 * kBlock, stride = kBlock;
    }
    if (!(d2 <= radius_sq)) return false;
    double d = std::sqrt(d2);
    // A clear face needs the foot inside the face by a margin (1e-6 of the coordinates) far
    // beyond the kernel's rounding: outside the face branch clear_radius() cannot answer, and
    // a small collider skips it (a large one computes the feet for the walk).
    if (s > 0.0 && (face || ob.kept > kCopyAbove)) {
      // A clear face (see clear_radius()): the answer whatever the list says, and a record
      // that lasts while the point stays over the face, however near the other triangles tie.
      Feet feet;  // of the first candidate at p
      const std::uint32_t slot0 = cache.slots[ei * cache.candidates()];
      double r = clear_radius(o, slot0, p, n - 9 * stride, stride, d, s, m, reach, feet);
      if (!(r > 0.0) && feet.known && !feet.sliver && ob.kept > kCopyAbove) {
        // The point has left the face: the face across the edge it crossed, or that edge
        // (walk_on(); only on large colliders: on a fine mesh nearly equidistant triangles
        // tie within microns and lists die young; on a small one the list answers for less,
        // and it is moved along with the point, which an edge answer is not).
        const double* t = n - 9 * stride;
        const int walked = walk_on(o, p, radius_sq, reach, m, cache, ei, slot0, feet, d2, d, s, t, stride, r);
        if (walked == 2) {  // over the edge: t is the better of the two faces
          n = t + 9 * stride;
          hit = true;
          signed_distance = detail::signed_from(d, s);
          normal[0] = n[0], normal[1] = n[stride], normal[2] = n[2 * stride];
          if (answer) answer->tri = n - 9 * stride, answer->stride = stride;
          if (e.age < kMinAge) ++e.age;
          return true;
        }
        n = t + 9 * stride;  // walked == 1: the neighbour, with its record radius r
      }
      if (r > 0.0) {
        hit = true;
        signed_distance = detail::signed_from(d, s);
        normal[0] = n[0], normal[1] = n[stride], normal[2] = n[2 * stride];
        if (answer) answer->tri = n - 9 * stride, answer->stride = stride;
        ContactCache::Plane& pl = cache.entries[ei].plane;
        if (records && plane_due(cache, e, pl)) {
          pl.a[0] = n[-9 * static_cast<std::ptrdiff_t>(stride)];
          pl.a[1] = n[-8 * static_cast<std::ptrdiff_t>(stride)];
          pl.a[2] = n[-7 * static_cast<std::ptrdiff_t>(stride)];
          pl.n[0] = n[0], pl.n[1] = n[stride], pl.n[2] = n[2 * stride];
          if (!store_plane(pl, cache.epoch, p, r, true)) plane_failed(e);
        }
        if (e.age < kMinAge) ++e.age;
        return true;
      }
    }
    const bool alone = e.count == 1 || static_cast<double>(cl[1]) - moved - m > d;
    double loser = std::numeric_limits<double>::infinity();  // the other evaluated candidate
    double loser_s = 0.0;                                     // and its plane distance
    if (!alone) {
      // The second candidate may be as near (a point over an edge between two triangles, or
      // one whose second triangle is only a little farther): evaluate it too. (Leaving the
      // second case to query_cached(), which moves the certificate, cost 700 calls per step
      // while the skirt slid over the sphere: its gap was gone again one step later.)
      const double* t = tri_ptr(cache.slots[ei * cache.candidates() + 1]);
      const double d2a = d2, sa = s;  // the first candidate's, for query_cached_from()
      double s1;
      bool face1;
      const double d2b = detail::closest_sq<kBlock>(p, t, s1, face1);
      const std::int32_t idx1 = orig_[cache.slots[ei * cache.candidates() + 1]];
      if (d2b <= radius_sq && better(d2b, idx1, d2, e.tri_index)) {
        loser = d, loser_s = s;
        d2 = d2b, s = s1, n = t + 9 * kBlock, stride = kBlock, face = face1;
        d = std::sqrt(d2);
      } else {
        loser = std::sqrt(d2b), loser_s = s1;
      }
      if (e.count > 2 && !(static_cast<double>(cl[2]) - moved - m > d)) {
        // A third may tie (a point near a vertex of the collider): the full check goes on
        // from here instead of evaluating these two again (~750 calls per step while the
        // skirt_hires cloth slides over its sphere).
        if (pre) *pre = Evaluated{2, {d2a, d2b}, {sa, s1}};
        return false;
      }
    }
    // the other candidates and every other triangle stay farther: this is the answer
    if (!(d + moved + m < e.others_lb)) return false;
    hit = true;
    signed_distance = detail::signed_from(d, s);
    normal[0] = n[0], normal[1] = n[stride], normal[2] = n[2 * stride];
    if (answer) answer->tri = n - 9 * stride, answer->stride = stride;
    // The next calls can take a plane certificate (the loser: the other evaluated one): "no
    // force" beyond the band (which holds over edges too), else this face (only from inside
    // it: make_plane() fails elsewhere, as clear_radius() does).
    if (records && plane_due(cache, e, cache.entries[ei].plane) &&
        !(d > band && make_far(p, cache, ei, d, s, alone ? 1 : 2, loser, loser_s, moved, m, band)) &&
        !(face && make_plane(p, cache, ei, n - 9 * stride, stride, d, s, alone ? 1 : 2, loser, moved, m,
                             reach)))
      plane_failed(e);
  }
  if (e.age < kMinAge) ++e.age;
  return true;
}

// certify_inline()'s walk from the first candidate (slot0; its data t with stride, d2, d, s at
// p; `feet` known, not a sliver: the foot beyond an edge or too near one for a clear face): 1
// when the face across the edge the point is over answers by its clear face (it becomes the
// entry's first candidate; d2, d, s, t, stride and r are its), 2 when the edge answers (d2,
// d, s, t, stride: the better face), else 0.
int ColliderSet::walk_on(std::size_t o, const double p[3], double radius_sq, double reach, double m,
                         ContactCache& cache, std::size_t ei, std::uint32_t slot0, Feet& feet,
                         double& d2, double& d, double& s, const double*& t, std::size_t& stride,
                         double& r) const {
  const int beyond = edge_over(p, t, stride, feet);
  if (feet.in[beyond] > feet.margin) {
    // The foot is still inside the face: only the strip along that edge can answer, within
    // kEdgeZeta of its length (the clear face failed for another reason otherwise: the point
    // too near the plane, or another triangle within the clearance).
    const auto T = [t, stride](int c) { return t[static_cast<std::size_t>(c) * stride]; };
    const auto edge = [&](int i) {  // coordinate i of the edge's vector
      return beyond == 0 ? T(3 + i) : (beyond == 1 ? T(6 + i) - T(3 + i) : -T(6 + i));
    };
    const double ee = edge(0) * edge(0) + edge(1) * edge(1) + edge(2) * edge(2);
    if (!(feet.in[beyond] * feet.in[beyond] < kEdgeZeta * kEdgeZeta * ee)) return 0;
  }
  const std::int32_t nb = adj_[3 * static_cast<std::size_t>(slot0) + static_cast<std::size_t>(beyond)];
  if (nb < 0) return 0;
  const auto nbu = static_cast<std::uint32_t>(nb);
  const double* tn = tri_ptr(nbu);
  double sn;
  const double d2n = detail::closest_sq<kBlock>(p, tn, sn);
  if (!(d2n <= radius_sq && sn > 0.0)) return 0;
  const double dn = std::sqrt(d2n);
  Feet feet_n;
  ContactCache::Entry& e = cache.entries[ei];
  const double rn = clear_radius(o, nbu, p, tn, kBlock, dn, sn, m, reach, feet_n);
  if (rn > 0.0) {
    // It is the answer. It becomes the entry's first candidate, in a list that certifies
    // nothing by itself (every other triangle >= 0 away): the next calls try its clear face
    // first; when that fails, a search makes a real list.
    std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
    float* cw = cache.lower.data() + ei * cache.candidates();
    cs[0] = nbu;
    cw[0] = round_down(dn - m);
    e.count = 1, e.others_lb = 0.0, e.settled = 1;
    e.x0[0] = p[0], e.x0[1] = p[1], e.x0[2] = p[2];
    e.tri_index = orig_[nbu];
    const detail::Tri tt = tri_at(nbu);  // a large collider: the entry keeps a copy
    std::memcpy(cache.firsts.data() + 12 * ei, &tt, sizeof tt);
    d2 = d2n, d = dn, s = sn, t = tn, stride = kBlock, r = rn;
    return 1;
  }
  if (!edge_answer(o, slot0, beyond, p, t, stride, s, d, feet, nbu, tn, sn, dn, feet_n, m)) return 0;
  // Over the edge between the two faces: the better of the two is the answer.
  if (better(d2n, orig_[nbu], d2, e.tri_index)) d2 = d2n, d = dn, s = sn, t = tn, stride = kBlock;
  return 2;
}

bool ColliderSet::certify_fast(std::size_t o, const double p[3], double radius_sq,
                               ContactCache& cache, std::size_t ei, bool& hit,
                               double& signed_distance, double normal[3]) const {
  return certify_inline(o, p, radius_sq, cache, ei, hit, signed_distance, normal);
}

namespace detail {
/// accumulate_penalty()'s way to the inlined check.
struct PenaltyLoop {
  /// Object o's padded box and whether it has triangles (out_of_reach()'s data).
  static bool box(const ColliderSet& set, std::size_t o, const double*& lo, const double*& hi) {
    const ColliderSet::Object& ob = set.objects_[o];
    lo = ob.lo.data(), hi = ob.hi.data();
    return ob.kept > 0;
  }
  using Evaluated = ColliderSet::Evaluated;
  using Answer = ColliderSet::Answer;
  static bool certify(const ColliderSet& set, std::size_t o, const double p[3], double radius_sq,
                      ContactCache& cache, std::size_t ei, bool& hit, double& signed_distance,
                      double normal[3], Evaluated& pre, Answer& answer) {
    return set.certify_inline(o, p, radius_sq, cache, ei, hit, signed_distance, normal, &pre, &answer);
  }
  /// Whether object o has a rim (an edge not shared by exactly two triangles).
  static bool open(const ColliderSet& set, std::size_t o) { return set.objects_[o].open; }
  /// The kept triangle data of a hit (its input triangle index): component k at [k * kBlock].
  static const double* triangle_data(const ColliderSet& set, const ColliderHit& h) {
    const ColliderSet::Object& ob = set.objects_[static_cast<std::size_t>(h.object)];
    return set.tri_ptr(static_cast<std::uint32_t>(ob.input_to_kept[static_cast<std::size_t>(h.triangle)]));
  }
  static ColliderHit query_cached(const ColliderSet& set, std::size_t o, const double p[3],
                                  double radius_sq, QueryMethod method, ContactCache& cache,
                                  std::size_t ei, bool& certified, const Evaluated& pre) {
    return set.query_cached_from(o, p, radius_sq, method, cache, ei, certified, pre);
  }
};
}  // namespace detail

ColliderHit ColliderSet::renew_cached(std::size_t o, const double p[3], double radius_sq,
                                      QueryMethod method, ContactCache& cache,
                                      std::size_t ei) const {
  const Object& ob = objects_[o];
  ContactCache::Entry& e = cache.entries[ei];
  const std::size_t k = std::min(cache.candidates(), kMaxCandidates);
  std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
  float* cl = cache.lower.data() + ei * cache.candidates();
  const bool use_copy = ob.kept > kCopyAbove;
  const double m = certificate_margin(p, ob.scale);
  const auto set_first = [&] {
    e.tri_index = orig_[cs[0]];
    if (use_copy) {
      const detail::Tri t = tri_at(cs[0]);
      std::memcpy(cache.firsts.data() + 12 * ei, &t, sizeof t);
    }
  };
  // A search. K-nearest (a list) unless lists die young here (see kMinAge, kRetry). A list
  // that died young makes the wait before the next one twice as long (up to 128x).
  // (lean == 0: the last search made a list; lean > 0: 1-nearest searches since.)
  if (k > 1 && e.count >= 0 && e.lean == 0)
    e.backoff = e.age >= kMinAge ? 0 : static_cast<std::uint8_t>(std::min(e.backoff + 1, 7));
  const bool list =
      k > 1 && (e.count < 0 || e.age >= kMinAge || e.lean >= (kRetry << e.backoff));
  e.lean = list ? 0 : static_cast<std::uint16_t>(std::min(e.lean + 1, 0xffff));
  e.age = 0;
  e.settled = 1;
  e.x0[0] = p[0], e.x0[1] = p[1], e.x0[2] = p[2];
  if (!list) {  // 1-nearest (the single-triangle certificate)
    double lb = 0.0;
    const ColliderHit hit =
        query_object(o, p, radius_sq, method, e.count >= 1 ? e.tri_index : -1, &lb);
    // Another triangle ties with the answer (within 4 m; a point near a vertex): a
    // single-triangle certificate cannot hold for one call there. On a small collider,
    // whose lists live long, a list is made at once instead (skirt_hires's first 2 s: 1.0 %
    // fewer instructions; on fine spheres, whose lists die young, it cost up to 1.4 %).
    const bool tie = k > 1 && ob.kept <= kCopyAbove && hit.valid() &&
                     !(std::sqrt(hit.distance_sq) + 4.0 * m < lb);
    if (!tie) {
      e.others_lb = lb;
      e.count = hit.valid() ? 1 : 0;
      if (hit.valid()) {
        cs[0] = static_cast<std::uint32_t>(ob.input_to_kept[static_cast<std::size_t>(hit.triangle)]);
        cl[0] = round_down(std::sqrt(hit.distance_sq) - m);
        set_first();
      }
      return hit;
    }
    e.lean = 0;
  }
  std::uint32_t ns[kMaxCandidates];
  double nd[kMaxCandidates];
  double lb = 0.0;
  const std::size_t n =
      query_nearest(o, p, radius_sq, method, k,
                    std::span<const std::uint32_t>(cs, e.count > 0 ? static_cast<std::size_t>(e.count) : 0),
                    ns, nd, lb);
  e.others_lb = lb;
  e.count = static_cast<std::int32_t>(n);
  for (std::size_t c = 0; c < n; ++c) cs[c] = ns[c], cl[c] = round_down(std::sqrt(nd[c]) - m);
  if (n == 0) return ColliderHit{};
  set_first();
  const detail::Tri t = tri_at(ns[0]);
  double s, v, w;
  TriangleRegion region;
  const double d2 = detail::closest_sq(p, t, s, v, w, region);
  ColliderHit hit;
  hit.object = static_cast<std::int32_t>(o);
  hit.triangle = orig_[ns[0]];
  hit.distance_sq = d2;
  hit.signed_distance = detail::signed_distance(d2, s);
  hit.normal = Eigen::Vector3d(t.nx, t.ny, t.nz);
  return hit;
}

namespace {

#ifdef CLOTHSIM_AVX2
bool use_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") && std::getenv("CLOTHSIM_NO_AVX2") == nullptr;
  return yes;
}

// Rows r[0..3] (4 doubles each) to columns c0..c3.
__attribute__((target("avx2"), always_inline)) inline void transpose4(const __m256d r[4], __m256d& c0, __m256d& c1,
                                                                      __m256d& c2, __m256d& c3) {
  const __m256d t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
  const __m256d t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
  c0 = _mm256_permute2f128_pd(t0, t2, 0x20), c1 = _mm256_permute2f128_pd(t1, t3, 0x20);
  c2 = _mm256_permute2f128_pd(t0, t2, 0x31), c3 = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// Four points' x, y, z stored one after another (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) to
// lanes: v[0] = x0 x1 x2 x3, v[1] the y, v[2] the z; and back.
__attribute__((target("avx2"), always_inline)) inline void aos_to_lanes(const double* a, __m256d v[3]) {
  const __m256d v0 = _mm256_loadu_pd(a), v1 = _mm256_loadu_pd(a + 4), v2 = _mm256_loadu_pd(a + 8);
  const __m256d xy = _mm256_blend_pd(v0, v1, 0b1100);       // x0 y0 x2 y2
  const __m256d zx = _mm256_permute2f128_pd(v0, v2, 0x21);  // z0 x1 z2 x3
  const __m256d yz = _mm256_blend_pd(v1, v2, 0b1100);       // y1 z1 y3 z3
  v[0] = _mm256_blend_pd(xy, zx, 0b1010);
  v[1] = _mm256_shuffle_pd(xy, yz, 0b0101);
  v[2] = _mm256_blend_pd(zx, yz, 0b1010);
}
__attribute__((target("avx2"), always_inline)) inline void lanes_to_aos(const __m256d v[3], double* a) {
  const __m256d xy = _mm256_shuffle_pd(v[0], v[1], 0b0000);  // x0 y0 x2 y2
  const __m256d zx = _mm256_blend_pd(v[2], v[0], 0b1010);    // z0 x1 z2 x3
  const __m256d yz = _mm256_shuffle_pd(v[1], v[2], 0b1111);  // y1 z1 y3 z3
  _mm256_storeu_pd(a, _mm256_permute2f128_pd(xy, zx, 0x20));
  _mm256_storeu_pd(a + 4, _mm256_blend_pd(yz, xy, 0b1100));
  _mm256_storeu_pd(a + 8, _mm256_permute2f128_pd(zx, yz, 0x31));
}

// box_dist_sq() in lanes: e = p < lo ? lo - p : (p > hi ? p - hi : 0), summed from 0 in x, y,
// z order (the same operations).
__attribute__((target("avx2"), always_inline)) inline __m256d box_dist_sq_lanes(const __m256d p[3], const double* lo,
                                                                              const double* hi) {
  const __m256d zero = _mm256_setzero_pd();
  __m256d d2 = zero;
  for (int k = 0; k < 3; ++k) {
    const __m256d l = _mm256_set1_pd(lo[k]), h = _mm256_set1_pd(hi[k]);
    __m256d ek = _mm256_blendv_pd(zero, _mm256_sub_pd(p[k], h), _mm256_cmp_pd(p[k], h, _CMP_GT_OQ));
    ek = _mm256_blendv_pd(ek, _mm256_sub_pd(l, p[k]), _mm256_cmp_pd(p[k], l, _CMP_LT_OQ));
    d2 = _mm256_add_pd(d2, _mm256_mul_pd(ek, ek));
  }
  return d2;
}

// The 32-bit halves idx[0..3] of v.
__attribute__((target("avx2"), always_inline)) inline __m128i half(__m256d v, __m256i idx) {
  return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(_mm256_castpd_si256(v), idx));
}

/// accumulate_impl()'s box test and plane certificate for four consecutive points (p: their
/// x, y, z in lanes; f: the first point's force, x, y, z per point) and one object (e: the first
/// point's entry, the next ones `stride` entries on), in AVX2 lanes: the same IEEE operations
/// in the same order as the scalar code (no FMA), so the same bits. Adds the forces of the
/// pairs it answers to f, and their statistics; returns the lanes (bits) in the object's
/// reach that it did not answer.
__attribute__((target("avx2"), always_inline)) inline unsigned plane_lanes_avx2(
    const __m256d p[3], const ContactCache::Entry* e, std::size_t stride, const double* lo, const double* hi,
    double reach_sq, double eps, double k_rep, double* f, PenaltyStats& stats) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d reach =  // not out_of_reach()
      _mm256_cmp_pd(box_dist_sq_lanes(p, lo, hi), _mm256_set1_pd(reach_sq), _CMP_NGT_UQ);
  const int in_reach = _mm256_movemask_pd(reach);
  if (in_reach == 0) return 0;
  // The four planes (64 bytes each: a, n, x0 as floats, r2 and born), transposed to lanes.
  const auto* base = reinterpret_cast<const double*>(&e->plane);
  const std::size_t step = stride * (sizeof(ContactCache::Entry) / sizeof(double));
  __m256d lo4[4], hi4[4];
  for (std::size_t l = 0; l < 4; ++l) {
    lo4[l] = _mm256_load_pd(base + l * step);      // a0 a1 a2 n0
    hi4[l] = _mm256_load_pd(base + l * step + 4);  // n1 n2 (x0[0] x0[1]) (x0[2] r2|born)
  }
  __m256d a[3], n[3], q[4];
  transpose4(lo4, a[0], a[1], a[2], n[0]);
  transpose4(hi4, n[1], n[2], q[0], q[1]);
  // the floats: q[0] holds x0[0] and x0[1] of each lane, q[1] x0[2] and the word r2 | born << 16
  const __m256i even = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6), odd = _mm256_setr_epi32(1, 3, 5, 7, 1, 3, 5, 7);
  const __m256d dx = _mm256_sub_pd(p[0], _mm256_cvtps_pd(_mm_castsi128_ps(half(q[0], even))));
  const __m256d dy = _mm256_sub_pd(p[1], _mm256_cvtps_pd(_mm_castsi128_ps(half(q[0], odd))));
  const __m256d dz = _mm256_sub_pd(p[2], _mm256_cvtps_pd(_mm_castsi128_ps(half(q[1], even))));
  // radius_sq(): r2 as the upper half of a float (`born`, the word's upper half, shifts out)
  const __m256d r2 = _mm256_cvtps_pd(_mm_castsi128_ps(_mm_slli_epi32(half(q[1], odd), 16)));
  const __m256d abs_r2 = _mm256_andnot_pd(_mm256_set1_pd(-0.0), r2);
  const __m256d dist2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
  const __m256d inside = _mm256_and_pd(reach, _mm256_cmp_pd(dist2, abs_r2, _CMP_LT_OQ));
  __m256d face = _mm256_and_pd(inside, _mm256_cmp_pd(r2, zero, _CMP_GT_OQ));
  int answered = _mm256_movemask_pd(inside);
  if (_mm256_movemask_pd(face) != 0) {
    const __m256d s = _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(n[0], _mm256_sub_pd(p[0], a[0])), _mm256_mul_pd(n[1], _mm256_sub_pd(p[1], a[1]))),
        _mm256_mul_pd(n[2], _mm256_sub_pd(p[2], a[2])));
    // |s| < 1e-150 (s * s would underflow): left to the scalar code's signed_distance()
    const __m256d tiny = _mm256_and_pd(face, _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), s),
                                                          _mm256_set1_pd(1e-150), _CMP_NGE_UQ));
    answered &= ~_mm256_movemask_pd(tiny);
    face = _mm256_andnot_pd(tiny, face);
    const __m256d d = s;
    // respond(): the deepest penetration, then the band
    const __m256d behind = _mm256_and_pd(face, _mm256_cmp_pd(d, zero, _CMP_LT_OQ));
    alignas(32) double depth[4];
    _mm256_store_pd(depth, _mm256_and_pd(behind, _mm256_sub_pd(zero, d)));
    for (double v : depth) stats.max_penetration = std::max(stats.max_penetration, v);
    const __m256d veps = _mm256_set1_pd(eps);
    const __m256d near = _mm256_and_pd(face, _mm256_cmp_pd(d, veps, _CMP_NGT_UQ));
    const __m256d tunnelled = _mm256_and_pd(near, _mm256_cmp_pd(d, _mm256_sub_pd(zero, veps), _CMP_LT_OQ));
    const int contact = _mm256_movemask_pd(_mm256_andnot_pd(tunnelled, near));
    stats.tunnelled += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(_mm256_movemask_pd(tunnelled))));
    if (contact != 0) {
      const __m256d c = _mm256_mul_pd(_mm256_set1_pd(k_rep), _mm256_sub_pd(veps, d));  // k_rep (eps - d)
      __m256d cn[3];
      for (int k = 0; k < 3; ++k) cn[k] = _mm256_mul_pd(c, n[k]);
      // f_i += c n in lanes, only where in contact (the others keep their bits)
      __m256d fv[3];
      aos_to_lanes(f, fv);
      const __m256d in = _mm256_castsi256_pd(_mm256_setr_epi64x(-(contact & 1), -((contact >> 1) & 1),
                                                                -((contact >> 2) & 1), -((contact >> 3) & 1)));
      for (int k = 0; k < 3; ++k) fv[k] = _mm256_blendv_pd(fv[k], _mm256_add_pd(fv[k], cn[k]), in);
      lanes_to_aos(fv, f);
      stats.contacts += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(contact)));
    }
  }
  stats.certified += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(answered)));
  return static_cast<unsigned>(in_reach & ~answered);
}

/// accumulate_impl()'s points [i, end) four at a time (x and f: x, y, z per point): whether
/// all four are finite and near a collider (else point(i + l) for each), then per object
/// their plane certificates in lanes and pair(i + l, o, p) for the rest, object by object so
/// that every point adds its objects' forces in the same order. Returns where it stopped.
template <class Pair, class Point>
__attribute__((target("avx2"))) std::size_t groups_avx2(const ColliderSet& set, const double* x, double* f,
                                                        std::size_t i, std::size_t end, ContactCache& cache,
                                                        const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                                        double reach_sq, double eps, double k_rep, PenaltyStats& stats,
                                                        Pair& pair, Point& point) {
  const std::size_t no = set.object_count();
  const __m256d zero = _mm256_setzero_pd(), limit = _mm256_set1_pd(reach_sq);
  for (; i + 4 <= end; i += 4) {
    __m256d p[3];  // x, y, z of the four points
    aos_to_lanes(x + 3 * i, p);
    // isfinite(x + y + z) and not box_dist_sq(lo, hi, p) > reach_sq, as point() tests them
    const __m256d sum = _mm256_add_pd(_mm256_add_pd(p[0], p[1]), p[2]);
    const int finite = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_sub_pd(sum, sum), zero, _CMP_EQ_OQ));
    const int near = _mm256_movemask_pd(_mm256_cmp_pd(box_dist_sq_lanes(p, lo.data(), hi.data()), limit, _CMP_NGT_UQ));
    if ((finite & near) != 0xf) [[unlikely]] {
      // four finite points far from every collider: point() would leave them as they are
      if (finite == 0xf && near == 0) continue;
      for (std::size_t l = 0; l < 4; ++l) point(i + l);
      continue;
    }
    for (std::size_t o = 0; o < no; ++o) {
      const double *olo, *ohi;
      if (!detail::PenaltyLoop::box(set, o, olo, ohi)) continue;  // no triangles: out of reach
      for (unsigned rest = plane_lanes_avx2(p, &cache.entries[i * no + o], no, olo, ohi, reach_sq, eps, k_rep,
                                            f + 3 * i, stats);
           rest != 0; rest &= rest - 1) {
        const auto l = static_cast<std::size_t>(__builtin_ctz(rest));
        const double* xl = x + 3 * (i + l);
        const double q[3] = {xl[0], xl[1], xl[2]};
        pair(i + l, o, q);
      }
    }
  }
  return i;
}
#endif

void accumulate_impl(const ColliderSet& set, const Eigen::Ref<const Eigen::Matrix3Xd>& x, double eps,
                     double k_rep, Eigen::Ref<Eigen::Matrix3Xd>& f, PenaltyStats& stats, std::span<std::int32_t> hints,
                     ContactCache* cache, QueryMethod method, std::size_t begin = 0,
                     std::size_t end = std::numeric_limits<std::size_t>::max()) {
  if (!set.built()) throw std::logic_error("accumulate_penalty(): ColliderSet not built");
  if (!(eps > 0.0) || !std::isfinite(eps) || !(k_rep >= 0.0) || !std::isfinite(k_rep))
    throw std::invalid_argument("accumulate_penalty(): need eps > 0 and k_rep >= 0, finite");
  if (f.cols() != x.cols())
    throw std::invalid_argument("accumulate_penalty(): f and x differ in size");
  const std::size_t no = set.object_count();
  const auto n = static_cast<std::size_t>(x.cols());
  if (!hints.empty() && hints.size() != n * no)
    throw std::invalid_argument("accumulate_penalty(): hints need points * objects entries");
  if (cache && (cache->entries.size() != n * no ||
                cache->slots.size() != n * no * cache->candidates() ||
                cache->lower.size() != n * no * cache->candidates() ||
                cache->firsts.size() != n * no * 12))
    throw std::invalid_argument("accumulate_penalty(): ContactCache needs resize(points, objects)");
  if (end > n) end = n;
  if (begin > end)
    throw std::invalid_argument("accumulate_penalty(): point range outside the cloth");
  stats = PenaltyStats{};
  if (no == 0 || set.triangle_count() == 0) return;

  // Search to 2 eps so that points just past the band behind a surface are seen (tunnelled).
  const double reach = 2.0 * eps, reach_sq = reach * reach;
  const bool planes = cache && cache->band == eps;  // its plane records hold for this eps
  const Eigen::Vector3d lo = set.bounds_min(), hi = set.bounds_max();
  const double* px = x.data();
  double* pf = f.data();
  const Eigen::Index xs = x.outerStride(), fs = f.outerStride();
  // Eq. 12 for one (point, object) answer: d signed distance, n unit normal.
  const auto respond = [&](double* fi, double d, const double* nrm) {
    if (d < 0.0) stats.max_penetration = std::max(stats.max_penetration, -d);
    if (d > eps) return;
    if (d < -eps) {
      ++stats.tunnelled;
      return;
    }
    ++stats.contacts;
    const double c = k_rep * (eps - d);  // f_i += (k_rep (eps - d)) n
    fi[0] += c * nrm[0];
    fi[1] += c * nrm[1];
    fi[2] += c * nrm[2];
  };
  // An answer of the searches and lists (not of a plane record, which is always over a face):
  // in an edge or corner region, within the band, the distance and direction of the closest
  // point instead of the face's (detail::edge_contact()).
  const auto respond_at = [&](double* fi, std::size_t o, const double p[3], double d, const double* nrm,
                              const double* tri, std::size_t stride) {
    double dd = d, dir[3];
    TriangleRegion region;
    if (tri != nullptr && d <= eps) {
      const int edge = detail::edge_contact(p, tri, stride, detail::PenaltyLoop::open(set, o), dd, dir, region);
      // (2: behind a face of a closed solid, beside an edge or corner: outside beside a sharp one)
      if (edge == 1 || (edge == 2 && set.outside_at_feature(o, p, tri, stride, region, dir)))
        return respond(fi, dd, dir);
    }
    respond(fi, d, nrm);
  };
  // Everything but a certificate's common case, kept out of the loop.
  const auto full = [&](std::size_t i, std::size_t o, const double p[3],
                        const detail::PenaltyLoop::Evaluated& pre) __attribute__((noinline)) {
    ColliderHit h;
    if (cache) {
      bool certified = false;
      h = detail::PenaltyLoop::query_cached(set, o, p, reach_sq, method, *cache, i * no + o,
                                            certified, pre);
      if (certified) ++stats.certified;
    } else {
      const std::int32_t hint = hints.empty() ? -1 : hints[i * no + o];
      h = set.query_object(o, p, reach_sq, method, hint);
      if (!hints.empty()) hints[i * no + o] = h.triangle;
    }
    if (h.valid()) respond_at(pf + static_cast<Eigen::Index>(i) * fs, o, p, h.signed_distance, h.normal.data(),
                              detail::PenaltyLoop::triangle_data(set, h), kBlock);
  };
  // One (point, object) pair: the object's box, the plane certificate, the inlined check, the rest.
  const auto pair = [&](std::size_t i, std::size_t o, const double p[3]) {
    // Far from this object: nothing in reach, and its cache entry is left as it is (a
    // certificate stays true wherever the point goes: it is checked against the distance
    // moved since it was made).
    if (set.out_of_reach(o, p, reach_sq)) {
      if (!hints.empty()) hints[i * no + o] = -1;
      return;
    }
    if (planes) {  // the plane certificate: the common case in one cache line
                  // (after the box test: a point far from the object reads no cache)
      const ContactCache::Plane& pl = cache->entries[i * no + o].plane;
      const double dx = p[0] - static_cast<double>(pl.x0[0]),
                   dy = p[1] - static_cast<double>(pl.x0[1]),
                   dz = p[2] - static_cast<double>(pl.x0[2]);
      const double r2 = static_cast<double>(pl.radius_sq());
      if (dx * dx + dy * dy + dz * dz < std::abs(r2)) [[likely]] {
        ++stats.certified;
        if (r2 > 0.0) {  // over the face: the kernel's face branch, the same arithmetic
          const double apx = p[0] - pl.a[0], apy = p[1] - pl.a[1], apz = p[2] - pl.a[2];
          const double s = pl.n[0] * apx + pl.n[1] * apy + pl.n[2] * apz;
          // signed_distance(s * s, s) without its square root: in binary floating point
          // sqrt(s * s) is exactly |s| unless s * s underflows (Boldo 2015), and then the
          // sign rule gives s, or +0 for -0 (tested bit for bit against the kernel).
          const double d =
              std::abs(s) >= 1e-150 ? s : detail::signed_distance(s * s, s);
          respond(pf + static_cast<Eigen::Index>(i) * fs, d, pl.n);
        }
        return;
      }
    }
    bool hit = false;
    double d = 0.0, nrm[3];
    detail::PenaltyLoop::Evaluated pre;
    detail::PenaltyLoop::Answer answer;
    if (cache &&
        detail::PenaltyLoop::certify(set, o, p, reach_sq, *cache, i * no + o, hit, d, nrm, pre, answer))
        [[likely]] {
      ++stats.certified;
      if (hit) respond_at(pf + static_cast<Eigen::Index>(i) * fs, o, p, d, nrm, answer.tri, answer.stride);
    } else {
      full(i, o, p, pre);
    }
  };
  // The same point by point (a NaN point, or one far from every collider, is skipped).
  const auto point = [&](std::size_t i) {
    const double* xi = px + static_cast<Eigen::Index>(i) * xs;
    const double p[3] = {xi[0], xi[1], xi[2]};
    const bool finite = std::isfinite(p[0] + p[1] + p[2]);
    if (!finite || box_dist_sq(lo, hi, p) > reach_sq) [[unlikely]] {  // NaN, or far from every collider
      if (!finite) ++stats.nonfinite_points;
      if (!hints.empty()) std::fill_n(hints.begin() + static_cast<std::ptrdiff_t>(i * no), no, -1);
      // A NaN point's entries start again; a far point's are left as they are (its
      // certificates stay true wherever it goes, as for one object's box in pair()): writing
      // them cost two cache lines per point and step while the cloth was away.
      if (cache && !finite)
        for (std::size_t o = 0; o < no; ++o) cache->entries[i * no + o].count = -1;
      return;
    }
    for (std::size_t o = 0; o < no; ++o) pair(i, o, p);
  };
  std::size_t i = begin;
#ifdef CLOTHSIM_AVX2
  if (planes && xs == 3 && fs == 3 && use_avx2()) {
    // Four points at a time (the same arithmetic, the same bits)
    i = groups_avx2(set, px, pf, i, end, *cache, lo, hi, reach_sq, eps, k_rep, stats, pair, point);
  }
#endif
  for (; i < end; ++i) point(i);
}

}  // namespace

void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, double eps,
                        double k_rep, Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats,
                        std::span<std::int32_t> hints, QueryMethod method) {
  accumulate_impl(set, x, eps, k_rep, f, stats, hints, nullptr, method);
}

void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, double eps,
                        double k_rep, Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats,
                        ContactCache& cache, QueryMethod method) {
  cache.tick();
  cache.use_band(eps);
  accumulate_impl(set, x, eps, k_rep, f, stats, {}, &cache, method);
}

void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x,
                        std::size_t begin, std::size_t end, double eps, double k_rep,
                        Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats, ContactCache& cache,
                        QueryMethod method) {
  if (begin > end || end > static_cast<std::size_t>(x.cols()))
    throw std::invalid_argument("accumulate_penalty(): point range outside the cloth");
  accumulate_impl(set, x, eps, k_rep, f, stats, {}, &cache, method, begin, end);
}

}  // namespace clothsim
