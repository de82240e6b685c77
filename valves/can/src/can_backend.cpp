#include "craneassist/can/can_backend.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <limits>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "can_backend_impl.hpp"
#include "craneassist/can/heartbeat.hpp"
#include "craneassist/can/valve_frames.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/dynamics/pendulum.hpp"

namespace craneassist::can {

const char* to_string(FaultReason reason) {
  switch (reason) {
    case FaultReason::kNone:
      return "none";
    case FaultReason::kFeedbackLost:
      return "feedback lost";
    case FaultReason::kBadFeedbackFrame:
      return "bad feedback frame";
    case FaultReason::kBusOff:
      return "bus-off";
    case FaultReason::kErrorPassive:
      return "error-passive";
    case FaultReason::kControllerRestarted:
      return "controller restarted";
    case FaultReason::kSendError:
      return "send errors";
    case FaultReason::kLoopFrozen:
      return "control loop frozen";
    case FaultReason::kAddressLost:
      return "address lost";
    case FaultReason::kValveFault:
      return "valve fault";
    case FaultReason::kValveReplyLost:
      return "valve reply lost";
    case FaultReason::kDm1Fault:
      return "DM1 fault";
  }
  return "?";
}

using namespace backend_detail;

CanBackend::CanBackend(const CanMapping& mapping, const dynamics::CraneModel& model,
                       Transport& transport, const CanBackendOptions& options)
    : impl_(std::make_unique<Impl>(transport, options)) {
  try {
    check_mapping_fits(mapping, model);
  } catch (const config::ConfigError& e) {
    throw std::invalid_argument(e.what());
  }
  for (int i = 0; i < model.dof(); ++i) {
    const auto s = static_cast<std::size_t>(i);
    const JointMapping& jm = mapping.joints[s];
    Impl::Joint j;
    j.map = jm;
    if (s < model.cylinders.size() && model.cylinders[s].area_a_m2 > 0.0) {
      j.area_ratio = model.cylinders[s].area_b_m2 / model.cylinders[s].area_a_m2;
    }
    const double cycle = jm.valve.kind == ValveOutputKind::kIso11783Avc ? jm.valve.avc.cycle_s
                                                                        : jm.valve.signal.cycle_s;
    j.cycle_us = static_cast<std::int64_t>(std::llround(cycle * 1e6));
    if (!encode_valve_block(jm.valve, j.block_frame)) {
      throw std::invalid_argument(mapping.source + ": joint '" + jm.name +
                                  "': its valve command cannot be encoded");
    }
    impl_->joints.push_back(std::move(j));
  }
  impl_->pump_map = mapping.pump;
  impl_->grapple_map = mapping.grapple;
  if (mapping.heartbeat) {
    impl_->heartbeat = *mapping.heartbeat;
    impl_->heartbeat_cycle_us =
        static_cast<std::int64_t>(std::llround(mapping.heartbeat->cycle_s * 1e6));
  }
  if (mapping.address_claim) {
    // Frames that carry the claimed address as their J1939 source (every AVC command, by the
    // mapping's checks; a 29-bit heartbeat or signal output whose low byte is the address).
    const std::uint8_t address = mapping.address_claim->address;
    const auto from_address = [address](const CanFrame& f) {
      return f.extended && (f.id & 0xFFu) == address;
    };
    impl_->claimer.emplace(address, mapping.address_claim->name, mapping.address_claim->timeout_s);
    impl_->has_claim = true;
    for (auto& j : impl_->joints) j.from_claimed_address = from_address(j.block_frame);
    impl_->heartbeat_from_claimed_address = mapping.heartbeat && mapping.heartbeat->extended &&
                                            (mapping.heartbeat->id & 0xFFu) == address;
  } else {
    impl_->claim_state.store(j1939::ClaimState::kClaimed);
  }
  if (mapping.dm1) {
    for (std::uint8_t a : mapping.dm1->source_addresses) {
      Impl::Dm1Node node;
      node.source_address = a;
      impl_->dm1_nodes.push_back(node);
    }
  }
  if (!options.candump_log.empty()) {
    impl_->log_file = std::fopen(options.candump_log.c_str(), "w");
    if (impl_->log_file == nullptr) {
      throw std::runtime_error("cannot write the CAN log '" + options.candump_log + "'");
    }
  }
  impl_->last_write_us.store(mono_us());
  impl_->watchdog = std::thread([this] { watchdog_loop(); });
  impl_->logger = std::thread([this] { log_loop(); });
}

CanBackend::~CanBackend() {
  stop();
}

void CanBackend::stop() {
  std::lock_guard<std::mutex> lock(impl_->stop_mutex);
  impl_->stop.store(true);
  if (impl_->watchdog.joinable()) impl_->watchdog.join();
  if (impl_->logger.joinable()) impl_->logger.join();
  if (impl_->log_file != nullptr) {
    std::fclose(impl_->log_file);
    impl_->log_file = nullptr;
  }
}

void CanBackend::latch(FaultReason reason, const char* fmt, ...) {
  int expected = kClear;
  if (!fault_.compare_exchange_strong(expected, kLatching, std::memory_order_acq_rel)) return;
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(impl_->reason_text, sizeof impl_->reason_text, fmt, args);
  va_end(args);
  impl_->fault_time_s.store(static_cast<double>(mono_us() - impl_->start_us) * 1e-6);
  reason_.store(reason, std::memory_order_release);
  impl_->counters.faults.fetch_add(1, std::memory_order_relaxed);
  fault_.store(kLatched, std::memory_order_release);
}

bool CanBackend::wait_for_feedback(double timeout_s, valves::MachineState& state) {
  const std::int64_t end = mono_us() + static_cast<std::int64_t>(timeout_s * 1e6);
  for (;;) {
    read(state);
    bool all = true;
    for (const auto& j : impl_->joints) all = all && j.seen;
    if (all) return true;
    const std::int64_t left = end - mono_us();
    if (left <= 0) return false;
    impl_->transport.wait_readable(static_cast<int>(std::min<std::int64_t>(left / 1000 + 1, 10)));
    impl_->last_write_us.store(mono_us(), std::memory_order_release);
  }
}

void CanBackend::enable() {
  // Deliberate: the fault is cleared and the feedback must be fresh again before the next
  // read() reports valid.
  impl_->last_write_us.store(0, std::memory_order_release);  // armed by the next write()
  reason_.store(FaultReason::kNone, std::memory_order_release);
  impl_->reason_text[0] = '\0';
  impl_->fault_time_s.store(NAN);
  impl_->block_sent_after_fault = false;
  impl_->consecutive_send_errors = 0;
  // The valves' replies are judged afresh from here (a fault they still report latches again).
  impl_->supervised_since_us = 0;
  for (auto& j : impl_->joints) j.not_following_since_us = 0;
  fault_.store(kClear, std::memory_order_release);
  enabled_.store(true, std::memory_order_release);
  // Not (or no longer) holding the address: claim it; the valves stay blocked until then.
  if (impl_->claimer && (impl_->claimer->state() == j1939::ClaimState::kIdle ||
                         impl_->claimer->state() == j1939::ClaimState::kLost)) {
    start_claim(mono_us());
  }
}

std::string CanBackend::fault_text() const {
  if (!faulted()) return {};
  return impl_->reason_text;
}

double CanBackend::fault_time_s() const {
  return impl_->fault_time_s.load();
}

CanBackendCounters CanBackend::counters() const {
  const auto& c = impl_->counters;
  CanBackendCounters out;
  out.frames_sent = c.frames_sent.load();
  out.frames_received = c.frames_received.load();
  out.send_queue_full = c.send_queue_full.load();
  out.send_errors = c.send_errors.load();
  out.unknown_frames = c.unknown_frames.load();
  out.bad_frames = c.bad_frames.load();
  out.unsupported_frames = c.unsupported_frames.load();
  out.bus_error_frames = c.bus_error_frames.load();
  out.receive_errors = c.receive_errors.load();
  out.watchdog_block_frames = c.watchdog_block_frames.load();
  out.faults = c.faults.load();
  out.log_dropped = c.log_dropped.load();
  out.heartbeats_sent = c.heartbeats_sent.load();
  out.claim_frames_sent = c.claim_frames_sent.load();
  out.valve_replies = c.valve_replies.load();
  out.dm1_messages = c.dm1_messages.load();
  return out;
}

j1939::ClaimState CanBackend::address_claim_state() const {
  return impl_->claim_state.load(std::memory_order_acquire);
}

valves::BackendStatus CanBackend::read(valves::MachineState& state) {
  Impl& m = *impl_;
  const int n = static_cast<int>(m.joints.size());
  // Frames waiting now arrived since the last read (at most a cycle ago): they are fresh now.
  const std::int64_t taken_us = mono_us();
  for (int k = 0; k < kMaxDrainPerRead; ++k) {
    m.transport.receive(m.rx);
    if (m.rx.kind == ReceiveKind::kNone) break;
    switch (m.rx.kind) {
      case ReceiveKind::kError:
        m.counters.receive_errors.fetch_add(1, std::memory_order_relaxed);
        k = kMaxDrainPerRead;  // stop draining this cycle
        continue;
      case ReceiveKind::kUnsupported:
        m.counters.unsupported_frames.fetch_add(1, std::memory_order_relaxed);
        continue;
      case ReceiveKind::kBusError:
        m.counters.bus_error_frames.fetch_add(1, std::memory_order_relaxed);
        if ((m.rx.bus_error & kBusOff) != 0) {
          latch(FaultReason::kBusOff, "bus-off reported by the CAN controller on %s",
                m.transport.interface_name());
        } else if ((m.rx.bus_error & kControllerRestarted) != 0) {
          // A restart follows a bus-off whose error frame may not have reached us: frames were
          // lost either way, so the valves' state is not known.
          latch(FaultReason::kControllerRestarted,
                "the CAN controller on %s restarted after bus-off", m.transport.interface_name());
        } else if ((m.rx.bus_error & kErrorPassive) != 0) {
          latch(FaultReason::kErrorPassive, "error-passive reported by the CAN controller on %s",
                m.transport.interface_name());
        }
        // Warnings, protocol, ACK and arbitration errors are only counted: the controller
        // retransmits, and errors that persist drive it error-passive, which latches.
        continue;
      default:
        break;
    }
    const CanFrame& f = m.rx.frame;
    m.counters.frames_received.fetch_add(1, std::memory_order_relaxed);
    if (m.log_file != nullptr &&
        !m.control_ring.push(f, m.rx.timestamp_us, CandumpDirection::kRx)) {
      m.counters.log_dropped.fetch_add(1, std::memory_order_relaxed);
    }
    // Network management, valve replies and DM1 (a reply's status may share a frame with
    // feedback signals, so the frame goes on to them as well).
    bool known = on_supervised_frame(f, taken_us);
    for (auto& j : m.joints) {
      auto matches = [&f](const SignalSpec& s) { return s.id == f.id && s.extended == f.extended; };
      double value = 0.0;
      if (matches(j.map.position)) {
        known = true;
        const auto st = decode(j.map.position, f, value);
        if (st != SignalStatus::kOk) {
          m.counters.bad_frames.fetch_add(1, std::memory_order_relaxed);
          latch(FaultReason::kBadFeedbackFrame, "joint %s: position frame %X with dlc %u: %s",
                j.map.name.c_str(), f.id, static_cast<unsigned>(f.dlc), to_string(st));
          continue;
        }
        // The velocity from the kernel's stamps, unless a wall-clock step lies between them.
        const double dt = static_cast<double>(m.rx.timestamp_us - j.last_position_us) * 1e-6;
        if (j.seen && dt > 0.0 && dt < 1.0) {
          const double rate = (value - j.q) / dt;
          const double a = dt / (m.options.velocity_filter_s + dt);
          j.qdot += a * (rate - j.qdot);
        }
        j.q = value;
        j.seen = true;
        j.last_position_us = m.rx.timestamp_us;
        j.last_position_mono_us = taken_us;
      }
      for (int side = 0; side < 2; ++side) {
        const auto& spec = side == 0 ? j.map.pressure_a : j.map.pressure_b;
        if (!spec || !matches(*spec)) continue;
        known = true;
        const auto st = decode(*spec, f, value);
        if (st != SignalStatus::kOk) {
          m.counters.bad_frames.fetch_add(1, std::memory_order_relaxed);
          latch(FaultReason::kBadFeedbackFrame, "joint %s: pressure frame %X with dlc %u: %s",
                j.map.name.c_str(), f.id, static_cast<unsigned>(f.dlc), to_string(st));
          continue;
        }
        (side == 0 ? j.pa : j.pb) = value;
      }
    }
    // The informational signals (pump, swing sensor): a frame that does not decode is counted,
    // not a fault (the measurement goes stale).
    const auto informational = [&](const std::optional<SignalSpec>& spec, double& value,
                                   std::int64_t& last_us) {
      if (!spec || spec->id != f.id || spec->extended != f.extended) return;
      known = true;
      double decoded = 0.0;
      if (decode(*spec, f, decoded) != SignalStatus::kOk) {
        m.counters.bad_frames.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      value = decoded;
      last_us = taken_us;
    };
    informational(m.pump_map.pressure, m.pump_pressure_pa, m.pump_last_us);
    informational(m.pump_map.flow, m.pump_flow_m3_s, m.pump_last_us);
    informational(m.grapple_map.swing_radial, m.swing_rad[0], m.swing_last_us[0]);
    informational(m.grapple_map.swing_tangential, m.swing_rad[1], m.swing_last_us[1]);
    if (!known) m.counters.unknown_frames.fetch_add(1, std::memory_order_relaxed);
  }

  const std::int64_t now = mono_us();
  supervise(now);
  const auto timeout_us = static_cast<std::int64_t>(m.options.feedback_timeout_s * 1e6);
  bool fresh = true;
  state.q.resize(n);
  state.qdot.resize(n);
  state.load_pressure_pa.resize(n);
  state.pressure_a_pa.resize(n);
  state.pressure_b_pa.resize(n);
  state.chamber_pressures = false;
  for (int i = 0; i < n; ++i) {
    auto& j = m.joints[static_cast<std::size_t>(i)];
    const bool stale = !j.seen || now - j.last_position_mono_us > timeout_us;
    if (stale) {
      fresh = false;
      if (enabled() && j.seen) {
        latch(FaultReason::kFeedbackLost, "joint %s: no position frame for %.0f ms",
              j.map.name.c_str(), static_cast<double>(now - j.last_position_mono_us) * 1e-3);
      } else if (enabled()) {
        latch(FaultReason::kFeedbackLost, "joint %s: no position frame yet", j.map.name.c_str());
      }
    }
    state.q[i] = j.q;
    state.qdot[i] = j.qdot;
    state.load_pressure_pa[i] = j.pa - j.pb * j.area_ratio;
    // A chamber the mapping has no signal for is not measured (NaN); the crane scale uses the
    // cylinders whose both chambers are.
    constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();
    state.pressure_a_pa[i] = j.map.pressure_a ? j.pa : kNotMeasured;
    state.pressure_b_pa[i] = j.map.pressure_b ? j.pb : kNotMeasured;
    state.chamber_pressures =
        state.chamber_pressures || (j.map.pressure_a.has_value() && j.map.pressure_b.has_value());
  }
  state.t_s = static_cast<double>(mono_us() - m.start_us) * 1e-6;
  read_pump(state.pump, now, timeout_us);
  // The swing, where the mapping has the sensor and both its angles are fresh; else not measured
  // (NaN: the controller damps on its model, docs/sway.md). Not a fault: the crane moves safely
  // without it.
  constexpr double kNoSwing = std::numeric_limits<double>::quiet_NaN();
  state.swing_rad = state.swing_radial_rad = state.swing_tangential_rad = kNoSwing;
  const auto fresh_swing = [&](int axis) {
    return m.swing_last_us[axis] != 0 && now - m.swing_last_us[axis] <= timeout_us;
  };
  if (fresh_swing(0) && fresh_swing(1)) {
    state.swing_radial_rad = m.swing_rad[0];
    state.swing_tangential_rad = m.swing_rad[1];
    state.swing_rad = dynamics::swing_angle(m.swing_rad[0], m.swing_rad[1]);
  }
  // Until the address is claimed the valves are not commanded: no state to control from.
  state.valid = fresh && !faulted() && m.claimed();
  if (faulted()) return valves::BackendStatus::kFault;
  return state.valid ? valves::BackendStatus::kOk : valves::BackendStatus::kNoData;
}

void CanBackend::read_pump(valves::PumpMeasurement& pump, std::int64_t now_mono_us,
                           std::int64_t timeout_us) {
  // Measured when the mapping has pump signals and they are fresh; unmeasured: zeros.
  Impl& m = *impl_;
  pump = valves::PumpMeasurement{};
  const std::int64_t mono = mono_us();
  const bool fresh = m.pump_last_us != 0 && now_mono_us - m.pump_last_us <= timeout_us;
  if (fresh) {
    pump.pressure_pa = m.pump_pressure_pa;
    pump.flow_m3_s = m.pump_flow_m3_s;
    pump.power_w = m.pump_pressure_pa * m.pump_flow_m3_s;
    if (m.pump_integrated_us != 0) {
      m.pump_energy_j += pump.power_w * static_cast<double>(mono - m.pump_integrated_us) * 1e-6;
    }
  }
  m.pump_integrated_us = mono;
  pump.energy_j = m.pump_energy_j;
}

double CanBackend::command_period_s() const {
  std::int64_t longest_us = 0;
  for (const auto& j : impl_->joints) longest_us = std::max(longest_us, j.cycle_us);
  return static_cast<double>(longest_us) * 1e-6;
}

namespace {

// The time a periodic send counts as sent at: its slot in the schedule (one cycle after the
// previous one) when it went out within half a cycle of it, so that a control loop running a few
// ms late does not push every later send back (with a 20 ms cycle and a 100 Hz loop a send 4 ms
// late would otherwise leave the next one to the cycle after, 26 ms on); else, after a gap, a
// forced send or the first one, the schedule starts again from now.
std::int64_t schedule_slot(std::int64_t last_us, std::int64_t now_us, std::int64_t cycle_us) {
  const std::int64_t nominal = last_us + cycle_us;
  return std::abs(now_us - nominal) <= cycle_us / 2 ? nominal : now_us;
}

}  // namespace

valves::BackendStatus CanBackend::write(const valves::ValveCommand& command) {
  Impl& m = *impl_;
  const std::int64_t now = mono_us();
  m.last_write_us.store(now, std::memory_order_release);
  const bool safe = faulted() || !enabled();
  // The first cycle after a fault sends the block commands at once, whatever the cycle.
  const bool force = faulted() && !m.block_sent_after_fault;
  constexpr std::int64_t kEarlyUs = 3000;  // send up to 3 ms early rather than a period late
  const TimestampUs now_rt = m.log_file != nullptr ? realtime_now_us() : 0;
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    auto& j = m.joints[i];
    if (!m.may_send(j.from_claimed_address)) continue;  // J1939: not from an unclaimed address
    if (!force && now - j.last_sent_us < j.cycle_us - kEarlyUs) continue;
    const double spool = safe || static_cast<Eigen::Index>(i) >= command.spool.size()
                             ? 0.0
                             : command.spool[static_cast<Eigen::Index>(i)];
    const CanFrame* frame = &j.block_frame;
    if (!safe && encode_valve_command(j.map.valve, spool, j.command_frame)) {
      frame = &j.command_frame;
    }
    const SendStatus st = send_counted(m.transport, m.counters, m.control_ring,
                                       m.log_file != nullptr, *frame, now_rt);
    j.last_sent_us = force ? now : schedule_slot(j.last_sent_us, now, j.cycle_us);
    j.note_command(*frame);
    if (st == SendStatus::kOk) {
      m.consecutive_send_errors = 0;
    } else {
      if (++m.consecutive_send_errors >= m.options.max_send_errors && enabled()) {
        latch(FaultReason::kSendError, "%d consecutive sends failed on %s (last: %s)",
              m.consecutive_send_errors, m.transport.interface_name(), to_string(st));
      }
    }
  }
  if (force) m.block_sent_after_fault = true;
  if (m.heartbeat && m.may_send(m.heartbeat_from_claimed_address) &&
      (force || now - m.heartbeat_last_us >= m.heartbeat_cycle_us - kEarlyUs)) {
    const std::int64_t slot =
        force ? now : schedule_slot(m.heartbeat_last_us, now, m.heartbeat_cycle_us);
    send_heartbeat(now, now_rt);
    m.heartbeat_last_us = slot;
  }
  if (faulted()) return valves::BackendStatus::kFault;
  return valves::BackendStatus::kOk;
}

void CanBackend::send_heartbeat(std::int64_t now_us, std::int64_t now_rt_us) {
  Impl& m = *impl_;
  Heartbeat& hb = m.heartbeat_next;
  hb.state = faulted()   ? HeartbeatState::kFault
             : enabled() ? HeartbeatState::kEnabled
                         : HeartbeatState::kDisabled;
  hb.reason = static_cast<std::uint8_t>(fault_reason());
  encode_heartbeat(*m.heartbeat, hb, m.heartbeat_frame);
  m.heartbeat_last_us = now_us;
  if (send_counted(m.transport, m.counters, m.control_ring, m.log_file != nullptr,
                   m.heartbeat_frame, now_rt_us) == SendStatus::kOk) {
    m.counters.heartbeats_sent.fetch_add(1, std::memory_order_relaxed);
  }
  // The next one advances, whether or not this one went out; 255 wraps to 0.
  hb.counter = static_cast<std::uint8_t>(hb.counter + 1);
}

bool CanBackend::activate(double timeout_s, std::string* why) {
  Impl& m = *impl_;
  const std::int64_t end = mono_us() + static_cast<std::int64_t>(timeout_s * 1e6);
  // The claim (J1939-81: 250 ms for a contending claim) runs while the feedback comes in.
  if (m.claimer && m.claimer->state() != j1939::ClaimState::kClaimed &&
      m.claimer->state() != j1939::ClaimState::kClaiming) {
    start_claim(mono_us());
  }
  valves::MachineState state;
  for (;;) {
    read(state);
    if (m.claimer && m.claimer->state() == j1939::ClaimState::kLost) {
      if (why != nullptr) *why = fault_text();  // latched: "cannot claim address 0x80: ..."
      return false;
    }
    bool all = true;
    for (const auto& j : m.joints) all = all && j.seen;
    if (all && m.claimed()) break;
    const std::int64_t left = end - mono_us();
    if (left <= 0) {
      if (why != nullptr) {
        *why = !all ? "no position feedback of every joint within the timeout"
                    : "the J1939 address claim did not complete within the timeout";
      }
      return false;
    }
    m.transport.wait_readable(static_cast<int>(std::min<std::int64_t>(left / 1000 + 1, 10)));
    m.last_write_us.store(mono_us(), std::memory_order_release);
  }
  enable();
  return true;
}

void CanBackend::disable() noexcept {
  // The normal end of a run: every section to block now, and the heartbeat says disabled.
  enabled_.store(false, std::memory_order_release);
  Impl& m = *impl_;
  const std::int64_t now = mono_us();
  const TimestampUs now_rt = m.log_file != nullptr ? realtime_now_us() : 0;
  for (auto& j : m.joints) {
    if (!m.may_send(j.from_claimed_address)) continue;
    send_counted(m.transport, m.counters, m.control_ring, m.log_file != nullptr, j.block_frame,
                 now_rt);
    j.last_sent_us = now;
    j.note_command(j.block_frame);
  }
  if (m.heartbeat && m.may_send(m.heartbeat_from_claimed_address)) send_heartbeat(now, now_rt);
  // No further write() is expected: the watchdog's loop-frozen check is disarmed, but it keeps
  // sending block commands at each cycle until stop().
  m.last_write_us.store(1, std::memory_order_release);
}

void CanBackend::watchdog_loop() {
  Impl& m = *impl_;
  const auto period_ns = static_cast<long>(m.options.watchdog_period_s * 1e9);
  const auto loop_timeout_us = static_cast<std::int64_t>(m.options.loop_timeout_s * 1e6);
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  while (!m.stop.load(std::memory_order_acquire)) {
    next.tv_nsec += period_ns;
    while (next.tv_nsec >= 1000000000L) {
      next.tv_nsec -= 1000000000L;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    const std::int64_t now = mono_us();
    const std::int64_t last_write = m.last_write_us.load(std::memory_order_acquire);
    if (last_write == 0) continue;  // enabled, no write() yet: not armed
    const std::int64_t since_write = now - last_write;
    if (since_write < loop_timeout_us) continue;
    if (enabled() && !faulted()) {
      latch(FaultReason::kLoopFrozen, "control loop frozen: write() not called for %.0f ms",
            static_cast<double>(since_write) * 1e-3);
    }
    // The loop is not writing: the watchdog keeps the valves blocked itself, at each cycle.
    const TimestampUs now_rt = realtime_now_us();
    for (auto& j : m.joints) {
      if (!m.may_send(j.from_claimed_address)) continue;
      if (now - j.watchdog_last_sent_us < j.cycle_us - 2000) continue;
      j.watchdog_last_sent_us = now;
      if (send_counted(m.transport, m.counters, m.watchdog_ring, m.log_file != nullptr,
                       j.block_frame, now_rt) == SendStatus::kOk) {
        m.counters.watchdog_block_frames.fetch_add(1, std::memory_order_relaxed);
      }
    }
  }
}

void CanBackend::log_loop() {
  Impl& m = *impl_;
  char line[kCandumpLineCapacity];
  LogEntry e;
  for (;;) {
    const bool stopping = m.stop.load(std::memory_order_acquire);
    if (m.log_file != nullptr) {
      for (LogRing* ring : {&m.control_ring, &m.watchdog_ring}) {
        while (ring->pop(e)) {
          std::size_t written = 0;
          if (format_candump(e.frame, e.t_us, m.transport.interface_name(), line, written,
                             e.direction) == CandumpStatus::kOk) {
            std::fwrite(line, 1, written, m.log_file);
            std::fputc('\n', m.log_file);
          }
        }
      }
      std::fflush(m.log_file);
    }
    if (stopping) break;
    timespec ts{0, 20000000};
    nanosleep(&ts, nullptr);
  }
}

}  // namespace craneassist::can
