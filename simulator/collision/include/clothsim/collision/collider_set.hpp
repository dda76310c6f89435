// ColliderSet: static collider triangles grouped by object, with a 4-wide BVH per object,
// their closest-triangle queries and the certificate checks accumulate_penalty() runs.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "clothsim/collision/point_triangle.hpp"

namespace clothsim {

struct ContactCache;

namespace detail {
struct Tri;
struct PenaltyLoop;
}

/// The closest triangle of one collider object to a point.
struct ColliderHit {
  std::int32_t object = -1;    ///< -1: no triangle of this object within the query radius
  std::int32_t triangle = -1;  ///< index into the object's input triangle list
  double distance_sq = 0.0;
  double signed_distance = 0.0;  ///< > 0 in front (normal side), < 0 behind
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit normal of that triangle
  bool valid() const { return object >= 0; }
};

/// How a query searches: the BVH, or every triangle (the reference; same results).
enum class QueryMethod : std::uint8_t { Bvh, BruteForce };

/// Static collider triangles in world space, grouped by object, with a BVH per object.
/// Fill with add_object(), then build() once; afterwards it is read-only and thread-safe.
struct ColliderSet {
 public:
  /// Adds a mesh. `vertices` is 3 x V; `indices` holds 3 vertex indices per triangle
  /// (counter-clockwise seen from the front). Returns the object index.
  /// Throws std::invalid_argument naming the object on a bad index, a non-finite vertex or an
  /// index count that is not a multiple of 3; std::logic_error after build().
  std::uint32_t add_object(std::string name, const Eigen::Matrix3Xd& vertices,
                           std::span<const std::uint32_t> indices);
  /// The same with a 3 x T index matrix.
  std::uint32_t add_object(std::string name, const Eigen::Matrix3Xd& vertices,
                           const Eigen::Matrix<std::uint32_t, 3, Eigen::Dynamic>& triangles);

  /// Drops degenerate triangles (counted per object) and builds the BVHs. Call once.
  void build();
  bool built() const { return built_; }

  std::size_t object_count() const { return objects_.size(); }
  const std::string& object_name(std::size_t o) const { return objects_.at(o).name; }
  /// Triangles as given to add_object (including degenerate ones).
  std::size_t input_triangle_count(std::size_t o) const { return objects_.at(o).indices.size() / 3; }
  /// Triangles kept by build() (all objects, or one).
  std::size_t triangle_count() const { return kept_total_; }
  std::size_t triangle_count(std::size_t o) const;
  /// Degenerate triangles skipped by build().
  std::size_t degenerate_count(std::size_t o) const { return objects_.at(o).degenerate; }
  /// Corners of input triangle t of object o (as given, world space).
  void triangle(std::size_t o, std::size_t t, Eigen::Vector3d& a, Eigen::Vector3d& b,
                Eigen::Vector3d& c) const;
  /// Bounding box of every kept triangle, padded by 1e-9 of the coordinates (zero if none).
  Eigen::Vector3d bounds_min() const { return lo_; }
  Eigen::Vector3d bounds_max() const { return hi_; }
  std::size_t bvh_node_count() const { return nodes4_.size(); }  ///< 4-wide nodes
  /// Bytes held by the query structures (triangle blocks, nodes, slot map, clearances, edge
  /// neighbours), not the input copy.
  std::size_t bvh_bytes() const {
    return tri_.size() * sizeof(double) + nodes4_.size() * sizeof(Node4) +
           orig_.size() * sizeof(std::int32_t) + clear_.size() * sizeof(float) +
           adj_.size() * sizeof(std::int32_t) + eclear_.size() * sizeof(float);
  }
  /// The clearance of input triangle t of object o (0 for a dropped one): every other
  /// triangle of the object that reaches within this distance of the triangle's first corner
  /// lies behind its plane (all corners deeper than 1e-9 of the coordinates), or touches the
  /// plane only outside the triangle (its shadow on the plane is separated from it by a
  /// line). Then a point over the face, in front of it, is nearer to it than to any such
  /// triangle, wherever over the face it is (the face's outer Voronoi region, as on a convex
  /// mesh): the "clear face" certificate, which does not shrink with the gaps between nearly
  /// equidistant triangles. +infinity when no triangle fails. Computed when first needed
  /// (nearest triangles first, at most 512 tested per triangle: then the distance reached).
  double clearance(std::size_t o, std::size_t t) const;
  /// Computes every triangle's and edge's clearance now instead of when first needed (each
  /// costs ~9 microseconds once: ~0.75 s for 82k triangles): for steady step times from
  /// the first step on, and for benchmarks of the steady state. Only the speed depends on it.
  void prepare_clearances() const;

