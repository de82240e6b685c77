// A counting global allocator, so a test can prove that a code path performs no heap
// allocation. It replaces operator new/delete for the whole test executable: include this header
// in exactly one source file of an executable.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace craneassist::test {

inline std::atomic<long> g_heap_allocations{0};
// The same, counted per thread: what a code path allocates on the thread that runs it, whatever
// the other threads of the program (an observer's writer thread, a server's I/O thread) do.
inline thread_local long t_heap_allocations = 0;

// Heap allocations through operator new since the program started.
inline long heap_allocations() {
  return g_heap_allocations.load(std::memory_order_relaxed);
}
// Heap allocations through operator new on this thread since it started.
inline long heap_allocations_on_this_thread() {
  return t_heap_allocations;
}

}  // namespace craneassist::test

// noinline: otherwise GCC pairs the malloc/free inside with operator new/delete at call sites
// and warns (-Wmismatched-new-delete).
[[gnu::noinline]] void* operator new(std::size_t size) {
  craneassist::test::g_heap_allocations.fetch_add(1, std::memory_order_relaxed);
  ++craneassist::test::t_heap_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
[[gnu::noinline]] void operator delete(void* p) noexcept {
  std::free(p);
}
[[gnu::noinline]] void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
