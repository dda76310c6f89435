// Forces and time integration (report eqs. 1-7). Nothing here allocates after make_workspace(),
// but once per thread count (the threads' shares of springs and collision runs).
#include <clothsim/step.hpp>
#include <clothsim/integrators.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <sstream>
#include <string>

#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define CLOTHSIM_AVX2 1
#endif

#ifdef CLOTHSIM_HAVE_COLLISION
#include <clothsim/collision.hpp>
#endif

namespace clothsim {

namespace {

std::atomic<int> g_threads{1};

#ifdef _OPENMP
std::size_t thread_num() { return static_cast<std::size_t>(omp_get_thread_num()); }
std::size_t team_size() { return static_cast<std::size_t>(omp_get_num_threads()); }
double wtime() { return omp_get_wtime(); }
#else
std::size_t thread_num() { return 0; }
std::size_t team_size() { return 1; }
double wtime() { return 0.0; }
#endif

// Threads for a loop of `work` items: below ~4k items a parallel region costs more than it saves.
constexpr std::size_t kTeamWork = 4096;
int team(std::size_t work) {
  const int t = g_threads.load(std::memory_order_relaxed);
  return work >= kTeamWork ? t : 1;
}

// The collision loop's work for team(): a query costs ~10 spring terms, so half a mass's.
std::size_t collision_work(std::size_t masses, std::size_t objects) { return masses * objects / 2; }

}  // namespace

void set_threads(int n) {
#ifdef _OPENMP
  g_threads = n > 0 ? n : omp_get_num_procs();
#else
  (void)n;
  g_threads = 1;
#endif
}

int threads() { return g_threads.load(); }

bool step_splits(const Model& model) {
  const std::size_t n = model.mass_count();
  std::size_t collision = 0;
#ifdef CLOTHSIM_HAVE_COLLISION
  if (model.colliders) collision = collision_work(n, model.colliders->object_count());
#endif
  return std::max(n, collision) >= kTeamWork;  // team() of the mass loops and of the collision
}

int core_count() {
#ifdef _OPENMP
  // the cores this process may use, capped by OMP_NUM_THREADS when that is set lower
  return std::max(1, std::min(omp_get_num_procs(), omp_get_max_threads()));
#else
  return 1;
#endif
}

SpringAdjacency SpringAdjacency::build(const Model& model) {
  const std::size_t n = model.mass_count(), s_count = model.spring_count();
  if (s_count >= kB) throw std::length_error("clothsim: more than 2^31 - 1 springs");
  SpringAdjacency a;
  a.start.assign(n + 1, 0);
  for (std::size_t s = 0; s < s_count; ++s) {
    ++a.start[model.spring_a[s] + 1];
    ++a.start[model.spring_b[s] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) a.start[i + 1] += a.start[i];
  a.entry.resize(2 * s_count);
  std::vector<std::uint32_t> fill(a.start.begin(), a.start.end() - 1);
  for (std::size_t s = 0; s < s_count; ++s) {  // increasing s: the scatter's order per mass
    a.entry[fill[model.spring_a[s]]++] = static_cast<std::uint32_t>(s);
    a.entry[fill[model.spring_b[s]]++] = static_cast<std::uint32_t>(s) | kB;
  }
  // each spring goes to the block of its lower mass: the first block whose masses need it
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  a.block_start.assign(blocks + 1, 0);
  for (std::size_t s = 0; s < s_count; ++s)
    ++a.block_start[std::min(model.spring_a[s], model.spring_b[s]) / kBlock + 1];
  for (std::size_t b = 0; b < blocks; ++b) a.block_start[b + 1] += a.block_start[b];
  a.block_springs.resize(s_count);
  std::vector<std::uint32_t> bfill(a.block_start.begin(), a.block_start.end() - 1);
  for (std::size_t s = 0; s < s_count; ++s)
    a.block_springs[bfill[std::min(model.spring_a[s], model.spring_b[s]) / kBlock]++] = static_cast<std::uint32_t>(s);
  // the a ends' runs: consecutive spring indices at the head of each mass's list (fewer than
  // 2^27 springs: the AVX2 gather then reads a b end's byte offset as entry << 5 in 32 bits)
  if (s_count >= (std::size_t{1} << 27)) return a;
  a.run.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t e = a.start[i];
    for (; e < a.start[i + 1] && !(a.entry[e] & kB); ++e) {
      if (e > a.start[i] && a.entry[e] != a.entry[e - 1] + 1) break;
    }
    a.run[i] = e - a.start[i];
    for (; e < a.start[i + 1]; ++e)
      if (!(a.entry[e] & kB)) {  // an a end after the run: the entries' general path
        a.run.clear();
        return a;
      }
  }
  return a;
}

/// The gathered springs on several threads, blocked as on one. Thread t owns the masses
/// [n t / threads, n (t + 1) / threads), cut into chunks of at most kBlock masses. A spring is
/// computed by the thread of its lower mass: in the chunk of that mass (`local`), just before
/// the chunk's masses gather, or, when its other mass belongs to a later thread, before the
/// barrier (`out`), so that the later thread finds it done. Each spring is written once.
struct SpringSplit {
  int threads = 0;                         ///< made for this many threads (0: not yet)
  std::vector<std::uint32_t> chunk_start;  ///< (threads + 1) each thread's first chunk
  std::vector<std::uint32_t> chunk_mass;   ///< (chunks + 1) each chunk's first mass, then n
  std::vector<std::uint32_t> local_start, local;  ///< (chunks + 1), springs by chunk (increasing in each)
  std::vector<std::uint32_t> out_start, out;      ///< (threads + 1), springs by thread (increasing in each)

