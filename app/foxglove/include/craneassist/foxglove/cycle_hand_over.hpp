// How the loop hands its cycles to the MCAP recorder's and the Foxglove server's threads: each
// cycle's row and machine time copied into a preallocated single-producer/single-consumer ring
// (no lock, no allocation, never waits; a full ring drops the cycle and counts it), and the
// message times of both outputs.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/control/spsc_ring.hpp"

namespace craneassist::foxglove {

// Message time of a cycle at machine time t_s (ns; the epoch offset added, never negative).
std::uint64_t message_time_ns(std::int64_t epoch_ns, double t_s) noexcept;
// The wall clock now, ns since the Unix epoch.
std::int64_t wall_clock_ns() noexcept;

class CycleHandOver {
 public:
  struct Slot {
    control::LogRow row;
    double t_s = 0.0;
  };

  // Message times are the wall clock's reading at the first cycle plus machine time, in every
  // run: a real-time run's follow the wall clock, a faster one's start when it ran and advance
  // with machine time. Before the first cycle, machine time 0 is now.
  explicit CycleHandOver(std::size_t capacity) : ring_(capacity), epoch_ns_(wall_clock_ns()) {}

  // The loop's side (its thread only).
  void push(const control::CycleRecord& cycle) noexcept {
    if (!epoch_set_) {
      epoch_set_ = true;
      epoch_ns_.store(wall_clock_ns() -
                      static_cast<std::int64_t>(std::llround(cycle.time.t_s * 1e9)));
    }
    slot_.row = cycle.row;
    slot_.t_s = cycle.time.t_s;
    if (!ring_.push(slot_)) dropped_.fetch_add(1, std::memory_order_relaxed);
  }

  // The consumer's side: the oldest cycle (nullptr: none), then pop() it.
  const Slot* front() const noexcept { return ring_.front(); }
  void pop() noexcept { ring_.pop(); }
  // The message time of machine time t_s.
  std::uint64_t time_ns(double t_s) const noexcept {
    return message_time_ns(epoch_ns_.load(), t_s);
  }
  std::uint64_t dropped() const noexcept { return dropped_.load(); }

 private:
  control::SpscRing<Slot> ring_;
  bool epoch_set_ = false;  // loop thread only
  Slot slot_;               // loop thread only
  std::atomic<std::int64_t> epoch_ns_;
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace craneassist::foxglove
