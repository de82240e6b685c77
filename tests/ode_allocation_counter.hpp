// Counts ODE's own heap allocations (ODE calls malloc unless allocation handlers are set), so a
// test can prove that a dynamics computation allocates nothing inside ODE either.
#pragma once

#include <ode/ode.h>

#include <atomic>
#include <cstdlib>

namespace craneassist::test {

inline std::atomic<long> g_ode_allocations{0};

// ODE allocations since count_ode_allocations() was first called.
inline long ode_allocations() {
  return g_ode_allocations.load(std::memory_order_relaxed);
}

// Routes ODE's allocations through counting handlers.
inline void count_ode_allocations() {
  dSetAllocHandler([](dsizeint size) -> void* {
    g_ode_allocations.fetch_add(1, std::memory_order_relaxed);
    return std::malloc(size);
  });
  dSetReallocHandler([](void* p, dsizeint, dsizeint size) -> void* {
    g_ode_allocations.fetch_add(1, std::memory_order_relaxed);
    return std::realloc(p, size);
  });
  dSetFreeHandler([](void* p, dsizeint) { std::free(p); });
}

// Restores ODE's own allocation (plain malloc, realloc and free).
inline void stop_counting_ode_allocations() {
  dSetAllocHandler(nullptr);
  dSetReallocHandler(nullptr);
  dSetFreeHandler(nullptr);
}

}  // namespace craneassist::test
