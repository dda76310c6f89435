// What the penalty loop's files share: PenaltyLoop, its access to the ColliderSet's
// internals, and PenaltyPass, one accumulate_penalty() call's inputs and the steps of its
// per-point loop, which the scalar loop (penalty.cpp) and the AVX2 one (penalty_avx2.cpp)
// both inline.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "clothsim/collision/collider_set.hpp"
#include "clothsim/collision/contact_cache.hpp"
#include "clothsim/collision/penalty.hpp"
#include "clothsim/cpu.hpp"
#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim::detail {

// Squared distance from p to the axis-aligned box [lo, hi] (0 inside).
inline double box_dist_sq(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const double p[3]) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double e = p[k] < lo[k] ? lo[k] - p[k] : (p[k] > hi[k] ? p[k] - hi[k] : 0.0);
    d2 += e * e;
  }
  return d2;
}

/// accumulate_penalty()'s way to the inlined check.
struct PenaltyLoop {
  /// Object o's padded box and whether it has triangles (out_of_reach()'s data).
  static bool box(const ColliderSet& set, std::size_t o, const double*& lo, const double*& hi) {
    const ColliderSet::Object& ob = set.objects_[o];
    lo = ob.lo.data(), hi = ob.hi.data();
    return ob.kept > 0;
  }
  using Evaluated = ColliderSet::Evaluated;
  using Answer = ColliderSet::Answer;
  /// out_of_reach(), inlined into the per-point loops.
  static bool out_of_reach(const ColliderSet& set, std::size_t o, const double p[3], double radius_sq) {
    const ColliderSet::Object& ob = set.objects_[o];
    return ob.kept == 0 || box_dist_sq(ob.lo, ob.hi, p) > radius_sq;
  }
  /// certify_inline() (certify.cpp), for the points that no plane record answers.
  static bool certify(const ColliderSet& set, std::size_t o, const double p[3], double radius_sq,
                      ContactCache& cache, std::size_t ei, bool& hit, double& signed_distance,
                      double normal[3], Evaluated& pre, Answer& answer);
  /// Whether object o has a rim (an edge not shared by exactly two triangles).
  static bool open(const ColliderSet& set, std::size_t o) { return set.objects_[o].open; }
  /// The kept triangle data of a hit (its input triangle index): component k at [k * kBlock].
  static const double* triangle_data(const ColliderSet& set, const ColliderHit& h) {
    const ColliderSet::Object& ob = set.objects_[static_cast<std::size_t>(h.object)];
    return set.tri_ptr(static_cast<std::uint32_t>(ob.input_to_kept[static_cast<std::size_t>(h.triangle)]));
  }
  static ColliderHit query_cached(const ColliderSet& set, std::size_t o, const double p[3],
                                  double radius_sq, QueryMethod method, ContactCache& cache,
                                  std::size_t ei, bool& certified, const Evaluated& pre) {
    return set.query_cached_from(o, p, radius_sq, method, cache, ei, certified, pre);
  }
};

/// One accumulate_penalty() call: its checked inputs, and its steps for one point and one
/// (point, object) pair, inlined into both loops (the pair's common case is the hot path).
struct PenaltyPass {
  const ColliderSet& set;
  double eps, k_rep;
  double rest;           ///< where the force ends: eps for the penalty, the contact distance for a push
  PenaltyStats& stats;
  std::span<std::int32_t> hints;
  ContactCache* cache;
  QueryMethod method;
  std::size_t no;        ///< set.object_count()
  double reach_sq;       ///< (2 eps)^2, how far the searches look
  bool planes;           ///< the cache's plane records hold for this eps
  Eigen::Vector3d lo, hi;  ///< the padded box of every collider
  const double* px;      ///< x, column i at px + i * xs
  double* pf;            ///< f, column i at pf + i * fs
  Eigen::Index xs, fs;

