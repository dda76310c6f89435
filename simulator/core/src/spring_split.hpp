// Which springs and masses each thread of the gathered spring pass takes.
#pragma once

#include <clothsim/step.hpp>

#include <cstdint>
#include <vector>

namespace clothsim::detail {

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

  /// Makes the split for nt threads (allocates).
  void make(const Model& model, int nt);
};

}  // namespace clothsim::detail