  void make(const Model& model, int nt) {
    const std::size_t n = model.mass_count(), sc = model.spring_count();
    const auto parts = static_cast<std::size_t>(nt);
    chunk_start.assign(parts + 1, 0);
    chunk_mass.clear();
    for (std::size_t t = 0; t < parts; ++t) {  // thread t: masses [n t / parts, n (t + 1) / parts)
      chunk_start[t] = static_cast<std::uint32_t>(chunk_mass.size());
      for (std::size_t i = n * t / parts; i < n * (t + 1) / parts; i += SpringAdjacency::kBlock)
        chunk_mass.push_back(static_cast<std::uint32_t>(i));
    }
    chunk_start[parts] = static_cast<std::uint32_t>(chunk_mass.size());
    const std::size_t chunks = chunk_mass.size();
    chunk_mass.push_back(static_cast<std::uint32_t>(n));
    const auto chunk_of = [&](std::uint32_t i) {
      return static_cast<std::size_t>(std::upper_bound(chunk_mass.begin(), chunk_mass.end() - 1, i) -
                                      chunk_mass.begin()) - 1;
    };
    const auto thread_of = [&](std::size_t c) {
      return static_cast<std::size_t>(std::upper_bound(chunk_start.begin(), chunk_start.end() - 1,
                                                       static_cast<std::uint32_t>(c)) - chunk_start.begin()) - 1;
    };
    // where each spring goes: chunk c (< chunks) or thread t (chunks + t)
    std::vector<std::size_t> where(sc);
    local_start.assign(chunks + 1, 0);
    out_start.assign(parts + 1, 0);
    for (std::size_t s = 0; s < sc; ++s) {
      const std::uint32_t lo = std::min(model.spring_a[s], model.spring_b[s]);
      const std::uint32_t hi = std::max(model.spring_a[s], model.spring_b[s]);
      const std::size_t c = chunk_of(lo), t = thread_of(c);
      if (thread_of(chunk_of(hi)) == t) where[s] = c, ++local_start[c + 1];
      else where[s] = chunks + t, ++out_start[t + 1];
    }
    for (std::size_t c = 0; c < chunks; ++c) local_start[c + 1] += local_start[c];
    for (std::size_t t = 0; t < parts; ++t) out_start[t + 1] += out_start[t];
    local.resize(local_start[chunks]);
    out.resize(out_start[parts]);
    std::vector<std::uint32_t> lf(local_start.begin(), local_start.end() - 1), of(out_start.begin(), out_start.end() - 1);
    for (std::size_t s = 0; s < sc; ++s) {
      if (where[s] < chunks) local[lf[where[s]]++] = static_cast<std::uint32_t>(s);
      else out[of[where[s] - chunks]++] = static_cast<std::uint32_t>(s);
    }
    threads = nt;
  }
};

#ifdef CLOTHSIM_HAVE_COLLISION
struct CollisionScratch {
  ContactCache whole;  ///< every (mass, collider) pair's certificate
  /// More threads: the statistics of each run of kRun masses (combined in run order).
  static constexpr std::size_t kRun = 128;
  std::vector<PenaltyStats> runs;
  /// (threads + 1) the first run of each thread; each call moves a boundary by one run towards
  /// the thread that took longer (contacts are not spread evenly over the cloth).
  std::vector<std::size_t> bound;
  std::vector<double> seconds;  ///< (threads) each thread's time in the last call
};
#else
struct CollisionScratch {};
#endif

State make_state(const Model& model) {
  State s;
  s.x = model.x0;
  s.v = Eigen::Matrix3Xd::Zero(3, model.x0.cols());
  return s;
}

Workspace make_workspace(const Model& model) {
  Workspace ws;
  const auto n = static_cast<Eigen::Index>(model.mass_count());
  ws.f = Eigen::Matrix3Xd::Zero(3, n);
  ws.adjacency = std::make_shared<const SpringAdjacency>(SpringAdjacency::build(model));
  ws.spring_split = std::make_shared<SpringSplit>();
  ws.spring_f.assign(4 * model.spring_count() + 4, 0.0);
  for (std::size_t i = 0; i < model.pinned.size(); ++i)
    if (model.pinned[i]) ws.pinned_index.push_back(static_cast<std::uint32_t>(i));
  ws.pinned_x = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(ws.pinned_index.size()));
#ifdef CLOTHSIM_HAVE_COLLISION
  if (model.colliders) {
    ws.collision = std::make_shared<CollisionScratch>();
    ws.collision->whole.resize(model.mass_count(), model.colliders->object_count());
  }
#endif
  return ws;
}

