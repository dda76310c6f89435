// Penalty response: the forces that push cloth points out of the colliders (report eq. 12).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>

#include "clothsim/collision/collider_set.hpp"
#include "clothsim/collision/contact_cache.hpp"

namespace clothsim {

/// What one accumulate_penalty() call saw.
struct PenaltyStats {
  double max_penetration = 0.0;  ///< m, deepest a point was BEHIND a surface (-d for d < 0), >= 0
  std::size_t contacts = 0;      ///< (point, object) pairs with -eps <= d <= eps (a force)
  std::size_t tunnelled = 0;     ///< (point, object) pairs with -2 eps <= d < -eps (no force)
  std::size_t nonfinite_points = 0;  ///< points with a NaN/inf coordinate (skipped)
  std::size_t certified = 0;  ///< (point, object) pairs answered from a ContactCache certificate
};

/// Penalty response, report eq. 12 with the unit normal: for each point i and each collider
/// object, with d the signed distance to the object's closest triangle (normal n):
///   -eps <= d <= eps : f_i += k_rep * (eps - d) * n    (pushed to the front side)
///   -2eps <= d < -eps: tunnelled, no force, counted; deeper: not seen.
/// `f` (3 x n, same size as x) is ADDED to. `stats` is overwritten. `hints` is empty or has
/// x.cols() * set.object_count() entries (point-major), initialised to -1 and kept between
/// steps; it only speeds up the search. Never allocates. Throws std::logic_error if the set
/// is not built or sizes disagree.
void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, double eps,
                        double k_rep, Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats,
                        std::span<std::int32_t> hints = {},
                        QueryMethod method = QueryMethod::Bvh);

/// The same, with a ContactCache (resized to x.cols() x set.object_count()) instead of hints:
/// bit-identical forces and stats (but `certified`), much less work for points that move
/// little between calls (cloth at rest). Throws std::invalid_argument on a wrong cache size.
void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, double eps,
                        double k_rep, Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats,
                        ContactCache& cache, QueryMethod method = QueryMethod::Bvh);

/// The same for the points [begin, end) of x only (the others are neither read nor written,
/// nor their cache entries): threads may share one cache, each with its own ranges. The
/// answers do not depend on how the points are split. Call cache.tick() once per step (the
/// other forms do it themselves): it only paces the making of plane certificates. Throws
/// std::invalid_argument on a range outside x.
void accumulate_penalty(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x,
                        std::size_t begin, std::size_t end, double eps, double k_rep,
                        Eigen::Ref<Eigen::Matrix3Xd> f, PenaltyStats& stats, ContactCache& cache,
                        QueryMethod method = QueryMethod::Bvh);

/// Position-based contact, for the points [begin, end) of x: for each point i and collider
/// object, with d the signed distance to the object's closest triangle (normal n), seen within
/// the band (searched to 2 band behind a surface):
///   -band <= d <= distance: push_i += (distance - d) n   (the move that puts i at `distance`)
/// The cache's band is `band` (call cache.tick() and cache.use_band(band) once per call of
/// the whole cloth, as the penalty's ranges do). `push` is added to. Throws
/// std::invalid_argument unless 0 < distance <= band.
void accumulate_push(const ColliderSet& set, Eigen::Ref<const Eigen::Matrix3Xd> x, std::size_t begin,
                     std::size_t end, double distance, double band, Eigen::Ref<Eigen::Matrix3Xd> push,
                     PenaltyStats& stats, ContactCache& cache);

}  // namespace clothsim
