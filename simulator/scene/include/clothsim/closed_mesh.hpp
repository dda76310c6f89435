// Closed collider meshes: is a triangle mesh closed, which way do its faces point (signed
// volume), and which points are inside it (generalised winding number). Plain geometry on
// Eigen: no GL, no file format. Used at start-up to warn about a collider whose faces point
// inwards and about cloth masses that start inside a collider (docs/scenes.md, "Start-up
// warnings").
#pragma once

#include <clothsim/collision.hpp>
#include <clothsim/sim.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace clothsim {

/// A triangle soup: corners.col(3 t + k) is corner k of triangle t (counter-clockwise seen
/// from the front: the normal is (B - A) x (C - A)).
using TriangleCorners = Eigen::Matrix3Xd;

struct SolidInfo {
  /// Every edge is shared by exactly two triangles that run along it in opposite directions
  /// (corners are identified by exact position; triangles with two equal corners are ignored).
  /// False for an empty mesh.
  bool closed = false;
  /// m^3, sum over the triangles of A . (B x C) / 6 about the first corner: the enclosed volume
  /// when closed, positive when the faces point outwards, negative when they point inwards.
  double signed_volume = 0.0;
};
/// The whole mesh as one solid, from b2o::solid_parts() (blender2ogl/solid_parts.hpp: the
/// check the bake makes, part by part; collider_warnings() reports its parts).
SolidInfo analyse_solid(const TriangleCorners& corners);

/// Generalised winding number of the triangles around p (van Oosterom-Strackee solid angles
/// / 4 pi): for a closed mesh +1 inside with outward faces, -1 inside with inward faces, 0
/// outside (about +-0.5 on the surface).
double winding_number(const TriangleCorners& corners, const Eigen::Vector3d& p);

/// The most point-triangle tests count_inside() does by default: one test costs ~25 ns
/// (three square roots and an atan2), so at most ~1 s at start-up.
inline constexpr double kInsideWorkBudget = 4e7;

/// How many of `points` (3 x n) are inside the closed mesh (|winding number| > 0.5); points
/// outside its bounding box are outside without a test. -1 when the work, points in the box
/// times triangles, would exceed `work_budget`.
std::int64_t count_inside(const TriangleCorners& corners, const Eigen::Matrix3Xd& points,
                          double work_budget = kInsideWorkBudget);
/// Masses of `points` whose nearest triangle of open collider object o (within the points'
/// bounding-box diagonal, at least 2 eps) has them behind it (the foot on the plane on the
/// triangle, the signed distance < 0; not beside the collider's rim): `in_band` within 2 eps of it, `farther` beyond.
struct BehindCount {
  std::size_t in_band = 0, farther = 0;
};
BehindCount count_behind(const ColliderSet& set, std::size_t o, const Eigen::Matrix3Xd& points, double eps);

/// Free masses of `points` (`pinned[i]` 0, or `pinned` empty) in front of collider object o
/// within its contact band (0 <= d < eps) that its penalty pushes at once by more than `times`
/// their weight: k_rep (eps - d) > times m_i |g| (`mass` per point; a mass at rest sits at
/// eps - m g / k_rep); with no gravity, any push. `worst`: the largest push over the weight
/// (0 without gravity), `worst_push` the largest push, N.
struct LaunchCount {
  std::size_t count = 0;
  double worst = 0.0, worst_push = 0.0;
};
LaunchCount count_launched(const ColliderSet& set, std::size_t o, const Eigen::Matrix3Xd& points,
                           const Eigen::VectorXd& mass, const std::vector<std::uint8_t>& pinned, double eps,
                           double k_rep, double gravity, double times);

/// The start-up warnings about a model's colliders, one line each, "warning: ...": per
/// collider object, closed parts whose faces point inwards (negative signed volume) or both
/// ways (b2o::solid_parts(), as the bake warns), and, for an object that is a closed solid,
/// the cloth masses (at x0) that start inside it (skipped silently above the work budget);
/// for an open collider, the masses that start behind its faces (count_behind()); for any
/// collider, masses that start so deep in its contact band that it throws them (more than 10x
/// their weight: count_launched()). Empty without colliders.
std::vector<std::string> collider_warnings(const Model& model, double work_budget = kInsideWorkBudget);

}  // namespace clothsim
