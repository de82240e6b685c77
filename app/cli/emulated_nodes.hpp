// The machine's J1939 nodes in `craneassist emulate` (docs/can.md): the valves that answer
// their commands with Auxiliary Valve Estimated Flow (from each `valve.reply` source address),
// a signal valve's driver with its status signal, DM1 once a second from each node of
// `diagnostics.dm1`, those nodes' address claims (at start and on request), and hooks that
// inject the faults craneassist must catch: a valve fault, the replies stopping, a DM1 with an
// active DTC. Nothing here runs unless the mapping asks for replies or DM1.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "craneassist/can/mapping_config.hpp"
#include "craneassist/can/transport.hpp"
#include "craneassist/dynamics/model.hpp"

namespace craneassist::cli {

// Test hooks (hidden options of `emulate`): times in s since the emulator started, < 0 off.
struct EmulatedFaults {
  double valve_fault_at_s = -1.0;  // the valve reports limit status 6 and holds its fail-safe
  std::string valve_fault_joint;   // which joint's valve ("": the first with a reply)
  double reply_stop_at_s = -1.0;   // every valve reply stops
  double dm1_fault_at_s = -1.0;    // the first DM1 node reports SPN 1234 FMI 5, red stop lamp
};

class EmulatedNodes {
 public:
  // Throws std::invalid_argument when a hook needs what the mapping does not have.
  EmulatedNodes(const can::CanMapping& mapping, const EmulatedFaults& faults);

  // A received frame: true when it was J1939 network management (a request for address claimed
  // is answered for the emulated nodes; claims of other nodes are reported).
  bool on_frame(const can::CanFrame& frame, double t_s, can::Transport& bus);
  // Sends what is due at t_s: the nodes' claims at start, the replies every 50 ms from the
  // applied spools, DM1 every second.
  void tick(double t_s, const dynamics::JointVector& applied_spool, can::Transport& bus);
  // The joint's valve has failed (the valve-fault hook): it holds its fail-safe, no flow.
  bool failed(int joint, double t_s) const;

  std::uint64_t frames_sent() const { return sent_; }
  std::uint64_t send_failures() const { return send_failed_; }
  bool active() const { return !nodes_.empty() || !signal_replies_.empty(); }

 private:
  struct Node {
    std::uint8_t address = 0;
    std::uint64_t name = 0;
    bool dm1 = false;
  };
  struct AvcReply {
    int joint = 0;
    std::uint8_t valve = 0;
    std::uint8_t source = 0;
    bool fail_safe_float = false;
  };
  struct SignalReply {
    int joint = 0;
    const can::SignalSpec* status = nullptr;
    std::uint64_t ok = 0, not_ok = 0;
  };
  void send(const can::CanFrame& frame, can::Transport& bus);
  void claim(const Node& node, can::Transport& bus);

  EmulatedFaults faults_;
  int fault_joint_ = -1;
  std::vector<Node> nodes_;
  std::vector<AvcReply> avc_replies_;
  std::vector<SignalReply> signal_replies_;
  bool claimed_ = false;
  bool fault_announced_[3] = {};
  double next_reply_s_ = 0.0, next_dm1_s_ = 0.0;
  std::uint64_t sent_ = 0, send_failed_ = 0;
};

}  // namespace craneassist::cli
