#include "emulated_nodes.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/dm1.hpp"
#include "craneassist/can/iso11783_valve.hpp"

namespace craneassist::cli {

namespace {

constexpr double kReplyPeriodS = 0.05;  // Estimated Flow and driver status
constexpr double kDm1PeriodS = 1.0;     // J1939-73: DM1 once a second (and on change)
constexpr std::uint8_t kReplyPriority = 3;

void note(double t_s, const char* what) {
  std::printf("craneassist emulate: %.3f s: %s\n", t_s, what);
  std::fflush(stdout);
}

}  // namespace

EmulatedNodes::EmulatedNodes(const can::CanMapping& mapping, const EmulatedFaults& faults)
    : faults_(faults) {
  auto add_node = [this](std::uint8_t address, bool dm1) {
    for (auto& n : nodes_) {
      if (n.address == address) {
        n.dm1 = n.dm1 || dm1;
        return;
      }
    }
    // An illustrative NAME per node (the valve group's, not a real product's).
    can::j1939::Name name;
    name.identity_number = 0x10000u | address;
    name.function = 129;
    name.industry_group = 3;
    nodes_.push_back({address, can::j1939::pack_name(name), dm1});
  };
  for (std::size_t i = 0; i < mapping.joints.size(); ++i) {
    const auto& jm = mapping.joints[i];
    if (!jm.reply) continue;
    const int joint = static_cast<int>(i);
    if (jm.valve.kind == can::ValveOutputKind::kIso11783Avc) {
      avc_replies_.push_back({joint, jm.valve.avc.valve, jm.reply->source_address,
                              jm.valve.avc.fail_safe == can::iso11783::FailSafeMode::kFloat});
      add_node(jm.reply->source_address, false);
    } else {
      SignalReply r{joint, &jm.reply->status, jm.reply->ok_values.front(), 0};
      while (std::find(jm.reply->ok_values.begin(), jm.reply->ok_values.end(), r.not_ok) !=
             jm.reply->ok_values.end()) {
        ++r.not_ok;
      }
      signal_replies_.push_back(r);
    }
    if (fault_joint_ < 0 &&
        (faults.valve_fault_joint.empty() || faults.valve_fault_joint == jm.name)) {
      fault_joint_ = joint;
    }
  }
  if (mapping.dm1) {
    for (std::uint8_t a : mapping.dm1->source_addresses) add_node(a, true);
  }
  if (faults.valve_fault_at_s >= 0.0 && fault_joint_ < 0) {
    throw std::invalid_argument("--test-valve-fault-at: " +
                                (faults.valve_fault_joint.empty()
                                     ? std::string("no joint")
                                     : "joint '" + faults.valve_fault_joint + "' has no") +
                                " valve.reply in the mapping " + mapping.source);
  }
  if (faults.reply_stop_at_s >= 0.0 && avc_replies_.empty() && signal_replies_.empty()) {
    throw std::invalid_argument("--test-reply-stop-at: no joint has a valve.reply in the mapping " +
                                mapping.source);
  }
  if (faults.dm1_fault_at_s >= 0.0 && !mapping.dm1) {
    throw std::invalid_argument("--test-dm1-fault-at: the mapping " + mapping.source +
                                " has no diagnostics.dm1");
  }
}

void EmulatedNodes::send(const can::CanFrame& frame, can::Transport& bus) {
  if (bus.send(frame) == can::SendStatus::kOk) {
    ++sent_;
  } else {
    ++send_failed_;
  }
}

void EmulatedNodes::claim(const Node& node, can::Transport& bus) {
  can::CanFrame f;
  can::j1939::encode_address_claimed(node.name, node.address, f);
  send(f, bus);
}

bool EmulatedNodes::on_frame(const can::CanFrame& frame, double t_s, can::Transport& bus) {
  std::uint64_t name = 0;
  std::uint8_t source = 0;
  if (can::j1939::decode_address_claimed(frame, name, source)) {
    char text[128];
    if (source == can::j1939::kNullAddress) {
      std::snprintf(text, sizeof text, "Cannot Claim Address from NAME 0x%016llX",
                    static_cast<unsigned long long>(name));
    } else {
      std::snprintf(text, sizeof text, "address 0x%02X claimed by NAME 0x%016llX",
                    static_cast<unsigned>(source), static_cast<unsigned long long>(name));
    }
    note(t_s, text);
    return true;
  }
  std::uint32_t requested = 0;
  std::uint8_t destination = 0;
  if (can::j1939::decode_request(frame, requested, destination)) {
    if (requested == can::j1939::kPgnAddressClaimed) {
      for (const auto& n : nodes_) {
        if (destination == can::j1939::kGlobalAddress || destination == n.address) claim(n, bus);
      }
    }
    return true;
  }
  return false;
}

bool EmulatedNodes::failed(int joint, double t_s) const {
  return joint == fault_joint_ && faults_.valve_fault_at_s >= 0.0 &&
         t_s >= faults_.valve_fault_at_s;
}

void EmulatedNodes::tick(double t_s, const dynamics::JointVector& spool, can::Transport& bus) {
  if (!claimed_) {
    claimed_ = true;
    for (const auto& n : nodes_) claim(n, bus);
  }
  const bool valve_fault = faults_.valve_fault_at_s >= 0.0 && t_s >= faults_.valve_fault_at_s;
  const bool replies_stopped = faults_.reply_stop_at_s >= 0.0 && t_s >= faults_.reply_stop_at_s;
  const bool dm1_fault = faults_.dm1_fault_at_s >= 0.0 && t_s >= faults_.dm1_fault_at_s;
  const bool flags[3] = {valve_fault, replies_stopped, dm1_fault};
  const char* what[3] = {"test hook: the valve fails (limit status 6, its fail-safe)",
                         "test hook: every valve reply stops",
                         "test hook: DM1 with an active DTC (SPN 1234 FMI 5, red stop lamp)"};
  for (int k = 0; k < 3; ++k) {
    if (flags[k] && !fault_announced_[k]) {
      fault_announced_[k] = true;
      note(t_s, what[k]);
      if (k == 2) next_dm1_s_ = t_s;  // a DM1 goes out on change, not a second later
    }
  }

  if (t_s >= next_reply_s_ && !replies_stopped) {
    next_reply_s_ = std::max(next_reply_s_ + kReplyPeriodS, t_s);
    for (const auto& r : avc_replies_) {
      // The estimated flow of the spool the valve applied: into the extend port and back out of
      // the retract port when extending, the other way round when retracting.
      const double s = spool[r.joint];
      can::iso11783::AuxValveEstimatedFlow ef;
      ef.valve = r.valve;
      ef.fail_safe = r.fail_safe_float ? can::iso11783::FailSafeMode::kFloat
                                       : can::iso11783::FailSafeMode::kBlock;
      ef.limit = can::iso11783::LimitStatus::kNotLimited;
      ef.state = s > 1e-6    ? can::iso11783::ValveState::kExtend
                 : s < -1e-6 ? can::iso11783::ValveState::kRetract
                             : can::iso11783::ValveState::kBlock;
      ef.extend_flow = s;
      ef.retract_flow = -s;
      if (valve_fault && r.joint == fault_joint_) {
        ef.state = r.fail_safe_float ? can::iso11783::ValveState::kFloat
                                     : can::iso11783::ValveState::kBlock;
        ef.extend_flow = ef.retract_flow = 0.0;
        ef.limit = can::iso11783::LimitStatus::kNonRecoverableFault;
      }
      can::CanFrame f;
      if (can::iso11783::encode(ef, r.source, kReplyPriority, f) !=
          can::iso11783::CodecStatus::kInvalidArgument) {
        send(f, bus);
      }
    }
    for (const auto& r : signal_replies_) {
      can::CanFrame f;
      f.id = r.status->id;
      f.extended = r.status->extended;
      f.dlc = can::required_dlc(*r.status);
      can::insert_raw(*r.status, valve_fault && r.joint == fault_joint_ ? r.not_ok : r.ok, f);
      send(f, bus);
    }
  }

  if (t_s >= next_dm1_s_) {
    next_dm1_s_ = std::max(next_dm1_s_ + kDm1PeriodS, t_s);
    bool first = true;
    for (const auto& n : nodes_) {
      if (!n.dm1) continue;
      can::j1939::Dm1 d;  // lamps off, no active DTC
      if (dm1_fault && first) {
        d.red_stop = can::j1939::Lamp::kOn;
        d.spn = 1234;
        d.fmi = 5;
        d.occurrence_count = 1;
      }
      first = false;
      can::CanFrame f;
      can::j1939::encode_dm1(d, n.address, f);
      send(f, bus);
    }
  }
}

}  // namespace craneassist::cli
