// CanBackend's private state, shared by its two source files: can_backend.cpp (the frames of
// the mapping, the watchdog, the log) and can_backend_supervision.cpp (the J1939 address claim,
// the valves' replies and DM1). Not installed; nothing outside the backend includes it.
#pragma once

#include <time.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/can_backend.hpp"
#include "craneassist/can/dm1.hpp"
#include "craneassist/can/heartbeat.hpp"
#include "craneassist/can/iso11783_valve.hpp"

namespace craneassist::can {

namespace backend_detail {

inline std::int64_t mono_us() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

struct LogEntry {
  CanFrame frame;
  TimestampUs t_us = 0;
  CandumpDirection direction = CandumpDirection::kNone;  // sent or received
};

// Single producer, single consumer; a full ring drops the entry (counted by the caller).
class LogRing {
 public:
  explicit LogRing(std::size_t capacity) : buf_(capacity + 1) {}
  bool push(const CanFrame& f, TimestampUs t, CandumpDirection direction) {
    const std::size_t h = head_.load(std::memory_order_relaxed);
    const std::size_t next = (h + 1) % buf_.size();
    if (next == tail_.load(std::memory_order_acquire)) return false;
    buf_[h].frame = f;
    buf_[h].t_us = t;
    buf_[h].direction = direction;
    head_.store(next, std::memory_order_release);
    return true;
  }
  bool pop(LogEntry& e) {
    const std::size_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    e = buf_[t];
    tail_.store((t + 1) % buf_.size(), std::memory_order_release);
    return true;
  }

 private:
  std::vector<LogEntry> buf_;
  std::atomic<std::size_t> head_{0}, tail_{0};
};

struct AtomicCounters {
  std::atomic<std::uint64_t> frames_sent{0}, frames_received{0}, send_queue_full{0}, send_errors{0},
      unknown_frames{0}, bad_frames{0}, unsupported_frames{0}, bus_error_frames{0},
      receive_errors{0}, watchdog_block_frames{0}, faults{0}, log_dropped{0}, heartbeats_sent{0},
      claim_frames_sent{0}, valve_replies{0}, dm1_messages{0};
};

inline constexpr int kMaxDrainPerRead = 512;

}  // namespace backend_detail

enum class ReplyFault : std::uint8_t { kNone, kErrorState, kNonRecoverable, kStatus };

struct CanBackend::Impl {
  Impl(Transport& t, const CanBackendOptions& o)
      : transport(t), options(o), control_ring(o.log_capacity), watchdog_ring(o.log_capacity) {}

  struct Joint {
    JointMapping map;
    double area_ratio = 0.0;  // A_B / A_A
    std::int64_t cycle_us = 20000;
    std::int64_t last_sent_us = 0;           // control thread
    std::int64_t watchdog_last_sent_us = 0;  // watchdog thread
    CanFrame block_frame;                    // preencoded
    CanFrame command_frame;
    bool seen = false;
    // The newest position frame: its receive stamp (CLOCK_REALTIME, the kernel's; for the
    // velocity estimate and the log) and when read() took it (CLOCK_MONOTONIC; for freshness,
    // so a wall-clock step neither hides lost feedback nor fakes it).
    TimestampUs last_position_us = 0;
    std::int64_t last_position_mono_us = 0;
    double q = 0.0, qdot = 0.0, pa = 0.0, pb = 0.0;
    // The valve's reply (map.reply), control thread; can_backend_supervision.cpp.
    bool from_claimed_address = false;  // the command frame carries the claimed source address
    iso11783::ValveState commanded_state = iso11783::ValveState::kBlock;  // last frame sent
    double commanded_flow = 0.0;                                          // its port flow
    std::int64_t reply_mono_us = 0;              // the newest reply, taken (mono); 0: none yet
    std::int64_t not_following_since_us = 0;     // its state has differed from the command since
    ReplyFault reply_fault = ReplyFault::kNone;  // what the newest reply reported
    iso11783::ValveState reply_state = iso11783::ValveState::kNotAvailable;
    iso11783::LimitStatus reply_limit = iso11783::LimitStatus::kNotAvailable;
    std::uint64_t reply_status = 0;  // signal valves: the newest raw status

