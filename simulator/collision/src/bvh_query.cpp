// ColliderSet's closest-triangle searches: the nearest triangle of an object (query_object(),
// query(), closest()) and its K nearest (query_nearest()), over the 4-wide BVH or every
// triangle (brute force, the reference).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "bvh.hpp"
#include "collider.hpp"
#include "kernel.hpp"

namespace clothsim {

using detail::better;
using detail::kBlock;
using detail::kMaxCandidates;
using detail::load4;
using detail::pos;
using detail::StackEntry;
using detail::v4f;
using detail::vabs;

#ifdef CLOTHSIM_COLLISION_COUNTERS
std::uint64_t g_tri_tests = 0, g_box_tests = 0;  // profiling builds only
#endif

namespace {

// Squared distance from p to a node's box (0 inside), in float: cheap, branch-free, and made
// a safe lower bound by the caller's margin (see prune_bound()).
inline float box_dist_sq(const ColliderSet::Node& n, const float p[3]) {
  const float q0 = p[0] - n.c[0], q1 = p[1] - n.c[1], q2 = p[2] - n.c[2];
  const float e0 = std::max(std::abs(n.a[0] * q0 + n.a[1] * q1 + n.a[2] * q2) - n.h[0], 0.0f);
  const float e1 = std::max(std::abs(n.a[3] * q0 + n.a[4] * q1 + n.a[5] * q2) - n.h[1], 0.0f);
  const float e2 = std::max(std::abs(n.a[6] * q0 + n.a[7] * q1 + n.a[8] * q2) - n.h[2], 0.0f);
#ifdef CLOTHSIM_COLLISION_COUNTERS
  ++g_box_tests;
#endif
  return e0 * e0 + e1 * e1 + e2 * e2;
}

// A box may hold a triangle at squared distance <= best only if its float distance is <= the
// returned bound: float rounding in box_dist_sq() is below `margin` (4e-6 of the magnitudes
// involved; float epsilon is 6e-8), and the axes' norm is <= 1 + 1e-6 (checked at build).
inline float prune_bound(double best, double margin) {
  const double r = std::sqrt(best) + margin;
  return static_cast<float>(r * r * (1.0 + 1e-5)) * (1.0f + 1e-6f);
}

// One visit of a 4-wide node: its 4 oriented boxes against the point in one 128-bit vector
// (SSE on x86-64, NEON on ARM); the children within `bound` are pushed farthest first, so the
// nearest is popped next; the smallest distance of a real box pruned goes into pruned_f.
inline void visit4(const ColliderSet::Node4& n, const float pf[3], float bound, StackEntry* stack,
                   int& top, float& pruned_f) {
  const v4f q0 = pf[0] - load4(n.c[0]), q1 = pf[1] - load4(n.c[1]), q2 = pf[2] - load4(n.c[2]);
  const v4f t0 = load4(n.a[0]) * q0 + load4(n.a[1]) * q1 + load4(n.a[2]) * q2;
  const v4f t1 = load4(n.a[3]) * q0 + load4(n.a[4]) * q1 + load4(n.a[5]) * q2;
  const v4f t2 = load4(n.a[6]) * q0 + load4(n.a[7]) * q1 + load4(n.a[8]) * q2;
  const v4f e0 = pos(vabs(t0) - load4(n.h[0])), e1 = pos(vabs(t1) - load4(n.h[1])),
            e2 = pos(vabs(t2) - load4(n.h[2]));
  const v4f d2 = e0 * e0 + e1 * e1 + e2 * e2;
#ifdef CLOTHSIM_COLLISION_COUNTERS
  g_box_tests += 4;
#endif
  StackEntry pass[4];
  int np = 0;
  for (int k = 0; k < 4; ++k)
    if (d2[k] <= bound) {
      int j = np++;
      for (; j > 0 && pass[j - 1].d2 < d2[k]; --j) pass[j] = pass[j - 1];
      pass[j] = StackEntry{n.child[k], d2[k]};
    } else if (n.h[0][k] >= 0.0f) {  // a real box (empty lanes have h < 0)
      pruned_f = std::min(pruned_f, static_cast<float>(d2[k]));
    }
  for (int k = 0; k < np; ++k) stack[top++] = pass[k];
}

// Depth-first over one object's 4-wide tree, nearer boxes first. Boxes strictly farther than
// the current bound are pruned (an equal distance may hide a lower-index tie); `test(slot)` is
// called for every triangle slot of each leaf reached, and `bound_sq()` is the distance^2 a
// triangle must beat, which shrinks as test() finds closer ones. Returns the smallest float
// box distance^2 pruned (+inf if none): with the tested triangles, a bound of the rest.
template <class BoundSq, class Test>
float traverse(const std::vector<ColliderSet::Node4>& nodes4, const ColliderSet::Node& root_box,
               std::uint32_t root4, const float pf[3], double margin, BoundSq bound_sq,
               Test& test) {
  double bound_for = bound_sq();
  float bound = prune_bound(bound_for, margin);
  const float root_d2 = box_dist_sq(root_box, pf);
  if (root_d2 > bound) return root_d2;
  float pruned_f = std::numeric_limits<float>::infinity();
  StackEntry stack[128];  // each visit pops 1, pushes <= 4; depth <= 26 for 2^28 triangles
  int top = 0;
  stack[top++] = StackEntry{root4, 0.0f};
  while (top > 0) {
    const StackEntry e = stack[--top];
    if (e.d2 > bound) {
      pruned_f = std::min(pruned_f, e.d2);
      continue;
    }
    if ((e.ref & 7u) != 0) {  // leaf
      for (std::uint32_t slot = e.ref >> 3, end = slot + (e.ref & 7u); slot < end; ++slot)
        test(slot);
      if (bound_sq() != bound_for) bound_for = bound_sq(), bound = prune_bound(bound_for, margin);
      continue;
    }
    visit4(nodes4[e.ref >> 3], pf, bound, stack, top, pruned_f);
  }
  return pruned_f;
}

}  // namespace

ColliderHit ColliderSet::query_object(std::size_t o, const double p[3], double radius_sq,
                                      QueryMethod method, std::int32_t hint,
                                      double* others_lb) const {
  const Object& ob = objects_[o];
  ColliderHit hit;
  if (others_lb) *others_lb = std::numeric_limits<double>::infinity();
  if (ob.tri_end == ob.tri_begin) return hit;
  // For others_lb: the smallest distance^2 of a tested triangle that is not the answer, and the
  // smallest float box distance^2 of a pruned subtree.
  double other_d2 = std::numeric_limits<double>::infinity();
  float pruned_f = std::numeric_limits<float>::infinity();
  double margin = 0.0;
  double best = radius_sq;
  std::int32_t best_tri = std::numeric_limits<std::int32_t>::max();
  std::uint32_t best_slot = 0;
  double best_s = 0.0;
  bool found = false;

  const auto test = [&](std::uint32_t slot) {
#ifdef CLOTHSIM_COLLISION_COUNTERS
    ++g_tri_tests;
#endif
    double s;
    const double d2 = detail::closest_sq<kBlock>(p, tri_ptr(slot), s);
    const std::int32_t idx = orig_[slot];
    if (found && idx == best_tri) return;  // the hint, met again in the tree
    if (d2 <= radius_sq && better(d2, idx, best, best_tri)) {
      if (found) other_d2 = std::min(other_d2, best);
      best = d2, best_tri = idx, best_slot = slot, best_s = s, found = true;
    } else {
      other_d2 = std::min(other_d2, d2);
    }
  };

  if (method == QueryMethod::BruteForce) {
    for (std::uint32_t slot = ob.tri_begin; slot < ob.tri_end; ++slot)
      if (orig_[slot] >= 0) test(slot);
  } else {
    if (hint >= 0 && static_cast<std::size_t>(hint) < ob.input_to_kept.size()) {
      const std::int32_t slot = ob.input_to_kept[static_cast<std::size_t>(hint)];
      if (slot >= 0) test(static_cast<std::uint32_t>(slot));
    }
    const float pf[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                         static_cast<float>(p[2])};
    margin = 4e-6 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + ob.scale);
    pruned_f = traverse(nodes4_, ob.root_box, ob.root4, pf, margin, [&] { return best; }, test);
  }
  if (others_lb) {
    // Float box distances back to a safe lower bound of true distances (see prune_bound()).
    const double box_lb =
        std::isinf(pruned_f)
            ? std::numeric_limits<double>::infinity()
            : std::max(0.0, std::sqrt(static_cast<double>(pruned_f)) * (1.0 - 1e-5) - margin);
    *others_lb = std::min(std::sqrt(other_d2), box_lb);
  }
  if (!found) return hit;
  hit.object = static_cast<std::int32_t>(o);
  hit.triangle = best_tri;
  hit.distance_sq = best;
  hit.signed_distance = detail::signed_distance(best, best_s);
  const detail::Tri bt = tri_at(best_slot);
  hit.normal = Eigen::Vector3d(bt.nx, bt.ny, bt.nz);
  return hit;
}

