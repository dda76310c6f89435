// The per-mass spring lists of the gathered spring pass, and each thread's share of them.
#include "spring_split.hpp"

#include <algorithm>
#include <stdexcept>

namespace clothsim {

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

namespace detail {

void SpringSplit::make(const Model& model, int nt) {
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

}  // namespace detail

}  // namespace clothsim
