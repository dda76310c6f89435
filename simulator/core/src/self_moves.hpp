// Boxes of the masses' moves since the candidate lists were built, and distances between boxes:
// what the lists (self_lists.cpp) and their check (self_check.cpp) bound gap changes with.
#pragma once

#include "self_contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace clothsim::detail {

using Box = std::array<double, 6>;  // lo, hi

/// The most two masses, one moved within box p and one within box q, have moved apart.
inline double apart(const Box& p, const Box& q) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(p[k + 3] - q[k], q[k + 3] - p[k]);
    s += d * d;
  }
  return std::sqrt(s);
}

/// The distance between boxes [alo, ahi] and [blo, bhi].
inline double box_distance(const double* alo, const double* ahi, const double* blo, const double* bhi) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({0.0, alo[k] - bhi[k], blo[k] - ahi[k]});
    s += d * d;
  }
  return std::sqrt(s);
}

/// The distance between two nodes' boxes at xl.
inline double node_distance(const SelfBvh::Node& a, const SelfBvh::Node& b) {
  return box_distance(a.lo.data(), a.hi.data(), b.lo.data(), b.hi.data());
}

/// Mass i's move since xl (as of the last bound_moves).
inline auto move_of(const SelfScratch& sc, std::uint32_t i) { return sc.dl.col(i); }

/// Each node of tree t: the box of its primitives' masses' moves since xl (sc.dl), on nt threads.
void bound_moves(const SelfScratch& sc, const SelfBvh& t, std::vector<Box>& moves, int nt);
/// The masses' moves since xl at x (sc.dl) and the boxes of the masses' tree, on nt threads.
void bound_moves(SelfScratch& sc, const Eigen::Matrix3Xd& x, int nt);

/// A leaf pair of the check at once: its primitives' pairs whose masses cannot have come within
/// `far` unlisted, by the leaves' largest relative move `moved` (the most two of their masses,
/// one of each leaf, have moved apart) against the pair's room at xl (its boxes' distance less
/// `far`, at least the skin). Returns the bits 4 i + j of the pairs it does not clear (i <
/// count, j < other; with `one`, a leaf against itself, only j > i), and lowers `least_room` to
/// the least room of those it clears. A NaN box clears nothing.
struct LeafCheck {
  double moved, skin, far;
  std::uint32_t other;  ///< the second leaf's primitives
  bool one;
};
std::uint32_t leaf_clears(const SelfBvh::Lanes& a, std::uint32_t count, const SelfBvh::Lanes& b, const LeafCheck& c,
                          double& least_room);
#ifdef CLOTHSIM_AVX2
std::uint32_t leaf_clears_avx2(const SelfBvh::Lanes& a, std::uint32_t count, const SelfBvh::Lanes& b,
                               const LeafCheck& c, double& least_room);
#endif

/// Whether the lists still hold every pair within `far` at x, with the pairs found late listed
/// (self_check.cpp); the masses' moves are bounded on the way.
bool candidates_hold(const Eigen::Matrix3Xd& x, SelfScratch& sc, const Workspace& ws);

}  // namespace clothsim::detail
