// Plane records (ContactCache::Plane): make_plane() for a point over its answer's face,
// make_far() for one whose answer stays beyond the penalty band ("no force").
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "certificate.hpp"
#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::face_insides;
using detail::kBlock;
using detail::least_edge;
using detail::store_plane;

namespace {
// The least of face_insides() less the margin (-infinity on a sliver).
double inside_face(const double p[3], const double* t, std::size_t stride, double s) {
  double in[3], margin;
  if (!face_insides(p, t, stride, s, in, margin)) return -std::numeric_limits<double>::infinity();
  return in[least_edge(in)] - margin;
}
}  // namespace

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

}  // namespace clothsim
