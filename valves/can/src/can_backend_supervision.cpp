// CanBackend: the J1939 address claim, the valves' replies and DM1 (docs/can.md, "Address claim"
// and "Valve supervision"). Control thread: nothing here allocates, blocks or throws.
#include <algorithm>
#include <cstdio>

#include "can_backend_impl.hpp"

namespace craneassist::can {

using namespace backend_detail;

namespace {

// A command at or below this port flow is not checked against the valve's reported state: a
// valve may report block for a flow inside its dead band.
constexpr double kFollowMinFlow = 0.05;

unsigned long long ull(std::uint64_t v) {
  return static_cast<unsigned long long>(v);
}

// "red stop lamp, amber warning lamp" (the lamps on), or "no lamp on".
void lamps_text(const j1939::Dm1& d, char* out, std::size_t size) {
  out[0] = '\0';
  std::size_t used = 0;
  const std::pair<j1939::Lamp, const char*> lamps[] = {{d.red_stop, "red stop lamp"},
                                                       {d.amber_warning, "amber warning lamp"},
                                                       {d.protect, "protect lamp"},
                                                       {d.mil, "malfunction lamp"}};
  for (const auto& [lamp, name] : lamps) {
    if (lamp != j1939::Lamp::kOn || used >= size) continue;
    const int n = std::snprintf(out + used, size - used, "%s%s", used == 0 ? "" : ", ", name);
    if (n > 0) used += static_cast<std::size_t>(n);
  }
  if (used == 0) std::snprintf(out, size, "no lamp on");
}

}  // namespace

void CanBackend::send_network_frame(const CanFrame& frame) {
  Impl& m = *impl_;
  const TimestampUs now_rt = m.log_file != nullptr ? realtime_now_us() : 0;
  if (send_counted(m.transport, m.counters, m.control_ring, m.log_file != nullptr, frame, now_rt) ==
      SendStatus::kOk) {
    m.counters.claim_frames_sent.fetch_add(1, std::memory_order_relaxed);
  }
}

void CanBackend::start_claim(std::int64_t now_us) {
  Impl& m = *impl_;
  m.claimer->start(now_us, m.network_frame);
  m.claim_state.store(m.claimer->state(), std::memory_order_release);
  const SendStatus st = m.transport.send(m.network_frame);
  m.claim_unsent = st != SendStatus::kOk;
  if (st == SendStatus::kOk) {
    // J1939-81's 250 ms count from the claim on the bus, not from before it was sent: the
    // claim's clock starts again once the frame is out (a frame stamped 20 us after now_us made
    // the first command 249.98 ms after the claim under AddressSanitizer).
    m.claimer->start(std::max(now_us, mono_us()), m.network_frame);
    m.counters.frames_sent.fetch_add(1, std::memory_order_relaxed);
    m.counters.claim_frames_sent.fetch_add(1, std::memory_order_relaxed);
    if (m.log_file != nullptr &&
        !m.control_ring.push(m.network_frame, realtime_now_us(), CandumpDirection::kTx)) {
      m.counters.log_dropped.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

bool CanBackend::on_supervised_frame(const CanFrame& f, std::int64_t now) {
  Impl& m = *impl_;
  bool handled = false;

  // Address claim: a contending claim of our address, or a request for address claimed.
  if (m.claimer) {
    const j1939::ClaimState before = m.claimer->state();
    const auto action = m.claimer->on_frame(f, now, m.network_frame);
    if (action != j1939::AddressClaimer::Action::kNone) send_network_frame(m.network_frame);
    if (action == j1939::AddressClaimer::Action::kLost) {
      m.claim_state.store(j1939::ClaimState::kLost, std::memory_order_release);
      if (before == j1939::ClaimState::kClaimed) {
        latch(FaultReason::kAddressLost,
              "address 0x%02X lost: node with NAME 0x%016llX claimed it with priority "
              "(craneassist's NAME 0x%016llX); nothing more is sent from it",
              m.claimer->address(), ull(m.claimer->rival_name()), ull(m.claimer->name()));
      } else {
        latch(FaultReason::kAddressLost,
              "cannot claim address 0x%02X: node with NAME 0x%016llX has priority "
              "(craneassist's NAME 0x%016llX)",
              m.claimer->address(), ull(m.claimer->rival_name()), ull(m.claimer->name()));
      }
    }
    if (f.extended) {
      const std::uint32_t p = j1939::pgn(j1939::decompose(f.id));
      handled = p == j1939::kPgnAddressClaimed || p == j1939::kPgnRequest;
    }
  }

  for (auto& j : m.joints) {
    if (!j.map.reply) continue;
    const ValveReply& reply = *j.map.reply;
    if (j.map.valve.kind == ValveOutputKind::kIso11783Avc) {
      // Auxiliary Valve Estimated Flow of this valve from the valve's address.
      if (!f.extended) continue;
      const j1939::Identifier id = j1939::decompose(f.id);
      if (id.source_address != reply.source_address ||
          j1939::pgn(id) != iso11783::kPgnAuxValveEstimatedFlow0 + j.map.valve.avc.valve) {
        continue;
      }
      handled = true;
      iso11783::AuxValveEstimatedFlow ef;
      std::uint8_t source = 0;
      const auto st = iso11783::decode(f, ef, source);
      if (st != iso11783::CodecStatus::kOk) {
        m.counters.bad_frames.fetch_add(1, std::memory_order_relaxed);
        latch(FaultReason::kBadFeedbackFrame, "joint %s: valve reply frame %X with dlc %u: %s",
              j.map.name.c_str(), f.id, static_cast<unsigned>(f.dlc), iso11783::to_string(st));
        continue;
      }
      m.counters.valve_replies.fetch_add(1, std::memory_order_relaxed);
      j.reply_mono_us = now;
      j.reply_state = ef.state;
      j.reply_limit = ef.limit;
      j.reply_fault = ef.state == iso11783::ValveState::kError ? ReplyFault::kErrorState
                      : ef.limit == iso11783::LimitStatus::kNonRecoverableFault
                          ? ReplyFault::kNonRecoverable
                          : ReplyFault::kNone;
      // Does the valve follow the command? It echoes the commanded state; float is never
      // commanded, so a valve in float is in its fail-safe; block (or the other direction)
      // while craneassist commands a clear flow means its commands are not taking effect.
      const bool moving = (j.commanded_state == iso11783::ValveState::kExtend ||
                           j.commanded_state == iso11783::ValveState::kRetract) &&
                          j.commanded_flow >= kFollowMinFlow;
      const bool known_state = ef.state == iso11783::ValveState::kBlock ||
                               ef.state == iso11783::ValveState::kExtend ||
                               ef.state == iso11783::ValveState::kRetract;
      const bool differs = ef.state == iso11783::ValveState::kFloat ||
                           (moving && known_state && ef.state != j.commanded_state);
      if (!differs) {
        j.not_following_since_us = 0;
      } else if (j.not_following_since_us == 0) {
        j.not_following_since_us = now;
      }
    } else {
      // The signal valve driver's status signal.
      if (f.id != reply.status.id || f.extended != reply.status.extended) continue;
      handled = true;
      std::uint64_t raw = 0;
      if (f.dlc < required_dlc(reply.status) || !extract_raw(reply.status, f, raw)) {
        m.counters.bad_frames.fetch_add(1, std::memory_order_relaxed);
        latch(FaultReason::kBadFeedbackFrame, "joint %s: valve status frame %X with dlc %u: %s",
              j.map.name.c_str(), f.id, static_cast<unsigned>(f.dlc),
              to_string(SignalStatus::kShortFrame));
        continue;
      }
      m.counters.valve_replies.fetch_add(1, std::memory_order_relaxed);
      j.reply_mono_us = now;
      j.reply_status = raw;
      const bool ok =
          std::find(reply.ok_values.begin(), reply.ok_values.end(), raw) != reply.ok_values.end();
      j.reply_fault = ok ? ReplyFault::kNone : ReplyFault::kStatus;
    }
  }

  if (!m.dm1_nodes.empty() && f.extended) {
    const j1939::Identifier id = j1939::decompose(f.id);
    const std::uint32_t p = j1939::pgn(id);
    for (auto& node : m.dm1_nodes) {
      if (node.source_address != id.source_address) continue;
      if (p == j1939::kPgnDm1) {
        handled = true;
        j1939::Dm1 d;
        std::uint8_t source = 0;
        if (j1939::decode_dm1(f, d, source) != j1939::Dm1Status::kOk) {
          m.counters.bad_frames.fetch_add(1, std::memory_order_relaxed);
          latch(FaultReason::kBadFeedbackFrame,
                "DM1 from 0x%02X with dlc %u: too short for the lamps and a DTC",
                node.source_address, static_cast<unsigned>(f.dlc));
          continue;
        }
        m.counters.dm1_messages.fetch_add(1, std::memory_order_relaxed);
        node.last = d;
        node.multi_packet_bytes = 0;
        node.stop = j1939::dm1_requires_stop(d);
      } else if (p == j1939::kPgnTpCm) {
        std::uint8_t source = 0;
        std::uint16_t size = 0;
        if (!j1939::decode_dm1_announcement(f, source, size)) continue;
        handled = true;
        // More than one frame's worth: two or more active DTCs, each a stop by the rule.
        m.counters.dm1_messages.fetch_add(1, std::memory_order_relaxed);
        node.multi_packet_bytes = size;
        node.stop = size > 8;
      } else if (p == j1939::kPgnTpDt) {
        handled = true;  // TP.DT packets of the node's transfers: not reassembled
      }
    }
  }
  return handled;
}

void CanBackend::supervise(std::int64_t now) {
  Impl& m = *impl_;
  if (m.claimer) {
    if (m.claim_unsent && m.claimer->state() == j1939::ClaimState::kClaiming) start_claim(now);
    if (m.claimer->poll(now, m.network_frame) == j1939::AddressClaimer::Action::kSend) {
      send_network_frame(m.network_frame);
    }
    m.claim_state.store(m.claimer->state(), std::memory_order_release);
  }
  // The valves are judged while craneassist commands them: enabled, with its address.
  if (!enabled() || faulted() || !m.claimed()) return;
  if (m.supervised_since_us == 0) m.supervised_since_us = now;

  for (auto& j : m.joints) {
    if (!j.map.reply) continue;
    const ValveReply& reply = *j.map.reply;
    const auto timeout_us = static_cast<std::int64_t>(reply.timeout_s * 1e6);
    const bool avc = j.map.valve.kind == ValveOutputKind::kIso11783Avc;
    const unsigned valve = j.map.valve.avc.valve;
    const unsigned source = reply.source_address;
    switch (j.reply_fault) {
      case ReplyFault::kErrorState:
        latch(FaultReason::kValveFault, "joint %s: valve %u (0x%02X) reports error state",
              j.map.name.c_str(), valve, source);
        return;
      case ReplyFault::kNonRecoverable:
        latch(FaultReason::kValveFault,
              "joint %s: valve %u (0x%02X) reports a non-recoverable fault (limit status 6, "
              "state %s)",
              j.map.name.c_str(), valve, source, iso11783::to_string(j.reply_state));
        return;
      case ReplyFault::kStatus:
        latch(FaultReason::kValveFault,
              "joint %s: valve driver reports status %llu in frame %X (not an ok value)",
              j.map.name.c_str(), ull(j.reply_status), reply.status.id);
        return;
      case ReplyFault::kNone:
        break;
    }
    if (avc && j.not_following_since_us != 0 && now - j.not_following_since_us > timeout_us) {
      latch(FaultReason::kValveFault,
            "joint %s: valve %u (0x%02X) reports fail-safe: state %s for %.0f ms while commanded "
            "%s",
            j.map.name.c_str(), valve, source, iso11783::to_string(j.reply_state),
            static_cast<double>(now - j.not_following_since_us) * 1e-3,
            iso11783::to_string(j.commanded_state));
      return;
    }
    // Silence, timed from the newer of the last reply and the start of supervision.
    if (now - std::max(j.reply_mono_us, m.supervised_since_us) > timeout_us) {
      if (j.reply_mono_us == 0) {
        latch(FaultReason::kValveReplyLost, "joint %s: no valve reply within %.0f ms of enable",
              j.map.name.c_str(), reply.timeout_s * 1e3);
      } else {
        latch(FaultReason::kValveReplyLost, "joint %s: no valve reply for %.0f ms",
              j.map.name.c_str(), static_cast<double>(now - j.reply_mono_us) * 1e-3);
      }
      return;
    }
  }

  for (const auto& node : m.dm1_nodes) {
    if (!node.stop) continue;
    if (node.multi_packet_bytes > 0) {
      latch(FaultReason::kDm1Fault,
            "DM1 from 0x%02X: %d active DTCs (multi-packet DM1, its DTCs not decoded)",
            node.source_address, std::max(2, (node.multi_packet_bytes - 2) / 4));
      return;
    }
    char lamps[96];
    lamps_text(node.last, lamps, sizeof lamps);
    if (j1939::has_active_dtc(node.last)) {
      latch(FaultReason::kDm1Fault, "DM1 from 0x%02X: SPN %u FMI %u (%s)", node.source_address,
            static_cast<unsigned>(node.last.spn), static_cast<unsigned>(node.last.fmi), lamps);
    } else {
      latch(FaultReason::kDm1Fault, "DM1 from 0x%02X: red stop lamp on, no DTC",
            node.source_address);
    }
    return;
  }
}

}  // namespace craneassist::can