void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) {
  const std::size_t s_count = model.spring_count();
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const double* rest = model.rest_length0.data();
  const std::uint8_t* kind = model.spring_kind.data();
  const double k[2] = {model.options.k_struct, model.options.k_bend};  // k[kind != 0] = model.spring_stiffness(s)
  const double* px = x.data();
  double* pf = f.data();
  for (std::size_t s = 0; s < s_count; ++s) {
    const std::size_t a = 3 * std::size_t{sa[s]}, b = 3 * std::size_t{sb[s]};
    const double dx = px[a] - px[b], dy = px[a + 1] - px[b + 1], dz = px[a + 2] - px[b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (len == 0.0) continue;  // coincident ends: no direction, no force
    // eq. 4: f_a = dx/|dx| k (l - |dx|), f_b = -f_a
    const double c = k[kind[s] != 0] * (rest[s] - len) / len;
    pf[a] += c * dx;
    pf[a + 1] += c * dy;
    pf[a + 2] += c * dz;
    pf[b] -= c * dx;
    pf[b + 1] -= c * dy;
    pf[b + 2] -= c * dz;
  }
}

namespace {

bool has_adjacency(const Model& model, const Workspace& ws) {
  return ws.adjacency && ws.adjacency->start.size() == model.mass_count() + 1 &&
         ws.spring_f.size() == 4 * model.spring_count() + 4;
}

double* aligned32(std::vector<double>& v) {
  auto p = reinterpret_cast<std::uintptr_t>(v.data());
  return v.data() + ((32 - p % 32) % 32) / sizeof(double);
}

// Both passes exist twice: plain C++ and AVX2 (chosen at run time). They do the same IEEE
// operations in the same order (sqrt and / are correctly rounded in both; no FMA), so the
// results are bit-identical to each other and to the scatter loop.

// Pass 1, springs [s0, s1): fs[4s..4s+2] = c dx, c = k (l - |dx|) / |dx|, the scatter's
// arithmetic. |dx| = 0 gives 0 (the scatter skips such a spring; adding +-0 changes nothing
// but an exactly -0.0 partial force, which m g - gamma v does not produce).
void spring_pass_scalar(const Model& model, const double* px, double* fs, std::size_t j0, std::size_t j1,
                        const std::uint32_t* list = nullptr) {
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const double* rest = model.rest_length0.data();
  const std::uint8_t* kind = model.spring_kind.data();
  const double k[2] = {model.options.k_struct, model.options.k_bend};  // k[kind != 0] = model.spring_stiffness(s)
  for (std::size_t j = j0; j < j1; ++j) {
    const std::size_t s = list ? list[j] : j;  // springs j0..j1, or those a list names
    const std::size_t a = 3 * std::size_t{sa[s]}, b = 3 * std::size_t{sb[s]};
    const double dx = px[a] - px[b], dy = px[a + 1] - px[b + 1], dz = px[a + 2] - px[b + 2];
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double c = len == 0.0 ? 0.0 : k[kind[s] != 0] * (rest[s] - len) / len;
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
  const Eigen::Vector3d& g = model.options.gravity;
  const double gamma = model.options.damping;
  for (std::size_t i = i0; i < i1; ++i) {
    double f[3];
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

#ifdef CLOTHSIM_AVX2
// Listed: springs list[j0..j1), else springs j0..j1 (a range: consecutive rest lengths and
// kinds, contiguous stores, no list to read).
template <bool Listed>
__attribute__((target("avx2"))) void spring_pass_avx2_impl(const Model& model, const double* px, double* fs,
                                                           std::size_t j0, std::size_t j1,
                                                           const std::uint32_t* list) {
  const std::uint32_t* sa = model.spring_a.data();
  const std::uint32_t* sb = model.spring_b.data();
  const double* rest = model.rest_length0.data();
  const std::uint8_t* kind = model.spring_kind.data();
  // the stiffness of 4 springs: k_struct where the kind byte is 0, else k_bend (Model::spring_stiffness)
  const __m256d ks = _mm256_set1_pd(model.options.k_struct), kb = _mm256_set1_pd(model.options.k_bend);
  const __m256d zero = _mm256_setzero_pd();
  const __m256i xyz = _mm256_setr_epi64x(-1, -1, -1, 0);  // lanes x, y, z of a mass (never past x's end)
  // Eight springs per iteration as two independent groups of four, stage by stage, so that
  // one group's loads and products overlap the other's square root and division.
  constexpr int G = 2;
  std::size_t j = j0;
  for (; j + 4 * G <= j1; j += 4 * G) {
    std::size_t sl[G][4];
    for (int g = 0; g < G; ++g)
      for (int l = 0; l < 4; ++l) sl[g][l] = Listed ? list[j + 4 * g + l] : j + 4 * g + l;
    __m256d dx[G], dy[G], dz[G], len[G], kv[G], rv[G], c[G];
    for (int g = 0; g < G; ++g) {
      // per spring a lane vector xa - xb = (dx, dy, dz, 0), then transposed to dx, dy, dz of 4 springs
      __m256d d[4];
      for (int l = 0; l < 4; ++l)
        d[l] = _mm256_sub_pd(_mm256_maskload_pd(px + 3 * std::size_t{sa[sl[g][l]]}, xyz),
                             _mm256_maskload_pd(px + 3 * std::size_t{sb[sl[g][l]]}, xyz));
      const __m256d u0 = _mm256_unpacklo_pd(d[0], d[1]);  // x0 x1 z0 z1
      const __m256d u1 = _mm256_unpackhi_pd(d[0], d[1]);  // y0 y1 0 0
      const __m256d u2 = _mm256_unpacklo_pd(d[2], d[3]);  // x2 x3 z2 z3
      const __m256d u3 = _mm256_unpackhi_pd(d[2], d[3]);  // y2 y3 0 0
      dx[g] = _mm256_permute2f128_pd(u0, u2, 0x20);
      dy[g] = _mm256_permute2f128_pd(u1, u3, 0x20);
      dz[g] = _mm256_permute2f128_pd(u0, u2, 0x31);
    }
    for (int g = 0; g < G; ++g)
      len[g] = _mm256_sqrt_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx[g], dx[g]), _mm256_mul_pd(dy[g], dy[g])),
                                            _mm256_mul_pd(dz[g], dz[g])));
    for (int g = 0; g < G; ++g) {
      // A block's list is mostly runs of consecutive springs (the converter writes them edge by
      // edge): then the rest lengths and kinds load as in the list-free case.
      const bool run = Listed && sl[g][3] == sl[g][0] + 3;
      const std::size_t s0 = sl[g][0];
      __m256i kinds;  // the 4 kind bytes, widened
      if (Listed && !run) {
        kinds = _mm256_setr_epi64x(kind[sl[g][0]], kind[sl[g][1]], kind[sl[g][2]], kind[sl[g][3]]);
        rv[g] = _mm256_setr_pd(rest[sl[g][0]], rest[sl[g][1]], rest[sl[g][2]], rest[sl[g][3]]);
      } else {
        std::uint32_t four;
        std::memcpy(&four, kind + s0, sizeof four);
        kinds = _mm256_cvtepu8_epi64(_mm_cvtsi32_si128(static_cast<int>(four)));
        rv[g] = _mm256_loadu_pd(rest + s0);
      }
      kv[g] = _mm256_blendv_pd(kb, ks, _mm256_castsi256_pd(_mm256_cmpeq_epi64(kinds, _mm256_setzero_si256())));
    }
    for (int g = 0; g < G; ++g) c[g] = _mm256_div_pd(_mm256_mul_pd(kv[g], _mm256_sub_pd(rv[g], len[g])), len[g]);
    for (int g = 0; g < G; ++g) {
      const __m256d cg = _mm256_blendv_pd(c[g], zero, _mm256_cmp_pd(len[g], zero, _CMP_EQ_OQ));
      const __m256d fx = _mm256_mul_pd(cg, dx[g]), fy = _mm256_mul_pd(cg, dy[g]), fz = _mm256_mul_pd(cg, dz[g]);
      // transpose (fx, fy, fz, 0) of 4 springs into 4 blocks x, y, z, 0
      const __m256d t0 = _mm256_unpacklo_pd(fx, fy);    // x0 y0 x2 y2
      const __m256d t1 = _mm256_unpackhi_pd(fx, fy);    // x1 y1 x3 y3
      const __m256d t2 = _mm256_unpacklo_pd(fz, zero);  // z0 0 z2 0
      const __m256d t3 = _mm256_unpackhi_pd(fz, zero);  // z1 0 z3 0
      _mm256_store_pd(fs + 4 * sl[g][0], _mm256_permute2f128_pd(t0, t2, 0x20));
      _mm256_store_pd(fs + 4 * sl[g][1], _mm256_permute2f128_pd(t1, t3, 0x20));
      _mm256_store_pd(fs + 4 * sl[g][2], _mm256_permute2f128_pd(t0, t2, 0x31));
      _mm256_store_pd(fs + 4 * sl[g][3], _mm256_permute2f128_pd(t1, t3, 0x31));
    }
  }
  spring_pass_scalar(model, px, fs, j, j1, Listed ? list : nullptr);
}

__attribute__((target("avx2"))) void spring_pass_avx2(const Model& model, const double* px, double* fs,
                                                      std::size_t j0, std::size_t j1,
                                                      const std::uint32_t* list = nullptr) {
  if (list)
    spring_pass_avx2_impl<true>(model, px, fs, j0, j1, list);
  else
    spring_pass_avx2_impl<false>(model, px, fs, j0, j1, nullptr);
}

// The gather's first term for mass i: g m_i - gamma v_i with v, else the f_i already there.
__attribute__((target("avx2"), always_inline)) inline __m256d mass_base(std::size_t i, const double* m, __m256d g,
                                                                        __m256d gamma, const double* pv,
                                                                        const double* pf) {
  if (pv) {
    const __m256d v = _mm256_setr_pd(pv[3 * i], pv[3 * i + 1], pv[3 * i + 2], 0.0);
    return _mm256_sub_pd(_mm256_mul_pd(g, _mm256_set1_pd(m[i])), _mm256_mul_pd(gamma, v));
  }
  return _mm256_setr_pd(pf[3 * i], pf[3 * i + 1], pf[3 * i + 2], 0.0);
}

// The force of the spring whose b end entry `en` is (spring | kB): en << 5 in 32 bits drops
// the flag and is the byte offset of fs[4 spring] (SpringAdjacency::run, which enables the
// paths that use this, is made only for fewer than 2^27 springs).
__attribute__((target("avx2"), always_inline)) inline __m256d b_term(const char* fs_bytes, std::uint32_t en) {
  return _mm256_load_pd(reinterpret_cast<const double*>(fs_bytes + static_cast<std::uint32_t>(en << 5)));
}

__attribute__((target("avx2"))) void mass_pass_avx2(const Model& model, const SpringAdjacency& adj,
                                                    const double* fs, const double* pv, double* pf,
                                                    std::size_t i0, std::size_t i1) {
  const double* m = model.mass.data();
  const Eigen::Vector3d& gv = model.options.gravity;
  const __m256d g = _mm256_setr_pd(gv[0], gv[1], gv[2], 0.0);
  const __m256d gamma = _mm256_set1_pd(model.options.damping);
  const std::uint32_t* start = adj.start.data();
  const std::uint32_t* entry = adj.entry.data();
  const std::uint32_t* run = adj.run.empty() ? nullptr : adj.run.data();
  alignas(32) static const double signs[8] = {0.0, 0.0, 0.0, 0.0, -0.0, -0.0, -0.0, -0.0};
  const char* fb = reinterpret_cast<const char*>(fs);
  std::size_t i = i0;
  if (run) {
    // Two masses at a time, their sums interleaved term by term (each in its own order, so
    // the same bits): two dependency chains of adds for the core to overlap.
    for (; i + 2 <= i1; i += 2) {
      __m256d f[2] = {mass_base(i, m, g, gamma, pv, pf), mass_base(i + 1, m, g, gamma, pv, pf)};
      // the a ends: consecutive springs from the first entry on
      const std::uint32_t na0 = run[i], na1 = run[i + 1];
      const double* q0 = na0 > 0 ? fs + 4 * std::size_t{entry[start[i]]} : fs;
      const double* q1 = na1 > 0 ? fs + 4 * std::size_t{entry[start[i + 1]]} : fs;
      const std::uint32_t both = std::min(na0, na1);
      std::uint32_t t = 0;
      for (; t < both; ++t) {
        f[0] = _mm256_add_pd(f[0], _mm256_load_pd(q0 + 4 * std::size_t{t}));
        f[1] = _mm256_add_pd(f[1], _mm256_load_pd(q1 + 4 * std::size_t{t}));
      }
      for (std::uint32_t u = t; u < na0; ++u) f[0] = _mm256_add_pd(f[0], _mm256_load_pd(q0 + 4 * std::size_t{u}));
      for (std::uint32_t u = t; u < na1; ++u) f[1] = _mm256_add_pd(f[1], _mm256_load_pd(q1 + 4 * std::size_t{u}));
      // the b ends
      const std::uint32_t *b0 = entry + start[i] + na0, *b0_end = entry + start[i + 1];
      const std::uint32_t *b1 = entry + start[i + 1] + na1, *b1_end = entry + start[i + 2];
      for (; b0 < b0_end && b1 < b1_end; ++b0, ++b1) {
        f[0] = _mm256_sub_pd(f[0], b_term(fb, *b0));
        f[1] = _mm256_sub_pd(f[1], b_term(fb, *b1));
      }
      for (; b0 < b0_end; ++b0) f[0] = _mm256_sub_pd(f[0], b_term(fb, *b0));
      for (; b1 < b1_end; ++b1) f[1] = _mm256_sub_pd(f[1], b_term(fb, *b1));
      for (int h = 0; h < 2; ++h) {
        double* out = pf + 3 * (i + static_cast<std::size_t>(h));
        _mm_storeu_pd(out, _mm256_castpd256_pd128(f[h]));
        _mm_store_sd(out + 2, _mm256_extractf128_pd(f[h], 1));
      }
    }
  }
  for (; i < i1; ++i) {  // one at a time: every mass without runs, else the last of an odd range
    __m256d f = mass_base(i, m, g, gamma, pv, pf);
    // A run of a ends (+fs), a run of b ends (-fs: f - y), then any other order term by term
    // (ModelBuilder orders springs so that there is none; then the a ends are consecutive
    // springs, read as a range, and the rest are all b ends).
    std::uint32_t e = start[i];
    const std::uint32_t end = start[i + 1];
    if (run) {  // the a ends are consecutive springs: read as a range
      const std::uint32_t na = run[i];
      if (na > 0) {
        const double* q = fs + 4 * std::size_t{entry[e]};
        for (std::uint32_t k = 0; k < na; ++k) f = _mm256_add_pd(f, _mm256_load_pd(q + 4 * std::size_t{k}));
        e += na;
      }
      // the rest are b ends (SpringAdjacency::build checked)
      for (const std::uint32_t* b = entry + e; b < entry + end; ++b) f = _mm256_sub_pd(f, b_term(fb, *b));
      e = end;
    } else {
      for (; e < end && !(entry[e] & SpringAdjacency::kB); ++e)
        f = _mm256_add_pd(f, _mm256_load_pd(fs + 4 * std::size_t{entry[e]}));
    }
    for (; e < end && (entry[e] & SpringAdjacency::kB); ++e)
      f = _mm256_sub_pd(f, _mm256_load_pd(fs + 4 * std::size_t{entry[e] & ~SpringAdjacency::kB}));
    for (; e < end; ++e) {
      // +-fs: flip the sign bits for the b end (x + (-y) == x - y exactly)
      const std::uint32_t en = entry[e];
      const __m256d sign = _mm256_load_pd(signs + 4 * (en >> 31));
      f = _mm256_add_pd(f, _mm256_xor_pd(_mm256_load_pd(fs + 4 * std::size_t{en & ~SpringAdjacency::kB}), sign));
    }
    _mm_storeu_pd(pf + 3 * i, _mm256_castpd256_pd128(f));
    _mm_store_sd(pf + 3 * i + 2, _mm256_extractf128_pd(f, 1));
  }
}

bool use_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") && std::getenv("CLOTHSIM_NO_AVX2") == nullptr;
  return yes;
}
#endif

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
  [[maybe_unused]] const int nt = team(model.mass_count());
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
#pragma omp parallel num_threads(nt) if (nt > 1)
  {
    int t = 0, parts = 1;
#ifdef _OPENMP
    t = omp_get_thread_num();
    parts = omp_get_num_threads();
#endif
    if (split && parts == split->threads) {
      // Block by block as on one thread (SpringSplit): the springs other threads need first,
      // then, chunk by chunk, the chunk's other springs and its masses. (All springs, then all
      // masses, as below, made two threads spend 1.8x the cycles of one on the springs: the
      // spring blocks went out of the caches between the two passes.)
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
  }
}

}  // namespace

