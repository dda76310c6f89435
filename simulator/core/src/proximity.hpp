// Closest points between cloth elements (Ericson, Real-Time Collision Detection, 5.1.5 and
// 5.1.9): a point and a triangle, two segments; with the weights that place the closest point
// on each element, which the self-contact stage uses to share a correction between masses.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace clothsim::detail {

inline void put(double w[3], double a, double b, double c) { w[0] = a, w[1] = b, w[2] = c; }

/// The closest point of triangle abc to p is w[0] a + w[1] b + w[2] c (w >= 0, sum 1).
inline void closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c, double w[3]) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return put(w, 1.0, 0.0, 0.0);
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return put(w, 0.0, 1.0, 0.0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return put(w, 1.0 - v, v, 0.0);
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return put(w, 0.0, 0.0, 1.0);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double v = d2 / (d2 - d6);
    return put(w, 1.0 - v, 0.0, v);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return put(w, 0.0, 1.0 - v, v);
  }
  const double denom = va + vb + vc;
  if (!(denom > 0.0)) return put(w, 1.0, 0.0, 0.0);  // (no area: its first corner)
  const double v = vb / denom, u = vc / denom;
  put(w, 1.0 - v - u, v, u);
}

inline void put(double& s, double& t, double s_value, double t_value) { s = s_value, t = t_value; }

/// The closest points of segments p1q1 and p2q2 are p1 + s (q1 - p1) and p2 + t (q2 - p2).
inline void closest_on_segments(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                                const Eigen::Vector3d& q2, double& s, double& t) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double kTiny = 1e-30;
  if (a <= kTiny && e <= kTiny) return put(s, t, 0.0, 0.0);
  if (a <= kTiny) return put(s, t, 0.0, std::clamp(f / e, 0.0, 1.0));
  const double c = d1.dot(r);
  if (e <= kTiny) return put(s, t, std::clamp(-c / a, 0.0, 1.0), 0.0);
  const double b = d1.dot(d2), denom = a * e - b * b;
  s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;  // (parallel: any s)
  t = (b * s + f) / e;
  if (t < 0.0) t = 0.0, s = std::clamp(-c / a, 0.0, 1.0);
  else if (t > 1.0) t = 1.0, s = std::clamp((b - c) / a, 0.0, 1.0);
}

}  // namespace clothsim::detail
