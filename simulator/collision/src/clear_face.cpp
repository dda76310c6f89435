// The certificates that come from clearances: a clear face (a point over a face whose
// clearance keeps every other triangle out of the way), an edge answer (a point over a convex
// edge), and the walk from a face the point has left to the face or edge it is over now.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "certificate.hpp"
#include "clearance.hpp"
#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::better;
using detail::face_insides;
using detail::kBlock;
using detail::kEdgeEnds;
using detail::kEdgeZeta;
using detail::kLooseDepth;
using detail::kTau;
using detail::least_edge;
using detail::round_down;

bool detail::face_insides(const double p[3], const double* t, std::size_t stride, double s,
                          double in[3], double& margin) {
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

// face_insides() of one face at one point, computed once for the checks that need it.
[[gnu::always_inline]] inline bool ColliderSet::Feet::of(const double p[3], const double* t, std::size_t stride, double s) {
  if (!known) known = true, sliver = !face_insides(p, t, stride, s, in, margin);
  return !sliver;
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

}  // namespace clothsim