void add_spring_forces(const Model& model, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f,
                       Workspace& ws) {
  if (!has_adjacency(model, ws)) return add_spring_forces(model, x, f);
  gathered_springs(model, x, nullptr, f, ws);
}

void compute_forces(const Model& model, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                    Eigen::Matrix3Xd& f, Workspace& ws) {
  const Options& o = model.options;
  if (has_adjacency(model, ws)) {
    // gravity, the damping of eq. 6 (a = (f - gamma v)/m) and the springs in one pass per mass
    gathered_springs(model, x, v.data(), f, ws);
  } else {
    f.noalias() = o.gravity * model.mass.transpose() - o.damping * v;
    add_spring_forces(model, x, f);
  }
  ws.last_penetration = 0.0;
  ws.last_contacts = 0;
#ifdef CLOTHSIM_HAVE_COLLISION
  if (model.colliders) {
    const ColliderSet& set = *model.colliders;
    PenaltyStats stats;
    const std::size_t n = model.mass_count();
    const int nt = team(collision_work(n, set.object_count()));
    if (!ws.collision) {  // a Workspace not made by make_workspace: the hints, if sized
      accumulate_penalty(set, x, o.epsilon, o.k_rep, f, stats, std::span<std::int32_t>(ws.contact_hint));
    } else if (nt <= 1) {
      accumulate_penalty(set, x, o.epsilon, o.k_rep, f, stats, ws.collision->whole);
    } else {
      // Runs of kRun masses, a contiguous share of them per thread (handing them out as
      // threads get free was 30 % slower: the cache entries then moved between the cores), the
      // shares balanced by the time each took in the last call. All share one cache: a point's
      // answer and force do not depend on the others or on who computes them; the statistics
      // combine in run order. So the results do not depend on the split, only the speed does.
      CollisionScratch& cs = *ws.collision;
      const std::size_t count = (n + CollisionScratch::kRun - 1) / CollisionScratch::kRun;
      const auto parts = static_cast<std::size_t>(nt);
      if (cs.runs.size() != count || cs.bound.size() != parts + 1) {  // allocates once per thread count
        cs.runs.assign(count, {});
        cs.bound.resize(parts + 1);
        for (std::size_t t = 0; t <= parts; ++t) cs.bound[t] = count * t / parts;
        cs.seconds.assign(parts, 0.0);
      }
      bool timed = true;
      cs.whole.tick();  // one call of the shared cache, in runs
      cs.whole.use_band(o.epsilon);
#pragma omp parallel num_threads(nt)
      {
        const std::size_t t = thread_num(), got = team_size();
        const double t0 = wtime();
        const std::size_t r0 = got == parts ? cs.bound[t] : count * t / got;
        const std::size_t r1 = got == parts ? cs.bound[t + 1] : count * (t + 1) / got;
        for (std::size_t r = r0; r < r1; ++r) {
          const std::size_t b = r * CollisionScratch::kRun;
          accumulate_penalty(set, x, b, std::min(n, b + CollisionScratch::kRun), o.epsilon, o.k_rep, f,
                             cs.runs[r], cs.whole);
        }
        if (got == parts) cs.seconds[t] = wtime() - t0;
#pragma omp single nowait
        if (got != parts) timed = false;
      }
      for (std::size_t t = 1; timed && t < parts; ++t) {
        if (cs.seconds[t - 1] > 1.1 * cs.seconds[t] && cs.bound[t] > cs.bound[t - 1]) --cs.bound[t];
        else if (cs.seconds[t] > 1.1 * cs.seconds[t - 1] && cs.bound[t] < cs.bound[t + 1]) ++cs.bound[t];
      }
      for (const auto& run : cs.runs) {
        stats.max_penetration = std::max(stats.max_penetration, run.max_penetration);
        stats.contacts += run.contacts;
      }
    }
    ws.last_penetration = stats.max_penetration;
    ws.last_contacts = static_cast<std::uint32_t>(stats.contacts);
  }
#endif
  const Drag& d = ws.drag;
  if (d.mass >= 0 && static_cast<std::size_t>(d.mass) < model.mass_count() && d.k > 0.0) {
    const Eigen::Vector3d pull = d.target - x.col(d.mass);
    const double len = pull.norm();
    f.col(d.mass) += d.k * (len > d.reach ? (d.reach / len) * pull : pull);
  }
}

