// The point-triangle kernel shared by every query path, so that the BVH, brute force and
// point_triangle() compute bit-identical distances for the same triangle.
#pragma once

#include "clothsim/collision.hpp"

namespace clothsim::detail {

/// Closest point on triangle (A, A+AB, A+AC) to P after Ericson, "Real-Time Collision
/// Detection" 5.1.5, with unit normal n. Returns |P - Q|^2; `s` = n.(P - A) (signed plane
/// distance); `v`, `w`: Q = A + v AB + w AC.
struct Tri {
  double ax, ay, az, bx, by, bz, cx, cy, cz, nx, ny, nz;  // A, AB, AC, n
};

inline double closest_sq(const double p[3], const Tri& t, double& s, double& v, double& w,
                         TriangleRegion& region) {
  const double apx = p[0] - t.ax, apy = p[1] - t.ay, apz = p[2] - t.az;
  s = t.nx * apx + t.ny * apy + t.nz * apz;
  const double d1 = t.bx * apx + t.by * apy + t.bz * apz;
  const double d2 = t.cx * apx + t.cy * apy + t.cz * apz;
  if (d1 <= 0.0 && d2 <= 0.0) {
    v = 0.0, w = 0.0, region = TriangleRegion::VertexA;
    return apx * apx + apy * apy + apz * apz;
  }
  const double bpx = apx - t.bx, bpy = apy - t.by, bpz = apz - t.bz;
  const double d3 = t.bx * bpx + t.by * bpy + t.bz * bpz;
  const double d4 = t.cx * bpx + t.cy * bpy + t.cz * bpz;
  if (d3 >= 0.0 && d4 <= d3) {
    v = 1.0, w = 0.0, region = TriangleRegion::VertexB;
    return bpx * bpx + bpy * bpy + bpz * bpz;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    v = d1 / (d1 - d3), w = 0.0, region = TriangleRegion::EdgeAB;
    const double ex = apx - v * t.bx, ey = apy - v * t.by, ez = apz - v * t.bz;
    return ex * ex + ey * ey + ez * ez;
  }
  const double cpx = apx - t.cx, cpy = apy - t.cy, cpz = apz - t.cz;
  const double d5 = t.bx * cpx + t.by * cpy + t.bz * cpz;
  const double d6 = t.cx * cpx + t.cy * cpy + t.cz * cpz;
  if (d6 >= 0.0 && d5 <= d6) {
    v = 0.0, w = 1.0, region = TriangleRegion::VertexC;
    return cpx * cpx + cpy * cpy + cpz * cpz;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    v = 0.0, w = d2 / (d2 - d6), region = TriangleRegion::EdgeCA;
    const double ex = apx - w * t.cx, ey = apy - w * t.cy, ez = apz - w * t.cz;
    return ex * ex + ey * ey + ez * ez;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    // Q = B + u (C - B); P - Q = BP - u (AC - AB)
    const double u = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    v = 1.0 - u, w = u, region = TriangleRegion::EdgeBC;
    const double ex = bpx - u * (t.cx - t.bx), ey = bpy - u * (t.cy - t.by),
                 ez = bpz - u * (t.cz - t.bz);
    return ex * ex + ey * ey + ez * ez;
  }
  // Inside the face: the plane distance is the distance (and more accurate than P - Q).
  const double denom = 1.0 / (va + vb + vc);
  v = vb * denom, w = vc * denom, region = TriangleRegion::Face;
  return s * s;
}

/// The signed distance from |P - Q|^2 and the plane side; +0 on the plane.
inline double signed_distance(double d2, double s) {
  const double d = std::sqrt(d2);
  return s < 0.0 ? -d : d;
}

}  // namespace clothsim::detail
