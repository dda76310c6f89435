// accumulate_penalty(): for every cloth point and collider object, the answer from a plane
// record, a certificate or a search, and the penalty force of report eq. 12.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <span>
#include <stdexcept>

#include "clothsim/collision/penalty.hpp"
#include "collider.hpp"
#include "penalty.hpp"

namespace clothsim {

bool ColliderSet::out_of_reach(std::size_t o, const double p[3], double radius_sq) const {
  return detail::PenaltyLoop::out_of_reach(*this, o, p, radius_sq);
}

void detail::PenaltyPass::full(std::size_t i, std::size_t o, const double p[3],
                               const PenaltyLoop::Evaluated& pre) {
  ColliderHit h;
  if (cache) {
    bool certified = false;
    h = detail::PenaltyLoop::query_cached(set, o, p, reach_sq, method, *cache, i * no + o,
                                          certified, pre);
    if (certified) ++stats.certified;
  } else {
    const std::int32_t hint = hints.empty() ? -1 : hints[i * no + o];
    h = set.query_object(o, p, reach_sq, method, hint);
    if (!hints.empty()) hints[i * no + o] = h.triangle;
  }
  if (h.valid()) respond_at(pf + static_cast<Eigen::Index>(i) * fs, o, p, h.signed_distance, h.normal.data(),
                            detail::PenaltyLoop::triangle_data(set, h), kBlock);
}


namespace {

void accumulate_impl(const ColliderSet& set, const Eigen::Ref<const Eigen::Matrix3Xd>& x, double eps,
                     double k_rep, Eigen::Ref<Eigen::Matrix3Xd>& f, PenaltyStats& stats, std::span<std::int32_t> hints,
                     ContactCache* cache, QueryMethod method, std::size_t begin = 0,
                     std::size_t end = std::numeric_limits<std::size_t>::max(), double rest = -1.0) {
  if (rest < 0.0) rest = eps;
  if (!set.built()) throw std::logic_error("accumulate_penalty(): ColliderSet not built");
  if (!(eps > 0.0) || !std::isfinite(eps) || !(k_rep >= 0.0) || !std::isfinite(k_rep))
    throw std::invalid_argument("accumulate_penalty(): need eps > 0 and k_rep >= 0, finite");
  if (f.cols() != x.cols())
    throw std::invalid_argument("accumulate_penalty(): f and x differ in size");
  const std::size_t no = set.object_count();
  const auto n = static_cast<std::size_t>(x.cols());
  if (!hints.empty() && hints.size() != n * no)
    throw std::invalid_argument("accumulate_penalty(): hints need points * objects entries");
  if (cache && (cache->entries.size() != n * no ||
                cache->slots.size() != n * no * cache->candidates() ||
                cache->lower.size() != n * no * cache->candidates() ||
                cache->firsts.size() != n * no * 12))
    throw std::invalid_argument("accumulate_penalty(): ContactCache needs resize(points, objects)");
  if (end > n) end = n;
  if (begin > end)
    throw std::invalid_argument("accumulate_penalty(): point range outside the cloth");
  stats = PenaltyStats{};
  if (no == 0 || set.triangle_count() == 0) return;

  // Search to 2 eps so that points just past the band behind a surface are seen (tunnelled).
  const double reach = 2.0 * eps, reach_sq = reach * reach;
  const bool planes = cache && cache->band == eps;  // its plane records hold for this eps
  const Eigen::Vector3d lo = set.bounds_min(), hi = set.bounds_max();
  const double* px = x.data();
  double* pf = f.data();
  const Eigen::Index xs = x.outerStride(), fs = f.outerStride();
  detail::PenaltyPass pass{set, eps, k_rep, rest, stats, hints, cache, method, no, reach_sq, planes, lo, hi,
                           px, pf, xs, fs};
  std::size_t i = begin;
#ifdef CLOTHSIM_AVX2
  if (planes && xs == 3 && fs == 3 && detail::use_avx2()) {
    // Four points at a time (the same arithmetic, the same bits)
    i = detail::groups_avx2(pass, i, end);
  }
#endif
  for (; i < end; ++i) pass.point(i);
}

}  // namespace

void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, double eps,
                        double k_rep, Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats,
                        std::span<std::int32_t> hints, QueryMethod method) {
  accumulate_impl(set, x, eps, k_rep, f, stats, hints, nullptr, method);
}

void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, double eps,
                        double k_rep, Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats,
                        ContactCache& cache, QueryMethod method) {
  cache.tick();
  cache.use_band(eps);
  accumulate_impl(set, x, eps, k_rep, f, stats, {}, &cache, method);
}

void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x,
                        std::size_t begin, std::size_t end, double eps, double k_rep,
                        Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats, ContactCache& cache,
                        QueryMethod method) {
  if (begin > end || end > static_cast<std::size_t>(x.cols()))
    throw std::invalid_argument("accumulate_penalty(): point range outside the cloth");
  accumulate_impl(set, x, eps, k_rep, f, stats, {}, &cache, method, begin, end);
}

void accumulate_push(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, std::size_t begin,
                     std::size_t end, double distance, double band, Eigen::Ref<Eigen::Matrix3Xd> push,
                     PenaltyStats& stats, ContactCache& cache) {
  if (begin > end || end > static_cast<std::size_t>(x.cols()))
    throw std::invalid_argument("accumulate_push(): point range outside the cloth");
  if (!(distance > 0.0) || !(band >= distance) || !std::isfinite(band))
    throw std::invalid_argument("accumulate_push(): need 0 < distance <= band, finite");
  accumulate_impl(set, x, band, 1.0, push, stats, {}, &cache, QueryMethod::Bvh, begin, end, distance);
}

}  // namespace clothsim
