// The list certificate's full check (query_cached(), query_cached_from()): the candidates,
// nearest first, against the bound of every other triangle, and the certificate moved to the
// point; and its renewal by a search when it fails (renew_cached(): K-nearest or 1-nearest).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <span>

#include "certificate.hpp"
#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::better;
using detail::certificate_margin;
using detail::kBlock;
using detail::kCopyAbove;
using detail::kMaxCandidates;
using detail::kMinAge;
using detail::kRetry;
using detail::moved_from;
using detail::round_down;

ColliderHit ColliderSet::query_cached(std::size_t o, const double p[3], double radius_sq,
                                      QueryMethod method, ContactCache& cache, std::size_t ei,
                                      bool& certified) const {
  return query_cached_from(o, p, radius_sq, method, cache, ei, certified, Evaluated{});
}

ColliderHit ColliderSet::query_cached_from(std::size_t o, const double p[3], double radius_sq,
                                           QueryMethod method, ContactCache& cache,
                                           std::size_t ei, bool& certified,
                                           const Evaluated& pre) const {
  ContactCache::Entry& e = cache.entries[ei];
  certified = false;
  if (e.count < 0) return renew_cached(o, p, radius_sq, method, cache, ei);
  const Object& ob = objects_[o];
  std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
  float* cl = cache.lower.data() + ei * cache.candidates();
  const bool use_copy = ob.kept > kCopyAbove;
  const double* first = cache.firsts.data() + 12 * ei;
  // Rounding of the computed distances, far below any useful gap.
  const double m = certificate_margin(p, ob.scale);
  const double moved = moved_from(p, e.x0);
  // Every candidate is now >= lower - moved away, every other triangle >= others_lb - moved.
  // Evaluate the candidates nearest first until the rest cannot win or tie (or reach).
  double best = std::numeric_limits<double>::infinity(), best_s = 0.0, stop = std::sqrt(radius_sq);
  double best_n[3] = {0.0, 0.0, 0.0};
  std::int32_t best_tri = std::numeric_limits<std::int32_t>::max();
  double dist[kMaxCandidates];  // distances of the evaluated candidates
  std::int32_t evaluated = 0;
  for (; evaluated < e.count; ++evaluated) {
    const std::int32_t c = evaluated;
    if (static_cast<double>(cl[c]) - moved - m > stop) break;
    double s, d2;
    const double* n;  // the normal's components at n[0], n[stride], n[2 stride]
    std::size_t stride;
    const bool known = c < pre.count;  // evaluated by certify_inline(), the same way
    if (c == 0 && use_copy) {
      d2 = known ? (s = pre.s[c], pre.d2[c]) : detail::closest_sq<1>(p, first, s);
      n = first + 9, stride = 1;
    } else {
      const double* t = tri_ptr(cs[c]);
      d2 = known ? (s = pre.s[c], pre.d2[c]) : detail::closest_sq<kBlock>(p, t, s);
      n = t + 9 * kBlock, stride = kBlock;
    }
    dist[c] = std::sqrt(d2);
    const std::int32_t idx = c == 0 ? e.tri_index : orig_[cs[c]];
    if (d2 <= radius_sq && better(d2, idx, best, best_tri)) {
      best = d2, best_tri = idx, best_s = s;
      best_n[0] = n[0], best_n[1] = n[stride], best_n[2] = n[2 * stride];
      stop = dist[c];
    }
  }
  if (!(stop + moved + m < e.others_lb)) return renew_cached(o, p, radius_sq, method, cache, ei);
  certified = true;
  ColliderHit hit;
  if (best_tri != std::numeric_limits<std::int32_t>::max()) {
    hit.object = static_cast<std::int32_t>(o);
    hit.triangle = best_tri;
    hit.distance_sq = best;
    hit.signed_distance = detail::signed_distance(best, best_s);
    hit.normal = Eigen::Vector3d(best_n[0], best_n[1], best_n[2]);
  }
  if (e.age < kMinAge) ++e.age;
  if (evaluated > e.settled && moved > 0.0) {
    // Move the certificate here: the same facts, measured from p. The evaluated candidates
    // get their distances now (so the next call evaluates only the near-ties), the others
    // and L lose what the point moved (and a rounding margin). Kept ascending. Only when
    // more candidates than the near-ties of the last move (`settled`) had to be evaluated:
    // a point at rest writes nothing, even on an edge between two triangles.
    e.x0[0] = p[0], e.x0[1] = p[1], e.x0[2] = p[2];
    e.others_lb -= moved + m;
    const std::uint32_t first_slot = e.count > 0 ? cs[0] : 0;
    for (std::int32_t c = 0; c < e.count; ++c) {
      const float lo = round_down(c < evaluated ? dist[c] - m
                                                : static_cast<double>(cl[c]) - moved - m);
      const std::uint32_t sl = cs[c];
      std::int32_t j = c;
      for (; j > 0 && cl[j - 1] > lo; --j) cl[j] = cl[j - 1], cs[j] = cs[j - 1];
      cl[j] = lo, cs[j] = sl;
    }
    std::int32_t ties = 0;
    while (ties < e.count && static_cast<double>(cl[ties]) - m <= stop) ++ties;
    e.settled = static_cast<std::uint8_t>(std::clamp(ties, 1, 255));
    if (e.count > 0 && cs[0] != first_slot) {
      e.tri_index = orig_[cs[0]];
      if (use_copy) {
        const detail::Tri t = tri_at(cs[0]);
        std::memcpy(cache.firsts.data() + 12 * ei, &t, sizeof t);
      }
    }
  }
  return hit;
}