namespace {

constexpr std::uint64_t kExpBits = 0x7ff0000000000000ull, kExpOne = std::uint64_t{1} << 52;

#ifdef CLOTHSIM_AVX2
// finite_span()'s test on 4 values: bit 63 of a lane is set when its value is NaN or infinite.
__attribute__((target("avx2"), always_inline)) inline __m256i nonfinite_lanes(__m256d v) {
  return _mm256_add_epi64(_mm256_and_si256(_mm256_castpd_si256(v), _mm256_set1_epi64x(static_cast<long long>(kExpBits))),
                          _mm256_set1_epi64x(static_cast<long long>(kExpOne)));
}

// finite_span()'s test on the first n - n % 4 values in AVX2: that count, or SIZE_MAX when one
// of them is not finite.
__attribute__((target("avx2"))) std::size_t finite_prefix_avx2(const double* p, std::size_t n) {
  __m256i any = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) any = _mm256_or_si256(any, nonfinite_lanes(_mm256_loadu_pd(p + i)));
  return _mm256_movemask_pd(_mm256_castsi256_pd(any)) != 0 ? std::numeric_limits<std::size_t>::max() : i;
}
#endif

// Whether p[0 .. n) are all finite: a double is NaN or infinite when its exponent bits are all
// ones, that is when (bits & E) + 2^52 carries into bit 63. Integer operations: no sum that
// could overflow, and the same answer in any order, on any thread count, with or without AVX2.
bool finite_span_plain(const double* p, std::size_t n) {
  std::uint64_t any = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t b;
    std::memcpy(&b, p + i, sizeof b);
    any |= (b & kExpBits) + kExpOne;
  }
  return (any >> 63) == 0;
}
bool finite_span(const double* p, std::size_t n) {
#ifdef CLOTHSIM_AVX2
  if (use_avx2()) {
    const std::size_t i = finite_prefix_avx2(p, n);
    return i != std::numeric_limits<std::size_t>::max() && finite_span_plain(p + i, n - i);
  }
#endif
  return finite_span_plain(p, n);
}

