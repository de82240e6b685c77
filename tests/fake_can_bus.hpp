// An in-memory CAN bus for host tests: two (or more) FakeCanTransport ends see each other's
// frames, as two raw sockets on one vcan interface do (a sender does not receive its own frames).
#pragma once

#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

#include "craneassist/can/transport.hpp"

namespace craneassist::can::testing {

class FakeCanBus;

class FakeCanTransport final : public Transport {
 public:
  explicit FakeCanTransport(FakeCanBus& bus) : bus_(bus) {}
  SendStatus send(const CanFrame& frame) override;
  void receive(Received& out) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.empty()) {
      out.kind = ReceiveKind::kNone;
      return;
    }
    out = queue_.front();
    queue_.pop_front();
  }
  bool wait_readable(int) override {
    std::lock_guard<std::mutex> lock(mutex_);
    return !queue_.empty();
  }
  const char* interface_name() const override { return "fake0"; }
  void deliver(const Received& r) {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(r);
  }
  SendStatus next_send_status = SendStatus::kOk;  // set by a test to inject failures

 private:
  FakeCanBus& bus_;
  std::mutex mutex_;
  std::deque<Received> queue_;
};

class FakeCanBus {
 public:
  void attach(FakeCanTransport* t) { ends_.push_back(t); }
  void broadcast(const FakeCanTransport* from, const CanFrame& frame) {
    Received r;
    r.kind = ReceiveKind::kFrame;
    r.frame = frame;
    r.timestamp_us = realtime_now_us() + wall_clock_step_us;
    for (auto* e : ends_) {
      if (e != from) e->deliver(r);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    log_.push_back(r);
  }
  std::vector<Received> log() {
    std::lock_guard<std::mutex> lock(mutex_);
    return log_;
  }
  // Added to the receive timestamps (CLOCK_REALTIME, as the kernel stamps them): a test's wall
  // clock step.
  std::int64_t wall_clock_step_us = 0;
  void clear_log() {
    std::lock_guard<std::mutex> lock(mutex_);
    log_.clear();
  }

 private:
  std::vector<FakeCanTransport*> ends_;
  std::mutex mutex_;
  std::vector<Received> log_;
};

inline SendStatus FakeCanTransport::send(const CanFrame& frame) {
  if (next_send_status != SendStatus::kOk) return next_send_status;
  bus_.broadcast(this, frame);
  return SendStatus::kOk;
}

}  // namespace craneassist::can::testing
