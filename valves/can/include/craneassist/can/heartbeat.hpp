// craneassist's alive message and its supervision on the machine side (docs/can.md).
//
// Payload, 8 bytes: byte 0 the alive counter (0..255, +1 per message, wrapping), byte 1 the
// state (0 disabled: every section commanded to block, 1 enabled, 2 fault latched), byte 2 the
// fault reason code (can::FaultReason, 0 none), bytes 3..7 0xFF (J1939: not available).
// Encode, decode and the monitor allocate nothing and throw nothing.
#pragma once

#include <cstdint>

#include "craneassist/can/can_frame.hpp"
#include "craneassist/can/mapping_config.hpp"

namespace craneassist::can {

enum class HeartbeatState : std::uint8_t { kDisabled = 0, kEnabled = 1, kFault = 2 };

struct Heartbeat {
  std::uint8_t counter = 0;
  HeartbeatState state = HeartbeatState::kDisabled;
  std::uint8_t reason = 0;
};

void encode_heartbeat(const HeartbeatSpec& spec, const Heartbeat& hb, CanFrame& frame);
bool is_heartbeat_frame(const HeartbeatSpec& spec, const CanFrame& frame);
// False when the frame is not the heartbeat, is shorter than 3 bytes or names an unknown state.
bool decode_heartbeat(const HeartbeatSpec& spec, const CanFrame& frame, Heartbeat& hb);

// The machine side: motion is allowed while a heartbeat in state enabled, whose counter advanced
// by exactly one, arrived within the timeout. A repeated or skipped counter does not refresh it.
class HeartbeatMonitor {
 public:
  explicit HeartbeatMonitor(const HeartbeatSpec& spec) : spec_(spec) {}

  // Feeds a received frame (t_s: its receive time). Returns true when it was the heartbeat.
  bool on_frame(const CanFrame& frame, double t_s);
  // Whether the sender may move the machine at time t_s. Counts a loss once per lapse.
  bool alive(double t_s);

  std::uint64_t messages() const { return messages_; }
  std::uint64_t sequence_errors() const { return sequence_errors_; }  // repeated/skipped counter
  std::uint64_t malformed() const { return malformed_; }
  std::uint64_t losses() const { return losses_; }  // alive -> not alive transitions
  // The last decoded heartbeat (state and reason as the sender reported them).
  const Heartbeat& last() const { return last_; }

 private:
  HeartbeatSpec spec_;
  Heartbeat last_;
  bool have_last_ = false;
  bool was_alive_ = false;
  double refreshed_s_ = -1e300;
  std::uint64_t messages_ = 0, sequence_errors_ = 0, malformed_ = 0, losses_ = 0;
};

}  // namespace craneassist::can