bool all_finite(const State& s) {
  // In 16 fixed slices (threaded for big states).
  constexpr int kSlices = 16;
  const auto n = static_cast<std::size_t>(s.x.size());
  const auto nv = static_cast<std::size_t>(s.v.size());
  [[maybe_unused]] const int nt = team(n);
  if (n < 4096 || nv != n || nt <= 1) return finite_span(s.x.data(), n) && finite_span(s.v.data(), nv);
  bool part[kSlices];
#pragma omp parallel for schedule(static) num_threads(nt)
  for (int k = 0; k < kSlices; ++k) {
    const std::size_t lo = n * static_cast<std::size_t>(k) / kSlices, hi = n * static_cast<std::size_t>(k + 1) / kSlices;
    part[k] = finite_span(s.x.data() + lo, hi - lo) && finite_span(s.v.data() + lo, hi - lo);
  }
  for (bool ok : part)
    if (!ok) return false;
  return true;
}

}  // namespace

void save_pins(const State& s, Workspace& ws) {
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p)
    ws.pinned_x.col(static_cast<Eigen::Index>(p)) = s.x.col(ws.pinned_index[p]);
}

void restore_pins(State& s, const Workspace& ws) {
  // Pinned masses keep their exact bits (x + h*0 would turn -0.0 into +0.0).
  for (std::size_t p = 0; p < ws.pinned_index.size(); ++p) {
    s.x.col(ws.pinned_index[p]) = ws.pinned_x.col(static_cast<Eigen::Index>(p));
    s.v.col(ws.pinned_index[p]).setZero();
  }
}