  // Eq. 12 for one (point, object) answer: d signed distance, n unit normal (rest = eps: the
  // penalty; rest < eps: a push to the distance rest, seen within the band eps).
  void respond(double* fi, double d, const double* nrm) {
    if (d < 0.0) stats.max_penetration = std::max(stats.max_penetration, -d);
    if (d > rest) return;
    if (d < -eps) {
      ++stats.tunnelled;
      return;
    }
    ++stats.contacts;
    const double c = k_rep * (rest - d);  // f_i += (k_rep (rest - d)) n
    fi[0] += c * nrm[0];
    fi[1] += c * nrm[1];
    fi[2] += c * nrm[2];
  }
  // An answer of the searches and lists (not of a plane record, which is always over a face):
  // in an edge or corner region, within the band, the distance and direction of the closest
  // point instead of the face's (detail::edge_contact()).
  void respond_at(double* fi, std::size_t o, const double p[3], double d, const double* nrm,
                  const double* tri, std::size_t stride) {
    double dd = d, dir[3];
    TriangleRegion region;
    if (tri != nullptr && d <= eps) {
      const int edge = detail::edge_contact(p, tri, stride, detail::PenaltyLoop::open(set, o), dd, dir, region);
      // (2: behind a face of a closed solid, beside an edge or corner: outside beside a sharp one)
      if (edge == 1 || (edge == 2 && set.outside_at_feature(o, p, tri, stride, region, dir)))
        return respond(fi, dd, dir);
    }
    respond(fi, d, nrm);
  }
  // Everything but a certificate's common case, kept out of the loop.
  [[gnu::noinline]] void full(std::size_t i, std::size_t o, const double p[3],
                              const PenaltyLoop::Evaluated& pre);
  // One (point, object) pair: the object's box, the plane certificate, the inlined check, the rest.
  [[gnu::always_inline]] void pair(std::size_t i, std::size_t o, const double p[3]) {
    // Far from this object: nothing in reach, and its cache entry is left as it is (a
    // certificate stays true wherever the point goes: it is checked against the distance
    // moved since it was made).
    if (PenaltyLoop::out_of_reach(set, o, p, reach_sq)) {
      if (!hints.empty()) hints[i * no + o] = -1;
      return;
    }
    if (planes) {  // the plane certificate: the common case in one cache line
                  // (after the box test: a point far from the object reads no cache)
      const ContactCache::Plane& pl = cache->entries[i * no + o].plane;
      const double dx = p[0] - static_cast<double>(pl.x0[0]),
                   dy = p[1] - static_cast<double>(pl.x0[1]),
                   dz = p[2] - static_cast<double>(pl.x0[2]);
      const double r2 = static_cast<double>(pl.radius_sq());
      if (dx * dx + dy * dy + dz * dz < std::abs(r2)) [[likely]] {
        ++stats.certified;
        if (r2 > 0.0) {  // over the face: the kernel's face branch, the same arithmetic
          const double apx = p[0] - pl.a[0], apy = p[1] - pl.a[1], apz = p[2] - pl.a[2];
          const double s = pl.n[0] * apx + pl.n[1] * apy + pl.n[2] * apz;
          // signed_distance(s * s, s) without its square root: in binary floating point
          // sqrt(s * s) is exactly |s| unless s * s underflows (Boldo 2015), and then the
          // sign rule gives s, or +0 for -0 (tested bit for bit against the kernel).
          const double d =
              std::abs(s) >= 1e-150 ? s : detail::signed_distance(s * s, s);
          respond(pf + static_cast<Eigen::Index>(i) * fs, d, pl.n);
        }
        return;
      }
    }
    bool hit = false;
    double d = 0.0, nrm[3];
    detail::PenaltyLoop::Evaluated pre;
    detail::PenaltyLoop::Answer answer;
    if (cache &&
        detail::PenaltyLoop::certify(set, o, p, reach_sq, *cache, i * no + o, hit, d, nrm, pre, answer))
        [[likely]] {
      ++stats.certified;
      if (hit) respond_at(pf + static_cast<Eigen::Index>(i) * fs, o, p, d, nrm, answer.tri, answer.stride);
    } else {
      full(i, o, p, pre);
    }
  }
  // One point, object by object (a NaN point, or one far from every collider, is skipped).
  [[gnu::always_inline]] void point(std::size_t i) {
    const double* xi = px + static_cast<Eigen::Index>(i) * xs;
    const double p[3] = {xi[0], xi[1], xi[2]};
    const bool finite = std::isfinite(p[0] + p[1] + p[2]);
    if (!finite || box_dist_sq(lo, hi, p) > reach_sq) [[unlikely]] {  // NaN, or far from every collider
      if (!finite) ++stats.nonfinite_points;
      if (!hints.empty()) std::fill_n(hints.begin() + static_cast<std::ptrdiff_t>(i * no), no, -1);
      // A NaN point's entries start again; a far point's are left as they are (its
      // certificates stay true wherever it goes, as for one object's box in pair()): writing
      // them would cost two cache lines per point and step while the cloth is away.
      if (cache && !finite)
        for (std::size_t o = 0; o < no; ++o) cache->entries[i * no + o].count = -1;
      return;
    }
    for (std::size_t o = 0; o < no; ++o) pair(i, o, p);
  }
};

#ifdef CLOTHSIM_AVX2
/// The pass's points [i, end) four at a time (penalty_avx2.cpp); returns where it stopped.
__attribute__((target("avx2"))) std::size_t groups_avx2(PenaltyPass& pass, std::size_t i, std::size_t end);
#endif

}  // namespace clothsim::detail
