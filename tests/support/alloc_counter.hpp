// Replaces the global operator new/delete to count allocations. Include it in exactly one
// source of a test executable (it defines the replacement operators), then read
// alloc_counter::count() before and after the code that must not allocate.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace alloc_counter {
inline std::atomic<long> g_allocations{0};
// Called through a pointer so that GCC does not pair the inlined new/free (-Wmismatched-new-delete).
inline void (*volatile g_free)(void*) = std::free;
inline long count() { return g_allocations.load(); }
}  // namespace alloc_counter

void* operator new(std::size_t n) {
  alloc_counter::g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { alloc_counter::g_free(p); }
void operator delete(void* p, std::size_t) noexcept { alloc_counter::g_free(p); }
// The nothrow form too (std::stable_sort's temporary buffer uses it, and frees it with the plain
// delete above: ASan reports a mismatch unless both are ours).
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  alloc_counter::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { alloc_counter::g_free(p); }