namespace {

#ifdef CLOTHSIM_AVX2
// The two updates of eqs. 1 and 6-7 in AVX2 for one thread: the same operations per element
// (h * v, then +; f * (1/m), then h *, then +), so the same bits.
// Four masses' values (lanes 0-3) spread over their 12 elements: m0 m0 m0 m1 | m1 m1 m2 m2 |
// m2 m3 m3 m3.
__attribute__((target("avx2"), always_inline)) inline void spread3(__m256d m, __m256d out[3]) {
  out[0] = _mm256_permute4x64_pd(m, 0b01000000), out[1] = _mm256_permute4x64_pd(m, 0b10100101);
  out[2] = _mm256_permute4x64_pd(m, 0b11111110);
}

// Masses i .. i + 3 pinned (pinned[] != 0), all-ones lanes, spread over their 12 elements.
__attribute__((target("avx2"), always_inline)) inline void pinned_lanes(const std::uint8_t* pinned, std::size_t i,
                                                                        __m256d out[3]) {
  std::uint32_t four;
  std::memcpy(&four, pinned + i, sizeof four);
  spread3(_mm256_castsi256_pd(_mm256_xor_si256(
              _mm256_cmpeq_epi64(_mm256_cvtepu8_epi64(_mm_cvtsi32_si128(static_cast<int>(four))), _mm256_setzero_si256()),
              _mm256_set1_epi64x(-1))),
          out);
}

__attribute__((target("avx2"))) bool drift_avx2(double* x, const double* v, const std::uint8_t* pinned, double h,
                                                std::size_t n) {
  // ... and whether every new x of a free mass is finite (a pinned one's is put back after the
  // step)
  const __m256d hv = _mm256_set1_pd(h);
  __m256i any = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {  // 4 masses, 12 elements
    __m256d pin[3];
    pinned_lanes(pinned, i, pin);
    for (std::size_t k = 0; k < 3; ++k) {
      double* px = x + 3 * i + 4 * k;
      const __m256d nx = _mm256_add_pd(_mm256_loadu_pd(px), _mm256_mul_pd(hv, _mm256_loadu_pd(v + 3 * i + 4 * k)));
      _mm256_storeu_pd(px, nx);
      any = _mm256_or_si256(any, _mm256_andnot_si256(_mm256_castpd_si256(pin[k]), nonfinite_lanes(nx)));
    }
  }
  bool ok = _mm256_movemask_pd(_mm256_castsi256_pd(any)) == 0;
  for (; i < n; ++i)
    for (std::size_t r = 0; r < 3; ++r) {
      x[3 * i + r] += h * v[3 * i + r];
      if (!pinned[i] && !finite_span_plain(x + 3 * i + r, 1)) ok = false;
    }
  return ok;
}
__attribute__((target("avx2"))) bool kick_avx2(double* v, const double* f, const double* im,
                                               const std::uint8_t* pinned, double h, std::size_t n) {
  // ... and whether every new v of a free mass is finite (a pinned one's is set to 0 after the
  // step)
  const __m256d hv = _mm256_set1_pd(h);
  __m256i any = _mm256_setzero_si256();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {  // 4 masses, 12 elements
    __m256d w[3], pin[3];
    spread3(_mm256_loadu_pd(im + i), w);
    pinned_lanes(pinned, i, pin);
    for (std::size_t k = 0; k < 3; ++k) {
      double* pv = v + 3 * i + 4 * k;
      const __m256d nv = _mm256_add_pd(_mm256_loadu_pd(pv),
                                       _mm256_mul_pd(hv, _mm256_mul_pd(_mm256_loadu_pd(f + 3 * i + 4 * k), w[k])));
      _mm256_storeu_pd(pv, nv);
      any = _mm256_or_si256(any, _mm256_andnot_si256(_mm256_castpd_si256(pin[k]), nonfinite_lanes(nv)));
    }
  }
  bool ok = _mm256_movemask_pd(_mm256_castsi256_pd(any)) == 0;
  for (; i < n; ++i)
    for (std::size_t r = 0; r < 3; ++r) {
      v[3 * i + r] += h * (f[3 * i + r] * im[i]);
      if (!pinned[i] && !finite_span_plain(v + 3 * i + r, 1)) ok = false;
    }
  return ok;
}
#endif

}  // namespace

