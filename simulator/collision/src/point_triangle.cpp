// point_triangle() and triangle_is_degenerate(): the public point-triangle query, on the
// kernel the ColliderSet queries share.
#include "clothsim/collision/point_triangle.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "kernel.hpp"

namespace clothsim {

PointTriangle point_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  PointTriangle r;
  if (triangle_is_degenerate(a, b, c)) {
    r.degenerate = true;
    return r;
  }
  const Eigen::Vector3d ab = b - a, ac = c - a, n = detail::unit_normal(ab, ac);
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

bool triangle_is_degenerate(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  if (!a.allFinite() || !b.allFinite() || !c.allFinite()) return true;
  const Eigen::Vector3d ab = b - a, ac = c - a, bc = c - b;
  const double longest_sq = std::max({ab.squaredNorm(), ac.squaredNorm(), bc.squaredNorm()});
  const double cross = ab.cross(ac).norm();
  // |AB x AC| = 2 area; relative to the longest edge so that slivers count as degenerate.
  return !(cross > 1e-12 * longest_sq) || !std::isfinite(cross);
}

}  // namespace clothsim