  /// Per object, the closest kept triangle with distance <= radius. `out` must have
  /// object_count() entries; entries of objects with nothing in reach get object = -1.
  /// `hints` (empty, or object_count() entries): a previous closest input triangle index per
  /// object (or -1) that makes the BVH search start small; updated on return. Results never
  /// depend on hints or method. Returns the number of objects hit.
  std::size_t query(const Eigen::Vector3d& p, double radius, std::span<ColliderHit> out,
                    QueryMethod method = QueryMethod::Bvh,
                    std::span<std::int32_t> hints = {}) const;
  /// The signed distance of p from object h.object as the penalty force sees it: h's
  /// (query()'s: the distance, signed by the answer's plane), made positive when p is behind
  /// that plane but outside the solid beside a sharp ridge or tip (outside_at_feature()).
  /// For start-up checks that must agree with the force; NaN for an invalid hit.
  double contact_distance(const Eigen::Vector3d& p, const ColliderHit& h) const;
  /// The closest kept triangle of any object within radius (ties: lowest object, then
  /// lowest triangle index); invalid hit when none. For tests and picking helpers.
  ColliderHit closest(const Eigen::Vector3d& p, double radius,
                      QueryMethod method = QueryMethod::Bvh) const;

  // --- internals shared with accumulate_penalty() ---
  /// How far the foot of a point is inside each edge of a face (0: A-B, 1: B-C, 2: C-A), and
  /// the rounding margin of those figures; computed once (of()) for the checks that need it.
  struct Feet {
    double in[3];  // set by of()
    double margin;
    bool known = false, sliver = false;
    /// Computes them unless known; false on a sliver (no face branch to rely on).
    bool of(const double p[3], const double* t, std::size_t stride, double s);
  };
  /// 64-byte BVH node (one cache line): an oriented box, float, padded so that it always
  /// contains every computed closest point of its triangles. Oriented, because an axis-aligned
  /// box of a tilted patch of a curved surface bulges towards a point hovering over it; with
  /// many small triangles that bulge makes the search visit ~sqrt(T) leaves instead of ~log T.
  struct alignas(64) Node {
    float c[3];    ///< centre
    float h[3];    ///< half extents along the three axes
    float a[9];    ///< the axes, row by row (orthonormal to float precision)
    std::uint32_t packed;  ///< leaf: first triangle << 3 | count (1..7); inner: right child << 3
    bool leaf() const { return (packed & 7u) != 0; }
    std::uint32_t index() const { return packed >> 3; }
    std::uint32_t count() const { return packed & 7u; }
  };
  /// The binary tree collapsed to 4 children per node, the boxes stored lane by lane so that
  /// one visit tests 4 boxes at once (vectorised). 256 bytes. Empty lanes never pass.
  struct alignas(64) Node4 {
    float c[3][4], h[3][4], a[9][4];
    std::uint32_t child[4];  ///< Node::packed form: leaf triangles, or a Node4 index << 3
  };
  /// True when no kept triangle of object o can be within sqrt(radius_sq) of p (p is farther
  /// from the object's padded box, or the object has none): one box test, no cache touched.
  bool out_of_reach(std::size_t o, const double p[3], double radius_sq) const;
  /// One object's query; `hint` is an input triangle index or -1. Returns hit or invalid.
  /// `others_lb`, if given, receives a lower bound of the distance of every kept triangle of
  /// the object other than the one returned (of all of them when none is returned).
  ColliderHit query_object(std::size_t o, const double p[3], double radius_sq, QueryMethod method,
                           std::int32_t hint, double* others_lb = nullptr) const;
  /// query_object() through a certificate: reuses entry `e` of `cache` when its answer is
  /// provably unchanged, otherwise searches and renews it. `certified` tells which.
  ColliderHit query_cached(std::size_t o, const double p[3], double radius_sq, QueryMethod method,
                           ContactCache& cache, std::size_t e, bool& certified) const;
  /// query_cached()'s common case, small enough to inline in the per-point loop: the entry's
  /// certificate holds with nothing in reach, or with its first candidate the answer (the
  /// point at rest or drifting). Then it returns true with `hit` (false: none in reach), and
  /// `signed_distance`, `normal` of the answer; the entry is updated exactly as query_cached()
  /// would. Returns false, touching nothing, when the full check is needed.
  bool certify_fast(std::size_t o, const double p[3], double radius_sq, ContactCache& cache,
                    std::size_t ei, bool& hit, double& signed_distance, double normal[3]) const;
  /// The K nearest kept triangles of object o within radius (ties: lowest input index), as
  /// slots in `slots` and distances^2 in `d2`, ascending; returns how many (<= k). `others_lb`
  /// receives a lower bound of the distance of every other kept triangle of the object.
  /// `seed`: slots to test first (a previous list), only to start with a small bound.
  std::size_t query_nearest(std::size_t o, const double p[3], double radius_sq, QueryMethod method,
                            std::size_t k, std::span<const std::uint32_t> seed,
                            std::uint32_t* slots, double* d2, double& others_lb) const;
  /// A point p behind the plane of its answer's triangle (data t, component k at
  /// t[k * stride]) of a closed object o, with its closest point Q on an edge or corner of it
  /// (`region`; dir = (P - Q) / |P - Q|): whether p is outside the solid after all, beside a
  /// sharp ridge or tip where one face's plane cuts through the space outside the others. By
  /// the angle-weighted pseudonormal at Q. False when it cannot tell (an open or non-manifold
  /// neighbourhood): then p counts as behind.
  bool outside_at_feature(std::size_t o, const double p[3], const double* t, std::size_t stride,
                          TriangleRegion region, const double dir[3]) const;

