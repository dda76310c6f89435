// Point-triangle distance: the closest point of a triangle to a point and its signed
// distance, with the conventions of clothsim/collision.hpp.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace clothsim {

/// Which feature of a triangle the closest point lies on.
enum class TriangleRegion : std::uint8_t { Face, EdgeAB, EdgeBC, EdgeCA, VertexA, VertexB, VertexC };

/// Point-triangle query result (report eqs. 8-11 with a unit normal and the closest point).
struct PointTriangle {
  Eigen::Vector3d closest = Eigen::Vector3d::Zero();  ///< closest point on the triangle
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();   ///< unit normal (CCW winding)
  double distance_sq = 0.0;      ///< |P - closest|^2
  double signed_distance = 0.0;  ///< +-|P - closest|, sign of n.(P - A); >= 0 on the plane
  TriangleRegion region = TriangleRegion::Face;
  bool degenerate = false;       ///< zero area / collinear: nothing else is meaningful
};

/// Closest point on triangle ABC to P, with the true signed distance. The same arithmetic
/// as the ColliderSet queries (bit-identical distances for the same triangle).
PointTriangle point_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// True when ABC has (numerically) no area: |AB x AC| <= 1e-12 * (longest edge)^2, or a
/// coordinate is not finite. Such triangles are skipped by ColliderSet::build().
bool triangle_is_degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c);

}  // namespace clothsim