namespace {

// One step of eqs. 1-7; on one thread with AVX2 it also tells whether the new state is finite
// (checked: true), as all_finite() would after it, from the values it writes.
void symplectic_euler(const Model& model, State& state, Workspace& ws, bool& checked, bool& finite) {
  const double h = model.options.dt;
  checked = false;
  save_pins(state, ws);
  const auto n = static_cast<std::int64_t>(model.mass_count());
  double* px = state.x.data();
  double* pv = state.v.data();
  const double* pf = ws.f.data();
  const double* im = model.inv_mass.data();
  [[maybe_unused]] const int nt = team(static_cast<std::size_t>(n));
#ifdef CLOTHSIM_AVX2
  if (use_avx2()) {
    // In AVX2, each thread its share of masses (a multiple of 4; the same bits on any count),
    // with the finiteness of what it writes.
    const std::uint8_t* pinned = model.pinned.data();
    const auto nm = static_cast<std::size_t>(n);
    const auto share = [nm](std::size_t t, std::size_t parts) { return std::min(nm, (nm * t / parts + 3) / 4 * 4); };
    bool x_ok = true, v_ok = true;
    if (nt <= 1) {  // (a parallel region of one thread still costs ~0.2 us)
      x_ok = drift_avx2(px, pv, pinned, h, nm);
    } else {
#pragma omp parallel num_threads(nt) reduction(&& : x_ok)
      {
        const std::size_t lo = share(thread_num(), team_size()), hi = share(thread_num() + 1, team_size());
        x_ok = drift_avx2(px + 3 * lo, pv + 3 * lo, pinned + lo, h, hi - lo);
      }
    }
    compute_forces(model, state.x, state.v, ws.f, ws);  // eqs. 2-5 at x(t+h)
    if (nt <= 1) {
      v_ok = kick_avx2(pv, pf, im, pinned, h, nm);
    } else {
#pragma omp parallel num_threads(nt) reduction(&& : v_ok)
      {
        const std::size_t lo = share(thread_num(), team_size()), hi = share(thread_num() + 1, team_size());
        v_ok = kick_avx2(pv + 3 * lo, pf + 3 * lo, im + lo, pinned + lo, h, hi - lo);
      }
    }
    // the pinned masses end with their saved positions and velocity 0
    checked = true;
    finite = x_ok && v_ok && finite_span(ws.pinned_x.data(), static_cast<std::size_t>(ws.pinned_x.size()));
    restore_pins(state, ws);
    return;
  }
#endif
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t e = 0; e < 3 * n; ++e) px[e] += h * pv[e];  // eq. 1
  compute_forces(model, state.x, state.v, ws.f, ws);            // eqs. 2-5 at x(t+h)
  // eqs. 6-7 (damping is in f): v += h (f / m), as h * (f * (1/m))
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
  for (std::int64_t i = 0; i < n; ++i)
    for (std::int64_t r = 0; r < 3; ++r) pv[3 * i + r] += h * (pf[3 * i + r] * im[i]);
  restore_pins(state, ws);
}

}  // namespace

void step_symplectic_euler(const Model& model, State& state, Workspace& ws) {
  bool checked = false, finite = true;
  symplectic_euler(model, state, ws, checked, finite);
}

StepStatus step(const Model& model, State& state, Workspace& ws) {
  ws.drag = state.drag;
  bool checked = false, finite = true;
  switch (model.options.integrator) {
    case Integrator::SymplecticEuler:
      symplectic_euler(model, state, ws, checked, finite);
      break;
    default:  // the other integrators (integrators.cpp, issue 5)
      integrate(model, state, ws);
      break;
  }
  state.t += model.options.dt;
  ++state.steps;
  state.max_penetration = std::max(state.max_penetration, ws.last_penetration);
  return StepStatus{checked ? finite : all_finite(state)};
}

double kinetic_energy(const Model& model, const State& state) {
  double e = 0.0;
  for (Eigen::Index i = 0; i < state.v.cols(); ++i)
    if (!model.pinned[static_cast<std::size_t>(i)]) e += 0.5 * model.mass[i] * state.v.col(i).squaredNorm();
  return e;
}

double gershgorin_omega_max(const Model& model) {
  const std::size_t n = model.mass_count();
  std::vector<double> ksum(n, model.colliders ? model.options.k_rep : 0.0);
  for (std::size_t s = 0; s < model.spring_count(); ++s) {
    ksum[model.spring_a[s]] += model.spring_stiffness(s);
    ksum[model.spring_b[s]] += model.spring_stiffness(s);
  }
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (!model.pinned[i]) w2 = std::max(w2, 2.0 * ksum[i] / model.mass[static_cast<Eigen::Index>(i)]);
  return std::sqrt(w2);
}

std::uint64_t state_hash(const State& state) {
  std::uint64_t h = 14695981039346656037ull;
  auto mix = [&h](const double* p, Eigen::Index count) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < static_cast<std::size_t>(count) * sizeof(double); ++i) {
      h ^= bytes[i];
      h *= 1099511628211ull;
    }
  };
  mix(state.x.data(), state.x.size());
  mix(state.v.data(), state.v.size());
  return h;
}

std::string validate_options(const Options& o) {
  auto num = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  auto positive = [&](const char* name, double v) -> std::string {
    if (std::isfinite(v) && v > 0.0) return {};
    return std::string(name) + " must be a finite number > 0 (got " + num(v) + ")";
  };
  auto non_negative = [&](const char* name, double v) -> std::string {
    if (std::isfinite(v) && v >= 0.0) return {};
    return std::string(name) + " must be a finite number >= 0 (got " + num(v) + ")";
  };
  for (const std::string& why : {positive("dt", o.dt), positive("mass", o.mass), non_negative("k_struct", o.k_struct),
                                 non_negative("k_bend", o.k_bend), non_negative("damping", o.damping),
                                 positive("epsilon", o.epsilon), non_negative("k_rep", o.k_rep)})
    if (!why.empty()) return why;
  if (!o.gravity.allFinite()) return "gravity must be finite";
  return {};
}

}  // namespace clothsim