std::size_t ColliderSet::query(const Eigen::Vector3d& p, double radius,
                               std::span<ColliderHit> out, QueryMethod method,
                               std::span<std::int32_t> hints) const {
  if (!built_) throw std::logic_error("ColliderSet::query() before build()");
  if (out.size() != objects_.size())
    throw std::invalid_argument("ColliderSet::query(): out needs one entry per object");
  if (!(radius >= 0.0)) throw std::invalid_argument("ColliderSet::query(): radius < 0 or NaN");
  if (!hints.empty() && hints.size() != objects_.size())
    throw std::invalid_argument("ColliderSet::query(): hints need one entry per object");
  const double pp[3] = {p.x(), p.y(), p.z()};
  const double r2 = radius * radius;
  std::size_t hits = 0;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    out[o] = query_object(o, pp, r2, method, hints.empty() ? -1 : hints[o]);
    if (out[o].valid()) ++hits;
    if (!hints.empty()) hints[o] = out[o].triangle;
  }
  return hits;
}

ColliderHit ColliderSet::closest(const Eigen::Vector3d& p, double radius,
                                 QueryMethod method) const {
  if (!built_) throw std::logic_error("ColliderSet::closest() before build()");
  if (!(radius >= 0.0)) throw std::invalid_argument("ColliderSet::closest(): radius < 0 or NaN");
  const double pp[3] = {p.x(), p.y(), p.z()};
  ColliderHit best;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    const ColliderHit h = query_object(o, pp, radius * radius, method, -1);
    if (h.valid() && (!best.valid() || h.distance_sq < best.distance_sq)) best = h;
  }
  return best;
}

