// The real machine behind valves::MachineInterface: valve commands out and joint feedback in over
// a CAN transport (SocketCAN on a real bus), per the mapping file (docs/can.md).
//
// Control thread (read/write): no allocation, no blocking, no I/O except non-blocking socket
// calls. A watchdog thread and a log writer thread run beside it.
//
// Safety. Any of
//   - lost feedback: no position frame of some joint for feedback_timeout_s (50 ms),
//   - a malformed feedback frame (a mapped feedback identifier with a wrong dlc or a value
//     outside the signal's min/max),
//   - bus-off or error-passive reported by the controller (error frames),
//   - send errors on max_send_errors consecutive sends,
//   - a frozen control loop: write() not called for loop_timeout_s (80 ms; the watchdog thread
//     notices and sends the block commands itself; armed by the first write() after enable()),
//   - the J1939 address lost to a node whose NAME has priority (mapping `address_claim`),
//   - a valve reply (mapping `valve.reply`) reporting a fault, not following the command, or
//     silent for its timeout; a DM1 with an active DTC or the red stop lamp (`diagnostics`)
// latches a fault: every section is commanded to block (ISO 11783: state block, flow 0; signal
// outputs: 0) on every cycle from then on, read() reports kFault and state.valid = false. The
// fault stays until a deliberate enable(); nothing clears it by itself.
//
// Address claim (J1939-81). With `address_claim` in the mapping nothing is sent before the
// address is claimed: activate() (and enable(), when not claimed) sends Address Claimed, and
// read() completes the claim when its timeout (250 ms) passes without a contending claim of
// higher priority; until then write() sends nothing and read() reports no valid state. Once the
// address is lost nothing more is sent from it (the valves' own command timeout and the
// machine's heartbeat supervision take over); frames without that source address (11-bit
// signal outputs) are still commanded to block.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/mapping_config.hpp"
#include "craneassist/can/transport.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::can {

struct CanBackendOptions {
  double feedback_timeout_s = 0.05;  // per joint: no position frame for this long -> fault
  double loop_timeout_s = 0.08;      // write() not called for this long -> fault (watchdog)
  double watchdog_period_s = 0.005;
  int max_send_errors = 3;           // consecutive failed sends -> fault
  std::string candump_log;           // candump -L file of all traffic; empty: none
  std::size_t log_capacity = 16384;  // frames buffered for the log writer
  double velocity_filter_s = 0.02;   // first-order filter on the differentiated positions
};

enum class FaultReason : std::uint8_t {
  kNone,
  kFeedbackLost,
  kBadFeedbackFrame,
  kBusOff,
  kErrorPassive,
  kSendError,
  kLoopFrozen,
  kControllerRestarted,  // the controller restarted: it was bus-off, frames were lost
  kAddressLost,          // J1939: the claimed address belongs to a node with priority
  kValveFault,           // a valve's reply reports a fault or does not follow the command
  kValveReplyLost,       // a valve's reply stopped for longer than its timeout
  kDm1Fault,             // a supervised node's DM1 has an active DTC or the red stop lamp
};
const char* to_string(FaultReason reason);

struct CanBackendCounters {
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_received = 0;
  std::uint64_t send_queue_full = 0;
  std::uint64_t send_errors = 0;
  std::uint64_t unknown_frames = 0;  // identifiers the mapping does not name (ignored)
  std::uint64_t bad_frames = 0;      // mapped feedback identifiers that failed to decode
  std::uint64_t unsupported_frames = 0;
  std::uint64_t bus_error_frames = 0;
  std::uint64_t receive_errors = 0;
  std::uint64_t watchdog_block_frames = 0;  // block commands the watchdog sent itself
  std::uint64_t faults = 0;
  std::uint64_t log_dropped = 0;
  std::uint64_t heartbeats_sent = 0;
  std::uint64_t claim_frames_sent = 0;  // Address Claimed and Cannot Claim Address
  std::uint64_t valve_replies = 0;      // valve replies received (mapping `valve.reply`)
  std::uint64_t dm1_messages = 0;       // DM1 from supervised nodes (single frame or announced)
};

class CanBackend final : public valves::MachineInterface {
 public:
  // The mapping must name the model's joints in order (throws std::invalid_argument otherwise).
  // The backend starts disabled: it sends block commands until enable().
  CanBackend(const CanMapping& mapping, const dynamics::CraneModel& model, Transport& transport,
             const CanBackendOptions& options = {});
  ~CanBackend() override;
  CanBackend(const CanBackend&) = delete;
  CanBackend& operator=(const CanBackend&) = delete;

  valves::BackendStatus read(valves::MachineState& state) override;
  valves::BackendStatus write(const valves::ValveCommand& command) override;
  void advance(double) override {}
  const char* name() const override { return "can"; }
  // The slowest valve command cycle of the mapping (ISO 11783-7 AVC, or the current signal's).
  double command_period_s() const override;
  bool real_time() const override { return true; }
  // activate(): claims the address (when the mapping has address_claim) while it waits for
  // every joint's feedback, then enable(); false (with why) when the feedback does not come, or
  // the address is lost (a latched fault) or not claimed within timeout_s. safe_stop():
  // disable(). deactivate(): disable(), then stop().
  bool activate(double timeout_s, std::string* why) override;
  void safe_stop() noexcept override { disable(); }
  void deactivate() override {
    disable();
    stop();
  }

  // Start-up (may block): reads until every joint's position has arrived, or the timeout.
  bool wait_for_feedback(double timeout_s, valves::MachineState& state);
  // The deliberate (re-)enable: clears a latched fault and lets write() command the valves;
  // with address_claim and the address not (or no longer) claimed, it starts claiming and the
  // valves stay blocked until the claim completes.
  void enable();
  // The normal end of a run (control thread, non-blocking): sends block to every section at once
  // and a heartbeat in state disabled; further write()s send block until the next enable().
  void disable() noexcept;
  bool enabled() const { return enabled_.load(std::memory_order_acquire); }
  bool faulted() const override { return fault_.load(std::memory_order_acquire) == kLatched; }
  FaultReason fault_reason() const { return reason_.load(std::memory_order_acquire); }
  // The reason text of the latched fault ("" when none); not for the control thread.
  std::string fault_text() const override;
  // Monotonic time (s since construction) when the fault latched, or NaN.
  double fault_time_s() const;
  CanBackendCounters counters() const;
  // The J1939 address claim (kClaimed also when the mapping has none).
  j1939::ClaimState address_claim_state() const;
  // Stops the watchdog and flushes the log (also done by the destructor).
  void stop();

 private:
  struct Impl;
  enum : int { kClear = 0, kLatching = 1, kLatched = 2 };
  void latch(FaultReason reason, const char* fmt, ...);
  void send_heartbeat(std::int64_t now_us, std::int64_t now_rt_us);
  void read_pump(valves::PumpMeasurement& pump, std::int64_t now_mono_us, std::int64_t timeout_us);
  // Address claim, valve replies and DM1 (can_backend_supervision.cpp), control thread.
  void start_claim(std::int64_t now_us);
  bool on_supervised_frame(const CanFrame& frame, std::int64_t now_us);  // true: one of theirs
  void supervise(std::int64_t now_us);
  void send_network_frame(const CanFrame& frame);
  void watchdog_loop();
  void log_loop();

  std::unique_ptr<Impl> impl_;
  std::atomic<bool> enabled_{false};
  std::atomic<int> fault_{kClear};
  std::atomic<FaultReason> reason_{FaultReason::kNone};
};

}  // namespace craneassist::can
