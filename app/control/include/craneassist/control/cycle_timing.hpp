// Real-time readiness of the control loop: the thread set-up (memory locked, SCHED_FIFO priority,
// a pinned core) and the cycle timing histogram, in the manner of cyclictest: per cycle, the
// start latency (how late the loop woke after its tick, on CLOCK_MONOTONIC) and the compute time
// (from the wake-up to the end of the cycle's work); an overrun is a cycle whose work ended after
// the next tick.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace craneassist::control {

// What the loop asks of the system before its first cycle (all off by default).
struct RealtimeSetup {
  bool lock_memory = false;  // mlockall(MCL_CURRENT | MCL_FUTURE): no page faults in the loop
  int priority = 0;          // SCHED_FIFO priority 1..99 of the loop thread; 0: leave as is
  int cpu = -1;              // pin the loop thread to this core; -1: leave as is
};

// What the system granted; each refused request has its reason (strerror and a hint).
struct RealtimeResult {
  bool memory_locked = false;
  int priority = 0;     // the SCHED_FIFO priority granted (0: none)
  int cpu = -1;         // the core the thread is pinned to (-1: none)
  std::string refused;  // "; "-separated reasons, "" when everything asked for was granted
  // The thread's scheduling before the set-up, restored by undo_realtime_setup().
  int previous_policy = 0, previous_priority = 0;
};

// Applies the set-up to the calling thread (before the loop; may allocate).
RealtimeResult apply_realtime_setup(const RealtimeSetup& setup);
// Back to the thread's scheduling before apply_realtime_setup(), memory unlocked.
void undo_realtime_setup(const RealtimeResult& result);

// A histogram of durations in 10 us bins up to 20 ms, with the count beyond, minimum, maximum
// and mean. add() allocates nothing and throws nothing.
class DurationHistogram {
 public:
  static constexpr double kBinS = 10e-6;
  static constexpr int kBins = 2000;
  void add(double d_s) noexcept;
  long count() const noexcept { return count_; }
  double min_s() const noexcept { return count_ > 0 ? min_s_ : 0.0; }
  double max_s() const noexcept { return max_s_; }
  double mean_s() const noexcept { return count_ > 0 ? sum_s_ / static_cast<double>(count_) : 0.0; }
  // The duration below which the share p (0..1) of the samples lie (bin upper edge; the maximum
  // when it lies beyond the last bin).
  double quantile_s(double p) const noexcept;

 private:
  std::array<std::uint32_t, kBins> bins_{};
  long beyond_ = 0;
  long count_ = 0;
  double min_s_ = 0.0, max_s_ = 0.0, sum_s_ = 0.0;
};

struct CycleTiming {
  DurationHistogram start_latency;  // paced runs only
  DurationHistogram compute;
  long overruns = 0;  // the cycle's work ended after the next tick (paced runs only)
};

// One line for a summary: "start latency max 85 us (p99 40, mean 12), compute max 210 us (p99
// 95, mean 60), 0 overruns in 60000 cycles".
std::string describe(const CycleTiming& timing);

}  // namespace craneassist::control
