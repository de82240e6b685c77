// A fixed-size single-producer/single-consumer ring: the control loop pushes (no lock, no
// allocation, never waits; a full ring refuses and the caller counts), one writer thread pops.
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

namespace craneassist::control {

template <class T>
class SpscRing {
 public:
  explicit SpscRing(std::size_t capacity) : slots_(capacity + 1) {}

  // Producer: copies `value` in; false when the ring is full.
  bool push(const T& value) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t next = (head + 1) % slots_.size();
    if (next == tail_.load(std::memory_order_acquire)) return false;
    slots_[head] = value;
    head_.store(next, std::memory_order_release);
    return true;
  }

  // Consumer: the oldest value, or nullptr when empty; pop() releases it.
  const T* front() const noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    return tail == head_.load(std::memory_order_acquire) ? nullptr : &slots_[tail];
  }
  void pop() noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    tail_.store((tail + 1) % slots_.size(), std::memory_order_release);
  }

 private:
  std::vector<T> slots_;
  std::atomic<std::size_t> head_{0};  // next slot the producer writes
  std::atomic<std::size_t> tail_{0};  // next slot the consumer reads
};

}  // namespace craneassist::control
