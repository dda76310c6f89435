// The gathered spring forces (spring_passes.hpp): the plain passes, and both passes over the
// whole model on one thread or several.
#include "spring_passes.hpp"
#include "spring_split.hpp"
#include "stages.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace clothsim {

void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) {
  const std::size_t s_count = model.spring_count();
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const float* rest = model.rest_length0.data();
  const std::uint8_t* kind = model.spring_kind.data();
  const double* k = model.spring_modulus;  // k[kind != 0] * scale[s] = model.spring_stiffness(s)
  const float* scale = model.spring_scale.data();
  const double* px = x.data();
  double* pf = f.data();
  for (std::size_t s = 0; s < s_count; ++s) {
    const std::size_t a = 3 * std::size_t{sa[s]}, b = 3 * std::size_t{sb[s]};
    const double dx = px[a] - px[b], dy = px[a + 1] - px[b + 1], dz = px[a + 2] - px[b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (len == 0.0) continue;  // coincident ends: no direction, no force
    // eq. 4: f_a = dx/|dx| k (l - |dx|), f_b = -f_a
    const double c = k[kind[s] != 0] * static_cast<double>(scale[s]) * (rest[s] - len) / len;
    pf[a] += c * dx;
    pf[a + 1] += c * dy;
    pf[a + 2] += c * dz;
    pf[b] -= c * dx;
    pf[b + 1] -= c * dy;
    pf[b + 2] -= c * dz;
  }
}

namespace detail {

// Pass 1, springs [s0, s1): fs[4s..4s+2] = c dx, c = k (l - |dx|) / |dx|, the scatter's
// arithmetic. |dx| = 0 gives 0 (the scatter skips such a spring; adding +-0 changes nothing
// but an exactly -0.0 partial force, which m g - gamma v does not produce).
void spring_pass_scalar(const Model& model, const double* px, double* fs, std::size_t j0, std::size_t j1,
                        const std::uint32_t* list) {
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const float* rest = model.rest_length0.data();
  const std::uint8_t* kind = model.spring_kind.data();
  const double* k = model.spring_modulus;  // k[kind != 0] * scale[s] = model.spring_stiffness(s)
  const float* scale = model.spring_scale.data();
  for (std::size_t j = j0; j < j1; ++j) {
    const std::size_t s = list ? list[j] : j;  // springs j0..j1, or those a list names
    const std::size_t a = 3 * std::size_t{sa[s]}, b = 3 * std::size_t{sb[s]};
    const double dx = px[a] - px[b], dy = px[a + 1] - px[b + 1], dz = px[a + 2] - px[b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double c = len == 0.0 ? 0.0 : k[kind[s] != 0] * static_cast<double>(scale[s]) * (rest[s] - len) / len;
    fs[4 * s] = c * dx;
    fs[4 * s + 1] = c * dy;
    fs[4 * s + 2] = c * dz;
  }
}

// Pass 2, masses [i0, i1): f_i = base_i + sum over i's springs, in increasing index, of +-fs.
// f_b + (-(c dx)) == the scatter's f_b - c dx exactly. With v, base_i = g m_i - gamma v_i (the
// Eigen form's two roundings), else the f_i already there.
void mass_pass_scalar(const Model& model, const SpringAdjacency& adj, const double* fs, const double* pv,
                      double* pf, std::size_t i0, std::size_t i1) {
  const double* m = model.mass.data();
  const Eigen::Vector3d& g = model.gravity;
  const double damping = model.damping, drag = model.drag;  // gamma_i = damping + drag m_i
  for (std::size_t i = i0; i < i1; ++i) {
    double f[3];
    const double gamma = damping + drag * m[i];
    for (int r = 0; r < 3; ++r) f[r] = pv ? g[r] * m[i] - gamma * pv[3 * i + r] : pf[3 * i + r];
    for (std::uint32_t e = adj.start[i], end = adj.start[i + 1]; e < end; ++e) {
      const std::uint32_t en = adj.entry[e];
      const double* q = fs + 4 * std::size_t{en & ~SpringAdjacency::kB};
      if (en & SpringAdjacency::kB) {
        for (int r = 0; r < 3; ++r) f[r] -= q[r];
      } else {
        for (int r = 0; r < 3; ++r) f[r] += q[r];
      }
    }
    for (int r = 0; r < 3; ++r) pf[3 * i + r] = f[r];
  }
}

}  // namespace detail

namespace {

using namespace detail;

bool has_adjacency(const Model& model, const Workspace& ws) {
  return ws.adjacency && ws.adjacency->start.size() == model.mass_count() + 1 &&
         ws.spring_f.size() == 4 * model.spring_count() + 4;
}

double* aligned32(std::vector<double>& v) {
  auto p = reinterpret_cast<std::uintptr_t>(v.data());
  return v.data() + ((32 - p % 32) % 32) / sizeof(double);
}

// Springs list[j0..j1) of an increasing list (SpringAdjacency's blocks, SpringSplit's chunks):
// when its ends are j1 - 1 - j0 apart they are consecutive, and become the range j0..j1 with
// no list (the passes' faster form; the same springs, the same bits).
void as_range(std::size_t& j0, std::size_t& j1, const std::uint32_t*& list) {
  if (!list || j1 <= j0 || list[j1 - 1] - list[j0] != j1 - 1 - j0) return;
  j1 = list[j0] + (j1 - j0), j0 = list[j0];
  list = nullptr;
}

// Both passes over the whole model, split into static per-thread ranges (no reduction
// between threads: each mass and spring is written by one thread only).
void gathered_springs(const Model& model, const Eigen::Matrix3Xd& x, const double* pv, Eigen::Matrix3Xd& f,
                      Workspace& ws) {
  const SpringAdjacency& adj = *ws.adjacency;
  const double* px = x.data();
  double* fs = aligned32(ws.spring_f);
  double* pf = f.data();
  const auto n = static_cast<std::int64_t>(model.mass_count());
  const auto sc = static_cast<std::int64_t>(model.spring_count());
  const int nt = team(ws, model.mass_count());
#ifdef CLOTHSIM_AVX2
  const bool avx2 = use_avx2() && 3 * model.mass_count() < 0x80000000u;
#endif
  if (nt <= 1 && !adj.block_start.empty()) {
    // One thread: block by block, each block's new springs then its masses, so that the spring
    // blocks a mass reads were written moments ago (still in L2). Same values, same order.
    const std::size_t blocks = adj.block_start.size() - 1, nm = model.mass_count();
    for (std::size_t b = 0; b < blocks; ++b) {
      std::size_t j0 = adj.block_start[b], j1 = adj.block_start[b + 1];
      const std::uint32_t* list = adj.block_springs.data();
      as_range(j0, j1, list);
      const std::size_t i0 = b * SpringAdjacency::kBlock, i1 = std::min(nm, i0 + SpringAdjacency::kBlock);
#ifdef CLOTHSIM_AVX2
      if (avx2) {
        spring_pass_avx2(model, px, fs, j0, j1, list);
        mass_pass_avx2(model, adj, fs, pv, pf, i0, i1);
        continue;
      }
#endif
      spring_pass_scalar(model, px, fs, j0, j1, list);
      mass_pass_scalar(model, adj, fs, pv, pf, i0, i1);
    }
    return;
  }
  const auto pass = [&](std::size_t j0, std::size_t j1, const std::uint32_t* list) {
    as_range(j0, j1, list);  // most chunks' lists (only springs to another thread's masses leave gaps)
#ifdef CLOTHSIM_AVX2
    if (avx2) return spring_pass_avx2(model, px, fs, j0, j1, list);
#endif
    spring_pass_scalar(model, px, fs, j0, j1, list);
  };
  const auto gather = [&](std::size_t i0, std::size_t i1) {
#ifdef CLOTHSIM_AVX2
    if (avx2) return mass_pass_avx2(model, adj, fs, pv, pf, i0, i1);
#endif
    mass_pass_scalar(model, adj, fs, pv, pf, i0, i1);
  };
  SpringSplit* split = ws.spring_split.get();
  if (split && split->threads != nt) split->make(model, nt);  // allocates once per thread count
  auto chunk = [](std::int64_t count, int t, int parts) {  // [lo, hi) of part t, lo a multiple of 4
    const std::int64_t per = (count / parts + 3) / 4 * 4;
    return std::pair<std::size_t, std::size_t>(static_cast<std::size_t>(std::min(count, t * per)),
                                               static_cast<std::size_t>(t + 1 == parts ? count : std::min(count, (t + 1) * per)));
  };
  parallel_region(nt, [&](int t, int parts) {
    if (split && parts == split->threads) {
      // Block by block as on one thread (SpringSplit): the springs other threads need first,
      // then, chunk by chunk, the chunk's other springs and its masses. (All springs, then all
      // masses, as below, makes two threads spend 1.8x the cycles of one on the springs: the
      // spring blocks leave the caches between the two passes.)
      const auto tt = static_cast<std::size_t>(t);
      pass(split->out_start[tt], split->out_start[tt + 1], split->out.data());
#pragma omp barrier
      for (std::uint32_t c = split->chunk_start[tt]; c < split->chunk_start[tt + 1]; ++c) {
        pass(split->local_start[c], split->local_start[c + 1], split->local.data());
        gather(split->chunk_mass[c], split->chunk_mass[c + 1]);
      }
    } else {  // a Workspace without a split, or a runtime that gave fewer threads than asked
      const auto [s0, s1] = chunk(sc, t, parts);
      pass(s0, s1, nullptr);
#pragma omp barrier
      const auto [i0, i1] = chunk(n, t, parts);
      gather(i0, i1);
    }
  });
}

}  // namespace

void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f,
                       Workspace& ws) {
  if (!has_adjacency(model, ws)) return add_spring_forces(model, x, f);
  gathered_springs(model, x, nullptr, f, ws);
}

void detail::internal_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                             Eigen::Matrix3Xd& f, Workspace& ws) {
  if (has_adjacency(model, ws)) {
    // gravity, the damping of eq. 6 (a = (f - gamma v)/m) and the springs in one pass per mass
    gathered_springs(model, x, v.data(), f, ws);
  } else {
    for (Eigen::Index i = 0; i < f.cols(); ++i)
      f.col(i) = model.gravity * model.mass[i] - model.damping_of(static_cast<std::size_t>(i)) * v.col(i);
    add_spring_forces(model, x, f);
  }
}

}  // namespace clothsim