 private:
  struct Object {
    std::string name;
    Eigen::Matrix3Xd vertices;
    std::vector<std::uint32_t> indices;
    std::size_t degenerate = 0;
    double scale = 0.0;  ///< largest |coordinate| of its kept triangles (rounding margins)
    std::uint32_t tri_begin = 0, tri_end = 0;  ///< its slots (blocks of 4, BVH leaf order)
    std::size_t kept = 0;                      ///< triangles kept by build()
    std::uint32_t root = 0;                    ///< binary node index (valid when tri_end > tri_begin)
    std::uint32_t root4 = 0;                   ///< its Node4 (or leaf) in Node::packed form
    bool open = false;  ///< an edge not shared by exactly two kept triangles (a rim): no inside
    Node root_box{};                           ///< the root's box (the early-out per object)
    /// Axis-aligned box of its kept triangles, padded as bounds_min/max (empty: lo > hi).
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1.0), hi = Eigen::Vector3d::Constant(-1.0);
    std::vector<std::int32_t> input_to_kept;   ///< input triangle -> kept slot, -1 if dropped
    std::vector<std::uint32_t> weld;           ///< input vertex -> id of its position
  };
  std::uint32_t build_node(std::uint32_t begin, std::uint32_t end, std::vector<double>& cent,
                           std::vector<std::uint32_t>& perm, const std::vector<double>& corners,
                           double pad);

