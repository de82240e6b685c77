// The hand-over of a device's latest gamepad state from its reader thread to the loop: the reader
// publishes under a mutex, the loop takes it with try_lock (keeping its previous copy when the
// reader holds the lock), so the loop never waits.
#pragma once

#include <mutex>

#include "craneassist/input/gamepad.hpp"

namespace craneassist::input {

struct PadSnapshot {
  GamepadState pad;
  double stamp_s = 0.0;  // when the reader last confirmed this state (steady clock, s)
  bool connected = false;
  bool has_state = false;  // a complete state was read since (re)connecting
};

class LatestPad {
 public:
  void publish(const PadSnapshot& s) {
    std::lock_guard<std::mutex> lock(mutex_);
    snapshot_ = s;
  }
  // Copies the latest snapshot into out; false (out unchanged) when the lock was busy.
  bool try_take(PadSnapshot& out) noexcept {
    if (!mutex_.try_lock()) return false;
    out = snapshot_;
    mutex_.unlock();
    return true;
  }

 private:
  std::mutex mutex_;
  PadSnapshot snapshot_;
};

}  // namespace craneassist::input
