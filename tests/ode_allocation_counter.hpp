// Counts ODE's own heap allocations (ODE calls malloc unless allocation handlers are set), so a
// test can prove that a dynamics computation allocates nothing inside ODE either. It includes
// allocation_counter.hpp: include it in the one source file of a test executable.
#pragma once

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <atomic>
#include <cstdlib>

#include "allocation_counter.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"

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

// cycle() allocates nothing, neither on the heap nor inside ODE; and a fresh RigidBodyTerms of
// model does allocate through ODE's counted handlers at its first step (or the check proves
// nothing).
template <class Cycle>
void expect_no_heap_or_ode_allocations(const dynamics::CraneModel& model, Cycle cycle) {
  count_ode_allocations();
  const long new_before = heap_allocations();
  const long ode_before = ode_allocations();
  cycle();
  const long new_calls = heap_allocations() - new_before;
  const long ode_allocs = ode_allocations() - ode_before;

  const long before_fresh = ode_allocations();
  { dynamics::RigidBodyTerms fresh(model); }
  const long fresh_allocs = ode_allocations() - before_fresh;

  stop_counting_ode_allocations();
  EXPECT_EQ(new_calls, 0);
  EXPECT_EQ(ode_allocs, 0);
  EXPECT_GT(fresh_allocs, 0);
}

}  // namespace craneassist::test
