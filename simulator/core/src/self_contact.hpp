// The self-contact stage (docs/collision.md, "Self-contact"): cloth against cloth, a cloth
// against itself. Its memory between steps and the two calls step() makes around each
// integrator step. Private to the core.
#pragma once

#include "proximity.hpp"
#include "self_bvh.hpp"

#include <clothsim/step.hpp>

#include <array>
#include <limits>
#include <memory>
#include <unordered_set>
#include <vector>

namespace clothsim::detail {

/// Each free mass moves at most this fraction of its distance to the nearest element it is
/// not part of between two detections (Chen et al. 2024, 2025; Warp uses 0.42): two elements
/// then close at most 2 * 0.42 of their gap, and never meet.
inline constexpr double kSelfGamma = 0.42;
/// No gap closes below this part of its pair's target: a free mass's bound is kSelfGamma
/// times its pairs' gaps less it, so that a squeeze does not shrink gaps toward rounding. A
/// pair with a moving pin takes none: its free masses would stand still while the pin turns.
inline constexpr double kSelfLeastGap = 0.02;
/// The detection looks this many contact distances around each element, and its candidate
/// lists farther by a skin (a Verlet list's): they hold until a pair they lack has two masses
/// moved apart by more than the skin, or than its distance less `far` (self_lists.cpp). The
/// lists reach at most kSelfListReach of the mesh's typical shortest edge (its triangles'
/// median), so that they hold few pairs of neighbouring elements of one layer. The radius is
/// as large as allows `far` and a skin of one radius within kSelfRadiusReach of that edge, in
/// its range; the skin is at least the radius and at most kSelfSkinMost contact distances.
inline constexpr double kSelfRadiusLeast = 2.0, kSelfRadiusMost = 4.0;
inline constexpr double kSelfRadiusReach = 0.75, kSelfListReach = 0.85;
inline constexpr double kSelfSkinMost = 8.0;
/// The candidate lists' moves are bounded per cluster of at most this many masses.
inline constexpr std::uint32_t kSelfCluster = 16;
inline constexpr std::uint32_t kNoCluster = 0xffffffffu;
/// The lists' checks since a build may test 1 / kSelfCheckWeight of the node pairs and pairs
/// the build tested; past that the lists are built again (docs/performance.md, "Self-contact").
inline constexpr std::uint64_t kSelfCheckWeight = 4;
/// The candidate lists' joins split into this many parts for the threads.
inline constexpr std::size_t kSelfJoinTasks = 256;
/// Passes of pushes and bounds after each step.
inline constexpr int kSelfPasses = 2;
/// Moves, each within bounds found where it starts, toward strain limiting's result.
inline constexpr int kSelfLimiterMoves = 3;
/// A detection runs before a step in which a mass moving at its speed times this would
/// pass its bound.
inline constexpr double kSelfLookAhead = 2.0;
/// A step in which a turning pin would move past a pair's gap runs in up to this many parts,
/// each with its own detection.
inline constexpr int kSelfMostParts = 8;

/// A pair of elements near each other: a mass and a triangle, or two edges. Their gap vector
/// is sum_i coef[i] x[mass[i]] (the coefficients place the closest points); the stage keeps
/// it at least `target` long.
struct SelfPair {
  std::uint32_t mass[4];
  double target;  ///< m: the contact distance, or the pair's distance at rest when smaller (-1: not yet measured)
  double gap;     ///< m: the distance at the last detection that measured it
  double built;   ///< m: the distance when the candidate lists were built
};

/// A pair the response watches until the next detection, with the unit direction of its gap
/// vector then (zero when the gap was 0): the side each element was on.
struct SelfContact {
  SelfPair pair;
  Eigen::Vector3d side;
};

struct SelfScratch {
  std::vector<std::uint32_t> triangles, edges;  ///< (3 t), (2 e) mass indices; edges once each
  std::vector<std::uint32_t> faced_masses;      ///< the masses in a face
  SelfBvh mass_tree, triangle_tree, edge_tree;
  std::uint64_t builds = 0;       ///< candidate lists built (the trees are rebuilt every few)
  std::uint64_t detections = 0;   ///< detections run
  std::uint64_t pin_overruns = 0; ///< pairs found nearer than their moving pin's move over one step (outside the guarantee)
  double first_pin_overrun = -1.0;  ///< s, the time of the first (-1: none)
  std::uint64_t split_steps = 0;  ///< steps run in parts so that no turning pin moved past a gap
  double pin_room = std::numeric_limits<double>::infinity();  ///< the last detection's least gap of a pair with a moving pin over that pin's move in one step (inf: none)
  std::uint64_t overrun_pairs = 0;  ///< the last detection's pairs with a gap less than their moving pin's move in one step
  std::vector<SelfPair> cand_vt, cand_ee;  ///< every pair within far + skin at xl, then those found late
  Eigen::Matrix3Xd xl;            ///< (3 x n) the positions the candidates were found at
  std::size_t built_vt = 0, built_ee = 0;  ///< how many of each list the build found; those after were found late
  std::unordered_set<std::uint64_t> late;  ///< the pairs found late (kind, primitives)
  std::uint64_t build_work = 0;   ///< the node pairs and pairs the last build tested
  std::uint64_t check_work = 0;   ///< the node pairs and pairs the checks have tested since (the front's entries weighted: self_check.cpp)
  Eigen::Matrix3Xd xc;            ///< (3 x n) the positions at the last check that the lists hold
  double slack = 0.0;             ///< m, how much more two masses may have moved apart since xc with the lists holding
  Eigen::Matrix3Xd dl;            ///< (3 x n) each mass's move since xl, at the last detection
  std::vector<double> reach, node_reach;  ///< m, (n) each mass's longest edge at xl; (mass tree nodes) their masses' longest
  std::vector<std::array<double, 6>> node_moved, triangle_moved, edge_moved;  ///< (each tree's nodes) the box of their masses' moves since xl
  /// Where the check's descent stopped (self_check.cpp): a node pair, and how far apart its two
  /// nodes' masses may have moved since xl with its pairs still clear (-inf: yet to descend).
  /// The next check tests these and descends again only under those past their limit.
  struct FrontEntry {
    SelfBvh::NodePair np;
    double limit;
  };
  std::vector<FrontEntry> front_vt, front_ee;  ///< the mass-triangle descent's, the edges'; empty after a build
  std::vector<SelfBvh::NodePair> node_pairs;      ///< a descent's stack
  std::vector<std::uint8_t> node_pair_depth;      ///< the depth of each node pair on it, while the check splits
  /// A part of the check (self_check.cpp): a run of the front, and what testing it found.
  struct CheckTask {
    std::size_t begin = 0, end = 0;  ///< its entries of the front
    std::uint64_t work = 0;          ///< the entries, node pairs and pairs it tested
    double slack = 0.0;              ///< m, the least slack it found
    std::vector<FrontEntry> front;   ///< the entries that replace its run
    std::vector<std::pair<std::uint64_t, SelfPair>> late;  ///< the pairs it found late (key, pair), in order
  };
  std::vector<CheckTask> check_tasks;
  std::vector<std::vector<SelfBvh::NodePair>> check_stacks;  ///< per thread
  std::vector<std::uint32_t> cluster_node, cluster_of;  ///< (clusters) a node of the mass tree; (n) each mass's cluster
  std::vector<std::uint32_t> cluster_at;          ///< (mass tree nodes) the cluster a node is (kNoCluster: none)
  std::vector<std::uint32_t> near_first, near;    ///< (clusters + 1), each cluster's neighbours at xl
  std::vector<double> cluster_moved;  ///< (clusters) m, the most its masses and its neighbours' moved apart
  std::vector<double> moved;      ///< (n) m, how much the gap of any of the mass's candidates may have changed since xl
  std::vector<std::uint32_t> active; ///< the candidates this detection measures
  std::vector<Eigen::Vector3d> active_gap;  ///< their gap vectors, as it measured them
  std::vector<std::vector<std::uint32_t>> chosen;  ///< per part of the lists, while choosing `active`
  std::vector<std::uint32_t> order_at;  ///< (n + 1) where each mass's pairs start, while ordering `active`
  struct Keyed {
    std::array<std::uint32_t, 4> mass;  ///< a candidate's masses
    std::uint32_t j;                    ///< the candidate
  };
  std::vector<Keyed> keyed, keyed_ordered;  ///< `active` with their masses, in turn in order, while ordering it
  Eigen::Matrix3Xd xd;            ///< (3 x n) the positions at the last detection
  bool common = false;            ///< no mass in a face is pinned: the bounds may follow the cloths' common move
  bool follow = false;            ///< they do until the next detection: `common`, and no mass touched a collider
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();  ///< m, the common move since the detection (0 unless `follow`)
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();  ///< m/s, the common velocity (0 unless `follow`)
  Eigen::Matrix3Xd xs, xpre;      ///< (3 x n) at the step's start (the pairs' masses); before the stage's moves (those it moved)
  std::uint64_t ends = 0;         ///< the response's runs (self_contact_end)
  std::vector<std::uint64_t> kept;  ///< (n) the run that last kept the mass's xpre
  std::vector<std::uint32_t> moved_masses;  ///< the masses this run moved, each once (all_moved: any)
  bool all_moved = false;         ///< the springs moved every mass in this run
  using Held = std::pair<std::uint32_t, Eigen::Vector3d>;  ///< a mass held, and where it was
  std::vector<Held> held_now, held_last;   ///< the masses the last hold and the one before held
  std::vector<std::vector<Held>> held_parts;  ///< per thread, while holding
  std::vector<std::uint8_t> near_parts;       ///< per thread, while holding: a mass left alone nears its bound
  Eigen::Matrix3Xd xlim;          ///< (3 x n) strain limiting's result, while it is reached
  std::vector<std::uint8_t> held;     ///< (n) 1 if the stage held the mass at its bound this step
  std::vector<double> bound;      ///< (n) m, how far each mass may be from xd + shift (inf: pinned or in no face)
  std::vector<double> away;       ///< (n) m, how far each mass is from xd + shift, while pushing
  std::vector<double> weight;     ///< (n) 1/kg, the inverse masses with the held masses at 0
  std::vector<double> pin_move;   ///< (n) m, how far a pinned mass moves in the next step (0: free)
  bool pins_move = false;         ///< some pin turns: detect before every step
  std::vector<std::uint8_t> in_face;  ///< (n) 1 if the mass is a corner of a face
  std::vector<SelfContact> vt, ee;  ///< the pairs of the last detection
  std::vector<std::uint32_t> pair_masses;  ///< the masses in them, each once
  std::vector<std::uint64_t> listed;  ///< (n) the stamp of the last list of masses each was put in
  std::uint64_t stamp = 0;
  struct Found {
    std::vector<SelfPair> pairs;
    std::vector<std::array<std::uint32_t, 4>> meeting;  ///< pairs whose boxes meet, to measure
    std::uint64_t tested = 0;  ///< node pairs and pairs
  };
  std::vector<Found> found;       ///< per task, while building the candidate lists
  double distance = 0.0;          ///< m, the contact distance between layers
  double radius = 0.0;            ///< m, how far a detection looks
  double far = 0.0;               ///< m, beyond this a pair neither bounds a mass nor comes into contact
  double skin = 0.0;              ///< m, how much farther the candidate lists look
  bool detect = true;             ///< detect before the next step
};

/// The gap vector of a pair at positions x: from the closest point of the second element
/// (a triangle, or an edge) to the first's (a mass, or an edge); it is sum_i coef[i] x[m[i]].
inline Eigen::Vector3d pair_gap(const Eigen::Matrix3Xd& x, const std::uint32_t m[4], bool vertex_triangle,
                                double coef[4]) {
  const auto at = [&](int k) -> Eigen::Vector3d { return x.col(static_cast<Eigen::Index>(m[k])); };
  if (vertex_triangle) {
    double w[3];
    closest_on_triangle(at(0), at(1), at(2), at(3), w);
    coef[0] = 1.0, coef[1] = -w[0], coef[2] = -w[1], coef[3] = -w[2];
  } else {
    double s = 0.0, t = 0.0;
    closest_on_segments(at(0), at(1), at(2), at(3), s, t);
    coef[0] = 1.0 - s, coef[1] = s, coef[2] = t - 1.0, coef[3] = -t;
  }
  return coef[0] * at(0) + coef[1] * at(1) + coef[2] * at(2) + coef[3] * at(3);
}

/// Which of four edge pairs (masses 0-1 | 2-3 each) are surely at least r apart at x (3 n): bit
/// k for pair k. Their segments' distance in lanes, with room for rounding; a pair of nearly
/// parallel or nearly zero-length edges is never sure. Four pair_gap() calls cost more.
/// masses_apart_avx2: the same for four pairs of a mass (0) and a triangle (1-3), by a lower
/// bound on their distance; a pair with a sliver triangle is never sure.
#ifdef CLOTHSIM_AVX2
std::uint32_t edges_apart_avx2(const double* x, const std::array<std::uint32_t, 4>* pairs, double r);
std::uint32_t masses_apart_avx2(const double* x, const std::array<std::uint32_t, 4>* pairs, double r);
#endif

/// Candidate j of both lists (vt first).
inline SelfPair& candidate(SelfScratch& sc, std::uint32_t j) {
  return j < sc.cand_vt.size() ? sc.cand_vt[j] : sc.cand_ee[j - sc.cand_vt.size()];
}
inline const SelfPair& candidate(const SelfScratch& sc, std::uint32_t j) {
  return j < sc.cand_vt.size() ? sc.cand_vt[j] : sc.cand_ee[j - sc.cand_vt.size()];
}

/// A squared length below this part of a squared bound is surely within the bound, rounding
/// and all: the tests that compare lengths with bounds skip the square root then.
inline constexpr double kSurelyWithin = 0.98;

/// How far mass i at x is from where its bound holds it: xd moved by the common move.
inline double away_from(const SelfScratch& sc, const Eigen::Matrix3Xd& x, Eigen::Index i) {
  return (x.col(i) - sc.xd.col(i) - sc.shift).norm();
}

/// Whether mass i, at x and moving at v for kSelfLookAhead steps of h, would pass its bound
/// (both taken relative to the common move).
inline bool nears_bound(const SelfScratch& sc, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Index i,
                        double h) {
  const double b = sc.bound[static_cast<std::size_t>(i)];
  const Eigen::Vector3d out = x.col(i) - sc.xd.col(i) - sc.shift, ahead = kSelfLookAhead * h * (v.col(i) - sc.drift);
  // (a + s <= sqrt(2 (a^2 + s^2)): most masses are answered without a square root)
  if (2.0 * (out.squaredNorm() + ahead.squaredNorm()) < kSurelyWithin * b * b) return false;
  return out.norm() + kSelfLookAhead * h * (v.col(i) - sc.drift).norm() > b;
}

/// The cloths' common move since the detection and their common velocity (the means over the
/// masses in faces), when `follow`. Two masses' relative move does not depend on it, so the
/// bounds may follow it: a cloth that falls as one needs no detection for its fall. Not while
/// a collider touches the cloth: a mass it stops would be dragged along by its bound.
void find_common_move(const State& state, SelfScratch& sc);

/// The stage's memory for a model with self-collision on and faces (else nullptr).
std::shared_ptr<SelfScratch> make_self_scratch(const Model& model);

/// Brings the candidate lists up to date at x (self_lists.cpp) and chooses the candidates a
/// detection measures (`active`): those that may have come within `far`, all those of a moving pin.
void find_candidates(const Model& m, const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws);

/// Detects at the state's positions (self_detect.cpp): every free mass's bound, and the pairs
/// that can reach their target before the next detection; h is the coming step.
void detect_self(const Model& m, const State& state, double h, SelfScratch& sc, const Workspace& ws);

/// Before the integrator and the pins' move: detects when the last step asked for it, keeps
/// the start positions. Returns in how many parts a step of h must run so that no turning pin
/// moves past a pair's gap in one (1 unless `may_split`; then it has detected for a part).
int self_contact_begin(const Model& model, const State& state, Workspace& ws, double h, bool may_split);
/// Strain limiting (limit_strain) with self-contact: its result is reached in up to
/// kSelfLimiterMoves moves, each within bounds found where it starts.
void limit_strain_within_bounds(const Model& model, State& state, Workspace& ws, double h);
/// After the integrator: pushes close pairs apart to the contact distance with Coulomb
/// friction, then holds every mass within its bound; the velocities take the pushes over h.
void self_contact_end(const Model& model, State& state, Workspace& ws, double h);

}  // namespace clothsim::detail