ColliderHit ColliderSet::renew_cached(std::size_t o, const double p[3], double radius_sq,
                                      QueryMethod method, ContactCache& cache,
                                      std::size_t ei) const {
  const Object& ob = objects_[o];
  ContactCache::Entry& e = cache.entries[ei];
  const std::size_t k = std::min(cache.candidates(), kMaxCandidates);
  std::uint32_t* cs = cache.slots.data() + ei * cache.candidates();
  float* cl = cache.lower.data() + ei * cache.candidates();
  const bool use_copy = ob.kept > kCopyAbove;
  const double m = certificate_margin(p, ob.scale);
  const auto set_first = [&] {
    e.tri_index = orig_[cs[0]];
    if (use_copy) {
      const detail::Tri t = tri_at(cs[0]);
      std::memcpy(cache.firsts.data() + 12 * ei, &t, sizeof t);
    }
  };
  // A search. K-nearest (a list) unless lists die young here (see kMinAge, kRetry). A list
  // that died young makes the wait before the next one twice as long (up to 128x).
  // (lean == 0: the last search made a list; lean > 0: 1-nearest searches since.)
  if (k > 1 && e.count >= 0 && e.lean == 0)
    e.backoff = e.age >= kMinAge ? 0 : static_cast<std::uint8_t>(std::min(e.backoff + 1, 7));
  const bool list =
      k > 1 && (e.count < 0 || e.age >= kMinAge || e.lean >= (kRetry << e.backoff));
  e.lean = list ? 0 : static_cast<std::uint16_t>(std::min(e.lean + 1, 0xffff));
  e.age = 0;
  e.settled = 1;
  e.x0[0] = p[0], e.x0[1] = p[1], e.x0[2] = p[2];
  if (!list) {  // 1-nearest (the single-triangle certificate)
    double lb = 0.0;
    const ColliderHit hit =
        query_object(o, p, radius_sq, method, e.count >= 1 ? e.tri_index : -1, &lb);
    // Another triangle ties with the answer (within 4 m; a point near a vertex): a
    // single-triangle certificate cannot hold for one call there. On a small collider,
    // whose lists live long, a list is made at once instead (1.0 % fewer instructions in
    // skirt_hires's first 2 s; not on large ones: on fine spheres, whose lists die young, it
    // costs up to 1.4 %).
    const bool tie = k > 1 && ob.kept <= kCopyAbove && hit.valid() &&
                     !(std::sqrt(hit.distance_sq) + 4.0 * m < lb);
    if (!tie) {
      e.others_lb = lb;
      e.count = hit.valid() ? 1 : 0;
      if (hit.valid()) {
        cs[0] = static_cast<std::uint32_t>(ob.input_to_kept[static_cast<std::size_t>(hit.triangle)]);
        cl[0] = round_down(std::sqrt(hit.distance_sq) - m);
        set_first();
      }
      return hit;
    }
    e.lean = 0;
  }
  std::uint32_t ns[kMaxCandidates];
  double nd[kMaxCandidates];
  double lb = 0.0;
  const std::size_t n =
      query_nearest(o, p, radius_sq, method, k,
                    std::span<const std::uint32_t>(cs, e.count > 0 ? static_cast<std::size_t>(e.count) : 0),
                    ns, nd, lb);
  e.others_lb = lb;
  e.count = static_cast<std::int32_t>(n);
  for (std::size_t c = 0; c < n; ++c) cs[c] = ns[c], cl[c] = round_down(std::sqrt(nd[c]) - m);
  if (n == 0) return ColliderHit{};
  set_first();
  const detail::Tri t = tri_at(ns[0]);
  double s, v, w;
  TriangleRegion region;
  const double d2 = detail::closest_sq(p, t, s, v, w, region);
  ColliderHit hit;
  hit.object = static_cast<std::int32_t>(o);
  hit.triangle = orig_[ns[0]];
  hit.distance_sq = d2;
  hit.signed_distance = detail::signed_distance(d2, s);
  hit.normal = Eigen::Vector3d(t.nx, t.ny, t.nz);
  return hit;
}

}  // namespace clothsim
