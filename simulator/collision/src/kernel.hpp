// The point-triangle kernel shared by every query path, so that the BVH, brute force and
// point_triangle() compute bit-identical distances for the same triangle.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>

#include "clothsim/collision/point_triangle.hpp"

namespace clothsim::detail {

/// The unit normal of a triangle with edges AB, AC (counter-clockwise winding), as every
/// path stores it.
inline Eigen::Vector3d unit_normal(const Eigen::Vector3d& ab, const Eigen::Vector3d& ac) {
  return ab.cross(ac).normalized();
}

/// Closest point on triangle (A, A+AB, A+AC) to P after Ericson, "Real-Time Collision
/// Detection" 5.1.5, with unit normal n. Returns |P - Q|^2; `s` = n.(P - A) (signed plane
/// distance); `v`, `w`: Q = A + v AB + w AC.
struct Tri {
  double ax, ay, az, bx, by, bz, cx, cy, cz, nx, ny, nz;  // A, AB, AC, n
};

/// The kernel on any storage: `t(k)` reads component k (A 0-2, AB 3-5, AC 6-8, n 9-11), so
/// the corners can be read in place (a strided block) as well as from a Tri.
template <class Get>
inline double closest_sq_impl(const double p[3], const Get& t, double& s, double& v, double& w,
                              TriangleRegion& region) {
  const double apx = p[0] - t(0), apy = p[1] - t(1), apz = p[2] - t(2);
  s = t(9) * apx + t(10) * apy + t(11) * apz;
  const double d1 = t(3) * apx + t(4) * apy + t(5) * apz;
  const double d2 = t(6) * apx + t(7) * apy + t(8) * apz;
  if (d1 <= 0.0 && d2 <= 0.0) {
    v = 0.0, w = 0.0, region = TriangleRegion::VertexA;
    return apx * apx + apy * apy + apz * apz;
  }
  const double bpx = apx - t(3), bpy = apy - t(4), bpz = apz - t(5);
  const double d3 = t(3) * bpx + t(4) * bpy + t(5) * bpz;
  const double d4 = t(6) * bpx + t(7) * bpy + t(8) * bpz;
  if (d3 >= 0.0 && d4 <= d3) {
    v = 1.0, w = 0.0, region = TriangleRegion::VertexB;
    return bpx * bpx + bpy * bpy + bpz * bpz;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    v = d1 / (d1 - d3), w = 0.0, region = TriangleRegion::EdgeAB;
    const double ex = apx - v * t(3), ey = apy - v * t(4), ez = apz - v * t(5);
    return ex * ex + ey * ey + ez * ez;
  }
  const double cpx = apx - t(6), cpy = apy - t(7), cpz = apz - t(8);
  const double d5 = t(3) * cpx + t(4) * cpy + t(5) * cpz;
  const double d6 = t(6) * cpx + t(7) * cpy + t(8) * cpz;
  if (d6 >= 0.0 && d5 <= d6) {
    v = 0.0, w = 1.0, region = TriangleRegion::VertexC;
    return cpx * cpx + cpy * cpy + cpz * cpz;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    v = 0.0, w = d2 / (d2 - d6), region = TriangleRegion::EdgeCA;
    const double ex = apx - w * t(6), ey = apy - w * t(7), ez = apz - w * t(8);
    return ex * ex + ey * ey + ez * ez;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    // Q = B + u (C - B); P - Q = BP - u (AC - AB)
    const double u = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    v = 1.0 - u, w = u, region = TriangleRegion::EdgeBC;
    const double ex = bpx - u * (t(6) - t(3)), ey = bpy - u * (t(7) - t(4)),
                 ez = bpz - u * (t(8) - t(5));
    return ex * ex + ey * ey + ez * ez;
  }
  // Inside the face: the plane distance is the distance (and more accurate than P - Q).
  const double denom = 1.0 / (va + vb + vc);
  v = vb * denom, w = vc * denom, region = TriangleRegion::Face;
  return s * s;
}

inline double closest_sq(const double p[3], const Tri& t, double& s, double& v, double& w,
                         TriangleRegion& region) {
  const double c[12] = {t.ax, t.ay, t.az, t.bx, t.by, t.bz, t.cx, t.cy, t.cz, t.nx, t.ny, t.nz};
  return closest_sq_impl(p, [&c](int k) { return c[k]; }, s, v, w, region);
}

/// |P - Q|^2 and s for the triangle whose component k is b[k * Stride] (the same arithmetic).
template <std::size_t Stride>
inline double closest_sq(const double p[3], const double* b, double& s) {
  double v, w;
  TriangleRegion region;
  return closest_sq_impl(p, [b](int k) { return b[k * static_cast<int>(Stride)]; }, s, v, w, region);
}

/// The same, and whether the closest point is inside the face (the kernel's face branch):
/// when it is not, the foot of P on the plane is outside the triangle or on its border, up to
/// the kernel's rounding.
template <std::size_t Stride>
inline double closest_sq(const double p[3], const double* b, double& s, bool& face) {
  double v, w;
  TriangleRegion region;
  const double d2 =
      closest_sq_impl(p, [b](int k) { return b[k * static_cast<int>(Stride)]; }, s, v, w, region);
  face = region == TriangleRegion::Face;
  return d2;
}

/// The penalty's distance and direction for an answer whose closest point Q is on an edge or a
/// corner of the triangle (component k of its data at t[k * stride]): d = +|P - Q| and the
/// direction (P - Q) / |P - Q|, the gradient of the distance to the surface there: returns 1.
/// Returns 0 (nothing set) over the face, where the face's plane gives both, when P is
/// straight over or under Q (its foot on the triangle's border), and when P is on Q. For a
/// closed mesh (`open` false: every edge shared by two triangles) with P behind the face's
/// plane it returns 2 with d, dir and `region` set: inside beside a reflex edge, outside
/// beside a sharp ridge or tip; ColliderSet::outside_at_feature() tells which.
/// So the push is the same whichever of the triangles that share the edge or corner wins the
/// tie (else a cloth centred on a box drifts off towards the face of lower index), and beside
/// the rim of an open mesh a point below its level is not "behind" it (else it is pushed up
/// by k_rep (eps + d), a force with no potential that feeds energy into a draped cloth).
inline int edge_contact(const double p[3], const double* t, std::size_t stride, bool open, double& d,
                        double dir[3], TriangleRegion& region) {
  double s, v, w;
  const auto T = [t, stride](int k) { return t[static_cast<std::size_t>(k) * stride]; };
  const double d2 = closest_sq_impl(p, T, s, v, w, region);
  // Over the face, or on its border with P straight over or under Q (|P - Q| is the plane
  // distance: a point behind a floor under an edge between two of its triangles is behind it).
  if (region == TriangleRegion::Face || !(d2 > 0.0) || !(d2 - s * s > 1e-9 * d2)) return 0;
  double e[3];
  for (int k = 0; k < 3; ++k) e[k] = p[k] - (T(k) + v * T(3 + k) + w * T(6 + k));
  const double len = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  if (!(len > 0.0)) return 0;
  d = std::sqrt(d2);
  for (int k = 0; k < 3; ++k) dir[k] = e[k] / len;
  // Behind the face's plane, off its border: beside the rim of an open mesh (below a plate's
  // level) this is no inside (1); in a closed solid it is inside beside a reflex edge (a point
  // sunk there) but outside beside a sharp ridge or tip, where the plane of one face cuts
  // through the space outside the other faces: the caller decides (2).
  if (!open && s < 0.0 && -s > 1e-6 * d) return 2;
  return 1;
}

/// The signed distance from d = |P - Q| and s = n.(P - A): behind (-d) only when P is behind
/// the plane by more than 1e-6 d. A point beyond an edge or a vertex that lies in the plane
/// up to rounding (|s| tiny against d) is in front: there the plane does not say on which side
/// of the solid P is, and for a convex edge it is outside. (A point above a box's top, exactly
/// in the plane of its side face, ties between the two faces; by that plane's sign the side
/// face, taken on the index, would call it behind by its height: docs/collision.md "Distance".)
inline double signed_from(double d, double s) { return s < 0.0 && -s > 1e-6 * d ? -d : d; }

/// The same from |P - Q|^2; +0 on the plane.
inline double signed_distance(double d2, double s) { return signed_from(std::sqrt(d2), s); }

}  // namespace clothsim::detail
