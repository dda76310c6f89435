// One kind of spring in colours, packed: no two springs of a colour share a mass, so a colour's
// springs can be worked on by several threads at once, in any order, with the same result.
#pragma once

#include <clothsim/sim.hpp>

#include <cstdint>
#include <vector>

namespace clothsim::detail {

struct Link {
  std::uint32_t a, b;
  double rest, k;  ///< m, N/m
};

struct Colouring {
  std::vector<std::uint32_t> start;  ///< (colours + 1) the last colour may share masses
  std::vector<Link> links;
};

/// Greedy edge colouring of the springs of one kind, in spring order; springs that cannot move
/// (both ends pinned, k 0) are left out; a spring that finds none of 63 colours free goes to a
/// last colour, which the passes take on one thread.
Colouring colour_springs(const Model& m, std::uint8_t kind);

}  // namespace clothsim::detail
