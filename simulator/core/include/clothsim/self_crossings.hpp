// Self-crossings of a triangle mesh: edges that pass through a triangle of the same mesh with
// which they share no vertex. A cloth that has gone through itself has some; a cloth that only
// folds onto itself, however closely, has none. Eigen and std only: no file formats.
//
// Vertices are welded by exact position first (a mesh split at UV seams has two vertices at
// one position; they count as one), so seams neither cross nor hide a shared corner.
#pragma once

#include <clothsim/sim.hpp>

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>

namespace clothsim {

/// What count_self_crossings() finds.
struct CrossingCount {
  std::size_t crossings = 0;       ///< (edge, triangle) pairs where the edge passes through the triangle
  std::size_t triangle_pairs = 0;  ///< distinct unordered triangle pairs (T1, T2): an edge of one crosses the other
  std::size_t touches = 0;         ///< (edge, triangle) pairs that meet without crossing: segment_meets_triangle()
};

/// The self-crossings of the mesh with positions `x` (3 x n) and triangles `triangles` (3 t
/// indices into x's columns). Welds vertices by exact position (-0.0 == 0.0), takes each
/// welded edge once, skips triangles with two welded corners equal, and tests each edge
/// against the triangles sharing no welded vertex with it (segment_crosses_triangle()). A BVH
/// over the triangles' boxes, built per call and walked against itself, finds the candidates:
/// 33 000 triangles take 35-50 ms on one core. Allocates; deterministic (the count does
/// not depend on the order of the triangles). Throws std::invalid_argument when
/// triangles.size() is no multiple of 3 or an index is out of range.
CrossingCount count_self_crossings(const Eigen::Matrix3Xd& x, std::span<const std::uint32_t> triangles);

/// The self-crossings of a Model's cloths (Model::triangles, all cloths together: one cloth
/// through another counts too) at positions x (3 x mass_count()).
CrossingCount count_self_crossings(const Model& m, const Eigen::Matrix3Xd& x);

/// Whether segment pq passes through triangle abc: p and q strictly on opposite sides of the
/// triangle's plane and the line pq strictly inside the triangle's three edges (orientation
/// predicates in double with Shewchuk's error bound: a sign too close to call is 0). Touching
/// (an endpoint on the plane, the line through an edge or a corner, within rounding) is no
/// crossing, so a flat mesh in one plane, tilted or not, has none. Symmetric in p and q. The
/// narrow phase of count_self_crossings().
bool segment_crosses_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// How segment pq meets triangle abc (the same predicates): it crosses it, touches it (its
/// ends not on one side of the plane, and the line through the closed triangle, with a sign
/// of 0 among them: an end on the triangle, or the segment through its edge or corner), or
/// neither. A segment in the triangle's plane neither crosses nor touches it, so that a flat
/// sheet does neither. Two layers that start along each other's grid lines touch.
enum class Meet { None, Touches, Crosses };
Meet segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace clothsim