    // Remembers what an ISO 11783 command frame just sent asked for (state and port flow), for
    // the reply's check that the valve follows it.
    void note_command(const CanFrame& f) {
      if (map.valve.kind != ValveOutputKind::kIso11783Avc || f.dlc < 3) return;
      commanded_state = static_cast<iso11783::ValveState>(f.data[2] & 0x0Fu);
      commanded_flow = f.data[0] * iso11783::kStandardFlowPerBit;
    }
  };

  // A node whose DM1 is supervised (mapping diagnostics.dm1).
  struct Dm1Node {
    std::uint8_t source_address = 0;
    bool stop = false;  // its newest DM1 asks for a stop (dm1_requires_stop, or multi-packet)
    j1939::Dm1 last;
    std::uint16_t multi_packet_bytes = 0;  // its newest DM1 was announced by TP.CM BAM
  };

  Transport& transport;
  CanBackendOptions options;
  std::vector<Joint> joints;
  std::int64_t start_us = backend_detail::mono_us();
  std::atomic<std::int64_t> last_write_us{0};
  std::atomic<double> fault_time_s{NAN};
  bool block_sent_after_fault = false;
  int consecutive_send_errors = 0;
  backend_detail::AtomicCounters counters;
  backend_detail::LogRing control_ring, watchdog_ring;
  std::FILE* log_file = nullptr;
  char reason_text[256] = {};
  std::atomic<bool> stop{false};
  std::thread watchdog, logger;
  std::mutex stop_mutex;
  Received rx;
  // Pump measurements (when the mapping has them): control thread only.
  PumpMapping pump_map;
  double pump_pressure_pa = 0.0, pump_flow_m3_s = 0.0, pump_energy_j = 0.0;
  std::int64_t pump_last_us = 0;  // newest pump frame, taken (CLOCK_MONOTONIC)
  // The grapple's swing sensor (mapping.grapple): the last radial and tangential angles, rad,
  // and when each was taken.
  GrappleMapping grapple_map;
  double swing_rad[2] = {0.0, 0.0};
  std::int64_t swing_last_us[2] = {0, 0};
  std::int64_t pump_integrated_us = 0;  // mono time of the last energy step
  // The heartbeat (when the mapping has one): control thread only.
  std::optional<HeartbeatSpec> heartbeat;
  std::int64_t heartbeat_cycle_us = 0;
  std::int64_t heartbeat_last_us = 0;
  Heartbeat heartbeat_next;
  CanFrame heartbeat_frame;
  bool heartbeat_from_claimed_address = false;
  // The J1939 address claim (mapping.address_claim): the claimer on the control thread; its
  // state published for the watchdog, which must not send from an unclaimed address either.
  std::optional<j1939::AddressClaimer> claimer;
  bool has_claim = false;  // set at construction
  std::atomic<j1939::ClaimState> claim_state{j1939::ClaimState::kIdle};
  bool claim_unsent = false;  // the last claim did not go out (queue full): send it again
  CanFrame network_frame;
  // Supervision (valve replies, DM1) runs while enabled with the address claimed; since when.
  std::int64_t supervised_since_us = 0;
  std::vector<Dm1Node> dm1_nodes;

  // Whether a frame may go out now (J1939-81): with an address claim, nothing before the claim
  // has completed, and nothing from the address once it is lost. Any thread.
  bool may_send(bool from_claimed_address) const {
    if (!has_claim) return true;
    const j1939::ClaimState s = claim_state.load(std::memory_order_acquire);
    return s == j1939::ClaimState::kClaimed ||
           (s == j1939::ClaimState::kLost && !from_claimed_address);
  }
  bool claimed() const { return may_send(true); }
};

namespace backend_detail {

// Sends one frame and accounts for it: counted as sent and copied to the log ring, or counted
// as a full queue or a send error. Non-blocking, allocation-free.
template <class Counters, class Ring>
SendStatus send_counted(Transport& transport, Counters& counters, Ring& ring, bool logging,
                        const CanFrame& frame, TimestampUs now_rt_us) {
  const SendStatus st = transport.send(frame);
  if (st == SendStatus::kOk) {
    counters.frames_sent.fetch_add(1, std::memory_order_relaxed);
    if (logging && !ring.push(frame, now_rt_us, CandumpDirection::kTx)) {
      counters.log_dropped.fetch_add(1, std::memory_order_relaxed);
    }
  } else {
    (st == SendStatus::kQueueFull ? counters.send_queue_full : counters.send_errors)
        .fetch_add(1, std::memory_order_relaxed);
  }
  return st;
}

}  // namespace backend_detail

}  // namespace craneassist::can
