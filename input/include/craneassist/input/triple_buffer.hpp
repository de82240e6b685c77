// The newest value, handed from one producer thread to one consumer thread: a triple buffer.
// Three preallocated slots; the producer writes its back slot and publishes it, the consumer
// takes the newest published slot as its front. Each side does one atomic exchange: neither
// waits nor allocates, the consumer always sees a whole value, and the newest value is never
// lost (a value published while the consumer is busy is there at its next update()).
#pragma once

#include <array>
#include <atomic>
#include <cstddef>

namespace craneassist::input {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}

  // Before the threads start: every slot (to preallocate them).
  std::array<T, 3>& slots() noexcept { return slots_; }

  // Producer: the slot to write, then publish() it (the producer gets another slot to write).
  T& back() noexcept { return slots_[index(back_)]; }
  void publish() noexcept {
    back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndexMask;
  }

  // Consumer: takes the newest published value into front(); false when nothing newer came.
  bool update() noexcept {
    if ((middle_.load(std::memory_order_acquire) & kFresh) == 0) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndexMask;
    return true;
  }
  // Consumer: the value taken last (a default or initial value before the first), the
  // consumer's to read and change.
  T& front() noexcept { return slots_[index(front_)]; }
  const T& front() const noexcept { return slots_[index(front_)]; }

 private:
  static constexpr int kFresh = 4;  // in middle_: its slot is newer than the consumer's front
  static constexpr int kIndexMask = 3;
  static constexpr std::size_t index(int i) noexcept { return static_cast<std::size_t>(i); }

  std::array<T, 3> slots_{};
  int back_ = 0;
  std::atomic<int> middle_{1};
  int front_ = 2;
};

}  // namespace craneassist::input
