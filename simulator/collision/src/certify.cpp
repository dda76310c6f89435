// certify_inline(): the certificate check accumulate_penalty() inlines for each (point, object)
// pair, from its entry's first candidates or a clear face, leaving plane records behind.
#include <cmath>
#include <cstddef>
#include <limits>

#include "certificate.hpp"
#include "collider.hpp"
#include "kernel.hpp"
#include "penalty.hpp"

namespace clothsim {

using detail::better;
using detail::certificate_margin;
using detail::kBlock;
using detail::kCopyAbove;
using detail::kMinAge;
using detail::moved_from;
using detail::plane_due;
using detail::plane_failed;
using detail::store_plane;

[[gnu::always_inline]] inline bool ColliderSet::certify_inline(
    std::size_t o, const double p[3], double radius_sq, ContactCache& cache, std::size_t ei,
    bool& hit, double& signed_distance, double normal[3], Evaluated* pre, Answer* answer) const {
  ContactCache::Entry& e = cache.entries[ei];
  if (e.count < 0) return false;
  const bool records = radius_sq == cache.band_reach_sq;  // plane records hold for this reach
  const double band = cache.band;
  const Object& ob = objects_[o];
  // The same m, moved and comparisons as query_cached(): the same decisions.
  const double m = certificate_margin(p, ob.scale);
  const double moved = moved_from(p, e.x0);
  const double reach = std::sqrt(radius_sq);
  if (e.count == 0) {  // nothing was in reach: still none while L - moved stays beyond reach
    if (!(reach + moved + m < e.others_lb)) return false;
    hit = false;
    ContactCache::Plane& pl = cache.entries[ei].plane;
    if (records && plane_due(cache, e, pl) &&
        !store_plane(pl, cache.epoch, p, e.others_lb - moved - m - reach - m, false))
      plane_failed(e);
  } else {
    const float* cl = cache.lower.data() + ei * cache.candidates();
    if (static_cast<double>(cl[0]) - moved - m > reach) return false;
    // The corners are read in place (a Tri filled from either source is spilled to the
    // stack and read back, a stall).
    double s, d2;
    const double* n;
    std::size_t stride;
    bool face;  // the closest point is inside the face (else neither a clear face nor a plane)
    if (ob.kept > kCopyAbove) {
      const double* t = cache.firsts.data() + 12 * ei;
      d2 = detail::closest_sq<1>(p, t, s, face);
      n = t + 9, stride = 1;
    } else {
      const double* t = tri_ptr(cache.slots[ei * cache.candidates()]);
      d2 = detail::closest_sq<kBlock>(p, t, s, face);
      n = t + 9 * kBlock, stride = kBlock;
    }
    if (!(d2 <= radius_sq)) return false;
    double d = std::sqrt(d2);
    // A clear face needs the foot inside the face by a margin (1e-6 of the coordinates) far
    // beyond the kernel's rounding: outside the face branch clear_radius() cannot answer, and
    // a small collider skips it (a large one computes the feet for the walk).
    if (s > 0.0 && (face || ob.kept > kCopyAbove)) {
      // A clear face (see clear_radius()): the answer whatever the list says, and a record
      // that lasts while the point stays over the face, however near the other triangles tie.
      Feet feet;  // of the first candidate at p
      const std::uint32_t slot0 = cache.slots[ei * cache.candidates()];
      double r = clear_radius(o, slot0, p, n - 9 * stride, stride, d, s, m, reach, feet);
      if (!(r > 0.0) && feet.known && !feet.sliver && ob.kept > kCopyAbove) {
        // The point has left the face: the face across the edge it crossed, or that edge
        // (walk_on(); only on large colliders: on a fine mesh nearly equidistant triangles
        // tie within microns and lists die young; on a small one the list answers for less,
        // and it is moved along with the point, which an edge answer is not).
        const double* t = n - 9 * stride;
        const int walked = walk_on(o, p, radius_sq, reach, m, cache, ei, slot0, feet, d2, d, s, t, stride, r);
        if (walked == 2) {  // over the edge: t is the better of the two faces
          n = t + 9 * stride;
          hit = true;
          signed_distance = detail::signed_from(d, s);
          normal[0] = n[0], normal[1] = n[stride], normal[2] = n[2 * stride];
          if (answer) answer->tri = n - 9 * stride, answer->stride = stride;
          if (e.age < kMinAge) ++e.age;
          return true;
        }
        n = t + 9 * stride;  // walked == 1: the neighbour, with its record radius r
      }
      if (r > 0.0) {
        hit = true;
        signed_distance = detail::signed_from(d, s);
        normal[0] = n[0], normal[1] = n[stride], normal[2] = n[2 * stride];
        if (answer) answer->tri = n - 9 * stride, answer->stride = stride;
        ContactCache::Plane& pl = cache.entries[ei].plane;
        if (records && plane_due(cache, e, pl)) {
          pl.a[0] = n[-9 * static_cast<std::ptrdiff_t>(stride)];
          pl.a[1] = n[-8 * static_cast<std::ptrdiff_t>(stride)];
          pl.a[2] = n[-7 * static_cast<std::ptrdiff_t>(stride)];
          pl.n[0] = n[0], pl.n[1] = n[stride], pl.n[2] = n[2 * stride];
          if (!store_plane(pl, cache.epoch, p, r, true)) plane_failed(e);
        }
        if (e.age < kMinAge) ++e.age;
        return true;
      }
    }
    const bool alone = e.count == 1 || static_cast<double>(cl[1]) - moved - m > d;
    double loser = std::numeric_limits<double>::infinity();  // the other evaluated candidate
    double loser_s = 0.0;                                     // and its plane distance
    if (!alone) {
      // The second candidate may be as near (a point over an edge between two triangles, or
      // one whose second triangle is only a little farther): evaluate it too, here. (In the
      // second case query_cached() would move the certificate, but the gap of a sliding point
      // is gone again a step later: ~700 full checks per step on the skirt's sphere.)
      const double* t = tri_ptr(cache.slots[ei * cache.candidates() + 1]);
      const double d2a = d2, sa = s;  // the first candidate's, for query_cached_from()
      double s1;
      bool face1;
      const double d2b = detail::closest_sq<kBlock>(p, t, s1, face1);
      const std::int32_t idx1 = orig_[cache.slots[ei * cache.candidates() + 1]];
      if (d2b <= radius_sq && better(d2b, idx1, d2, e.tri_index)) {
        loser = d, loser_s = s;
        d2 = d2b, s = s1, n = t + 9 * kBlock, stride = kBlock, face = face1;
        d = std::sqrt(d2);
      } else {
        loser = std::sqrt(d2b), loser_s = s1;
      }
      if (e.count > 2 && !(static_cast<double>(cl[2]) - moved - m > d)) {
        // A third may tie (a point near a vertex of the collider): the full check goes on
        // from here instead of evaluating these two again (~750 calls per step while the
        // skirt_hires cloth slides over its sphere).
        if (pre) *pre = Evaluated{2, {d2a, d2b}, {sa, s1}};
        return false;
      }
    }
    // the other candidates and every other triangle stay farther: this is the answer
    if (!(d + moved + m < e.others_lb)) return false;
    hit = true;
    signed_distance = detail::signed_from(d, s);
    normal[0] = n[0], normal[1] = n[stride], normal[2] = n[2 * stride];
    if (answer) answer->tri = n - 9 * stride, answer->stride = stride;
    // The next calls can take a plane certificate (the loser: the other evaluated one): "no
    // force" beyond the band (which holds over edges too), else this face (only from inside
    // it: make_plane() fails elsewhere, as clear_radius() does).
    if (records && plane_due(cache, e, cache.entries[ei].plane) &&
        !(d > band && make_far(p, cache, ei, d, s, alone ? 1 : 2, loser, loser_s, moved, m, band)) &&
        !(face && make_plane(p, cache, ei, n - 9 * stride, stride, d, s, alone ? 1 : 2, loser, moved, m,
                             reach)))
      plane_failed(e);
  }
  if (e.age < kMinAge) ++e.age;
  return true;
}

bool ColliderSet::certify_fast(std::size_t o, const double p[3], double radius_sq,
                               ContactCache& cache, std::size_t ei, bool& hit,
                               double& signed_distance, double normal[3]) const {
  return certify_inline(o, p, radius_sq, cache, ei, hit, signed_distance, normal);
}

bool detail::PenaltyLoop::certify(const ColliderSet& set, std::size_t o, const double p[3],
                                  double radius_sq, ContactCache& cache, std::size_t ei, bool& hit,
                                  double& signed_distance, double normal[3], Evaluated& pre,
                                  Answer& answer) {
  return set.certify_inline(o, p, radius_sq, cache, ei, hit, signed_distance, normal, &pre, &answer);
}

}  // namespace clothsim
