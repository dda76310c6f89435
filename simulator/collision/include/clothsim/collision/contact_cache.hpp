// ContactCache: per (point, object) certificates that let accumulate_penalty() skip searches.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace clothsim {

/// Per (point, object) memory between calls that lets accumulate_penalty() skip the search
/// while it provably gives the same answer (a certificate). Size it once with
/// resize(points, objects, candidates) (allocates); then calls never allocate.
///
/// candidates = K >= 2 (the default, 16): a search collects the K nearest triangles within
/// reach (a Verlet list) and L, a lower bound of the distance of every other triangle. While
/// the point has moved d from where the list was made, only the candidates are evaluated
/// (nearest first, stopping when the rest cannot win); if the best is closer than L - d it is
/// the global answer, bit for bit. candidates = 1: a single-triangle certificate (the closest
/// triangle and a 1-nearest search), the simplest form, as a reference. With K >= 2 a
/// point whose list did not survive 8 calls gets 1-nearest searches (one candidate) instead,
/// until such a certificate survives 8 calls or 8 of them were made (16, 32 .. 1024 when lists
/// keep dying young): fast points then cost about what the plain search costs instead of the
/// dearer K-nearest one.
struct ContactCache {
  static constexpr std::size_t kDefaultCandidates = 16;
  static constexpr std::size_t kMaxCandidates = 32;  ///< resize() clamps to 1 .. this
  /// Per entry, a plane certificate: the common case of a resting or slowly sliding point,
  /// checked first and in one cache line (the entry's first; its second holds the list
  /// certificate, which the hardware fetches with it). While the point stays within sqrt(|r2|) of x0, the
  /// object's answer is the triangle with corner `a` and unit normal `n`, the point over its
  /// face (r2 > 0: the distance is the plane distance n.(p - a), computed as the full check
  /// does, so the same bits), or no force and nothing counted (r2 < 0: nothing in reach, or
  /// the answer beyond the band on its front side, see ColliderSet::make_far). r2 = 0: none.
  /// Made from a holding list certificate (its lower bounds, less what the point moved) and
  /// the face's edges, or from a clear face (ColliderSet::clearance(): no gap to keep), with
  /// rounding margins, for one band (`band`).
  struct alignas(64) Plane {
    double a[3] = {0.0, 0.0, 0.0};
    double n[3] = {0.0, 0.0, 0.0};
    float x0[3] = {0.0f, 0.0f, 0.0f};
    std::uint16_t r2 = 0;    ///< the upper half of the float r2 (rounded towards 0), signed
    std::uint16_t born = 0;  ///< `epoch` when it was made (how long it lived: worth making?)
    float radius_sq() const {
      const std::uint32_t bits = std::uint32_t{r2} << 16;
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
  };
  struct alignas(64) Entry {
    Plane plane;  ///< the plane certificate, in the entry's first cache line
    double x0[3] = {0.0, 0.0, 0.0};  ///< where the certificate was made
    double others_lb = 0.0;  ///< every triangle that is not a candidate was >= this far from x0
    std::int32_t count = -1;      ///< candidates stored (0: none in reach), -1: no certificate
    std::int32_t tri_index = -1;  ///< the first candidate's input triangle index
    std::uint16_t age = 0;   ///< certified calls since the last search (counted up to 8)
    std::uint16_t lean = 0;  ///< > 0: the last searches were 1-nearest (lists died young)
    std::uint8_t backoff = 0;  ///< lists died young this many times in a row (max 7)
    /// Candidates a call at x0 evaluates (near-ties): a call that evaluates no more than this
    /// leaves the certificate where it is (moving it would learn nothing new).
    std::uint8_t settled = 1;
    std::uint8_t plane_backoff = 0;  ///< plane certificates died young this many times in a row
    std::uint8_t plane_wait = 0;     ///< calls to let pass before making the next one
  };
  std::vector<Entry> entries;        ///< point-major: entries[i * objects + o]
  std::vector<std::uint32_t> slots;  ///< entries.size() * candidates(): kept-triangle slots
  std::vector<float> lower;          ///< their distance from x0, rounded down (ascending)
  /// entries.size() * 12: a copy of each entry's first candidate (A, B - A, C - A, unit normal:
  /// the collider's own doubles), used for objects of more than 4096 triangles, so that a point
  /// at rest reads its entry and nothing of a collider that does not stay in cache.
  std::vector<double> firsts;
  /// Counts calls (accumulate_penalty() advances it; with point ranges, call tick() once per
  /// step): a plane certificate that lived fewer than 4 calls makes its entry wait 1, 3, 7 ..
  /// 63 calls before the next one (points sliding faster than such certificates last pay
  /// for making them otherwise). Only the speed depends on it, never a result.
  std::uint16_t epoch = 0;
  void tick() { ++epoch; }
  /// The penalty band eps the plane records hold for (they bake in the reach 2 eps, and "no
  /// force" records eps itself); < 0: none made yet. accumulate_penalty() calls use_band(eps)
  /// (with point ranges the caller does, once per step, as for tick()); a call with another
  /// eps neither reads nor makes records until then. Only the speed depends on it.
  double band = -1.0;
  double band_reach_sq = -1.0;  ///< (2 band)^2, the reach the records were made for
  /// Makes the plane records belong to eps: when it differs from `band`, all are dropped.
  void use_band(double eps) {
    if (eps == band) return;
    for (Entry& e : entries) e.plane.r2 = 0;
    band = eps, band_reach_sq = (2.0 * eps) * (2.0 * eps);
  }
  std::size_t candidates() const { return k_; }
  void resize(std::size_t points, std::size_t objects,
              std::size_t candidates = kDefaultCandidates) {
    k_ = candidates < 1 ? 1 : (candidates > kMaxCandidates ? kMaxCandidates : candidates);
    entries.assign(points * objects, Entry{});
    slots.assign(entries.size() * k_, 0u);
    lower.assign(entries.size() * k_, 0.0f);
    firsts.assign(entries.size() * 12, 0.0);
  }
  /// Bytes per (point, object) pair.
  std::size_t bytes_per_entry() const {
    return sizeof(Entry) + 12 * sizeof(double) +
           k_ * (sizeof(std::uint32_t) + sizeof(float));
  }

 private:
  std::size_t k_ = 1;
};

}  // namespace clothsim
