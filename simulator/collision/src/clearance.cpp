// Clearances: per triangle (around its first corner) and per edge (around its midpoint), how
// far every other triangle of the object stays out of the way of points over the face or the
// edge. A scan of the BVH, nearest boxes first, computed once per triangle when first needed.
#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>

#include "bvh.hpp"
#include "clearance.hpp"
#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::kBlock;
using detail::kEdgeEnds;
using detail::kEdgeZeta;
using detail::kLooseDepth;
using detail::kTau;
using detail::load4;
using detail::pos;
using detail::round_down;
using detail::StackEntry;
using detail::v4f;
using detail::vabs;

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

double ColliderSet::clearance(std::size_t o, std::size_t t) const {
  const std::int32_t slot = objects_.at(o).input_to_kept.at(t);
  return slot < 0 ? 0.0 : static_cast<double>(clear_at(o, static_cast<std::uint32_t>(slot)));
}

}  // namespace clothsim
