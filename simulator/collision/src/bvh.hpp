// The 4-wide node test's vector type and the traversal stack entry, shared by the
// closest-triangle searches (bvh_query.cpp) and the clearance scan (clearance.cpp).
#pragma once

#include <cstdint>
#include <cstring>

namespace clothsim::detail {

// 4 floats for the 4-wide node test (GCC/Clang vector extension, no intrinsics).
typedef float v4f __attribute__((vector_size(16)));
inline v4f load4(const float* p) {
  v4f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline v4f vabs(v4f x) { return x < 0.0f ? -x : x; }
inline v4f pos(v4f x) { return x > 0.0f ? x : v4f{0.0f, 0.0f, 0.0f, 0.0f}; }

// A BVH traversal's stack entry: a node or leaf (Node::packed form) and its box distance^2.
struct StackEntry {
  std::uint32_t ref;
  float d2;
};

}  // namespace clothsim::detail