  std::vector<Object> objects_;
  bool built_ = false;
  // Kept triangles: A, AB = B - A, AC = C - A, unit normal; one block of 4 slots per BVH leaf,
  // each block a small structure of arrays (12 components x 4 slots, 384 bytes).
  std::vector<double> tri_;
  friend struct detail::PenaltyLoop;
  /// The list's first candidates that certify_inline() evaluated before it gave up (two, when
  /// a third may be as near): their squared distances and plane distances, which
  /// query_cached_from() takes instead of evaluating them again.
  struct Evaluated {
    std::int32_t count = 0;
    double d2[2] = {0.0, 0.0}, s[2] = {0.0, 0.0};
  };
  /// query_cached(), with the candidates `pre` already evaluated: the same answer, the same
  /// entry updates.
  ColliderHit query_cached_from(std::size_t o, const double p[3], double radius_sq,
                                QueryMethod method, ContactCache& cache, std::size_t e,
                                bool& certified, const Evaluated& pre) const;
  /// certify_fast(), inlined into accumulate_penalty()'s per-point loop. It makes plane
  /// records only for the cache's band (radius_sq == band_reach_sq). Giving up with a third
  /// candidate that may tie, it leaves the two it evaluated in `*pre` (if given).
  /// Where the answer's triangle data is (component k at tri[k * stride]).
  struct Answer {
    const double* tri = nullptr;
    std::size_t stride = 0;
  };
  bool certify_inline(std::size_t o, const double p[3], double radius_sq, ContactCache& cache,
                      std::size_t ei, bool& hit, double& signed_distance, double normal[3],
                      Evaluated* pre = nullptr, Answer* answer = nullptr) const;
  /// certify_inline()'s "no force" certificate for entry ei, stored as a plane certificate
  /// with nothing to answer (r2 < 0), for a point whose answer lies farther than `band` on
  /// its triangle's front side: within its radius every triangle that can be the nearest
  /// stays farther than band with the point in front of its plane, so the penalty loop adds
  /// nothing and counts nothing, as for a point out of reach. d, s: the answer's distance and
  /// plane distance; loser, loser_s: the nearest other evaluated candidate's (or infinity).
  [[gnu::noinline]] bool make_far(const double p[3], ContactCache& cache, std::size_t ei, double d,
                                  double s, std::int32_t next, double loser, double loser_s,
                                  double moved, double m, double band) const;
  /// certify_inline()'s plane certificate for entry ei (ContactCache::Plane), kept out of line;
  /// false when none can be made here.
  [[gnu::noinline]] bool make_plane(const double p[3], ContactCache& cache,
                                    std::size_t ei, const double* t, std::size_t stride, double d,
                                    double s, std::int32_t next, double loser, double moved,
                                    double m, double reach) const;
  detail::Tri tri_at(std::uint32_t slot) const;
  /// Where slot's 12 components start (component k at [k * 4]).
  const double* tri_ptr(std::uint32_t slot) const;
  std::vector<std::int32_t> orig_;     ///< per slot: input triangle index in its object, -1 unused
  /// Per slot: clearance() rounded down, around the slot's corner A; NaN until first needed
  /// (clear_at() computes it then and stores it atomically: a pure function of the static
  /// collider, so threads that race store the same figure).
  mutable std::vector<float> clear_;
  float clear_at(std::size_t o, std::uint32_t slot) const;
  float clearance_of(std::size_t o, std::uint32_t slot) const;
  /// The radius of a "clear face" certificate at p for the triangle at `slot` (its data at t,
  /// component k at t[k * stride]), the answer's candidate at distance d with plane distance
  /// s > 0; <= 0 when it cannot be made (p not over the face by enough, too near the face's
  /// plane, or too near a triangle within the clearance). Within it, the triangle is the
  /// object's answer over its face (the kernel's face branch), strictly nearer than any other.
  /// `feet` keeps where the foot of p is against the face's edges when it was computed here,
  /// for the walk to reuse.
  double clear_radius(std::size_t o, std::uint32_t slot, const double p[3], const double* t,
                      std::size_t stride, double d, double s, double m, double reach,
                      Feet& feet) const;
  /// Per slot, the slots of the triangles across its edges A-B, B-C, C-A (-1: none, or not
  /// exactly one): corners matched by position, so an export with split vertices still joins.
  std::vector<std::int32_t> adj_;
  void compute_adjacency(std::size_t o);
  /// Per slot and edge (as adj_), the edge's clearance around its midpoint (0: none; see
  /// edge_clearance_of()); NaN until first needed, as clear_.
  mutable std::vector<float> eclear_;
  float eclear_at(std::size_t o, std::uint32_t slot, int k, std::uint32_t nb) const;
  float edge_clearance_of(std::size_t o, std::uint32_t slot, int k, std::uint32_t nb) const;
  /// certify_inline()'s walk from the entry's first candidate to the face across the edge the
  /// point is over or near (1: that face's clear face answers; 2: the edge answers; 0: neither).
  [[gnu::noinline]] int walk_on(std::size_t o, const double p[3], double radius_sq, double reach,
                                double m, ContactCache& cache, std::size_t ei, std::uint32_t slot0,
                                Feet& feet, double& d2, double& d, double& s, const double*& t,
                                std::size_t& stride, double& r) const;
  /// Whether p, in front of the face at `slot` (data t1, plane distance s1, distance d1) and
  /// of its neighbour nb across edge k (t2 in place, s2, d2), over that edge or along it, is
  /// answered by one of the two: then the better of them (distance, then index) is the answer.
  bool edge_answer(std::size_t o, std::uint32_t slot, int k, const double p[3], const double* t1,
                   std::size_t stride1, double s1, double d1, Feet& feet1, std::uint32_t nb,
                   const double* t2, double s2, double d2, Feet& feet2, double m) const;
  template <class InTheWay>
  double scan_in_the_way(std::size_t o, const double centre[3], const double (*planes)[5],
                         int nplanes, double far_loose, InTheWay in_the_way) const;
  std::size_t kept_total_ = 0;
  std::uint32_t collapse(std::uint32_t binary);
  /// query_cached()'s search and renewal of entry ei (kept out of its fast path).
  [[gnu::noinline]] ColliderHit renew_cached(std::size_t o, const double p[3], double radius_sq,
                                             QueryMethod method, ContactCache& cache,
                                             std::size_t ei) const;
  std::vector<Node> nodes_;    ///< the binary tree, only during build()
  std::vector<Node4> nodes4_;  ///< what queries traverse
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero(), hi_ = Eigen::Vector3d::Zero();
};

}  // namespace clothsim