std::size_t ColliderSet::query_nearest(std::size_t o, const double p[3], double radius_sq,
                                       QueryMethod method, std::size_t k,
                                       std::span<const std::uint32_t> seed, std::uint32_t* slots,
                                       double* d2s, double& others_lb) const {
  const Object& ob = objects_[o];
  others_lb = std::numeric_limits<double>::infinity();
  if (ob.tri_end == ob.tri_begin || k == 0) return 0;
  // The list: the k best (distance^2, input index) within radius found so far, ascending.
  // other_d2: the smallest distance^2 of a tested triangle not in the list; pruned_f: the
  // smallest float box distance^2 of a pruned subtree. Together they bound everything else.
  std::int32_t idxs[kMaxCandidates];
  std::size_t n = 0;
  double other_d2 = std::numeric_limits<double>::infinity();
  float pruned_f = std::numeric_limits<float>::infinity();
  double margin = 0.0;
  std::uint64_t in_list = 0;  // bit (slot mod 64) set for every slot ever put in the list

  const auto test = [&](std::uint32_t slot) {
#ifdef CLOTHSIM_COLLISION_COUNTERS
    ++g_tri_tests;
#endif
    if ((in_list >> (slot & 63u)) & 1u)  // perhaps in the list already (a seed, met again)
      for (std::size_t j = 0; j < n; ++j)
        if (slots[j] == slot) return;
    double s;
    const double d2 = detail::closest_sq<kBlock>(p, tri_ptr(slot), s);
    const std::int32_t idx = orig_[slot];
    if (d2 > radius_sq || (n == k && !better(d2, idx, d2s[k - 1], idxs[k - 1]))) {
      other_d2 = std::min(other_d2, d2);
      return;
    }
    if (n == k) other_d2 = std::min(other_d2, d2s[--n]);  // the last one drops out
    std::size_t j = n++;
    for (; j > 0 && better(d2, idx, d2s[j - 1], idxs[j - 1]); --j)
      d2s[j] = d2s[j - 1], idxs[j] = idxs[j - 1], slots[j] = slots[j - 1];
    d2s[j] = d2, idxs[j] = idx, slots[j] = slot;
    in_list |= std::uint64_t{1} << (slot & 63u);  // never cleared: a filter, not a set
  };
  // Nothing farther than this can enter the list or lower the bound of the rest.
  const auto bound_sq = [&] { return std::min(radius_sq, other_d2); };

  if (method == QueryMethod::BruteForce) {
    for (std::uint32_t slot = ob.tri_begin; slot < ob.tri_end; ++slot)
      if (orig_[slot] >= 0) test(slot);
  } else {
    for (const std::uint32_t slot : seed)
      if (slot >= ob.tri_begin && slot < ob.tri_end && orig_[slot] >= 0) test(slot);
    const float pf[3] = {static_cast<float>(p[0]), static_cast<float>(p[1]),
                         static_cast<float>(p[2])};
    margin = 4e-6 * (std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}) + ob.scale);
    pruned_f = traverse(nodes4_, ob.root_box, ob.root4, pf, margin, bound_sq, test);
  }
  const double box_lb =
      std::isinf(pruned_f)
          ? std::numeric_limits<double>::infinity()
          : std::max(0.0, std::sqrt(static_cast<double>(pruned_f)) * (1.0 - 1e-5) - margin);
  others_lb = std::min(std::sqrt(other_d2), box_lb);
  return n;
}

}  // namespace clothsim
