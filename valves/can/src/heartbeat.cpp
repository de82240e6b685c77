#include "craneassist/can/heartbeat.hpp"

namespace craneassist::can {

void encode_heartbeat(const HeartbeatSpec& spec, const Heartbeat& hb, CanFrame& frame) {
  frame.id = spec.id;
  frame.extended = spec.extended;
  frame.dlc = 8;
  frame.data.fill(0xFF);
  frame.data[0] = hb.counter;
  frame.data[1] = static_cast<std::uint8_t>(hb.state);
  frame.data[2] = hb.reason;
}

bool is_heartbeat_frame(const HeartbeatSpec& spec, const CanFrame& frame) {
  return frame.id == spec.id && frame.extended == spec.extended;
}

bool decode_heartbeat(const HeartbeatSpec& spec, const CanFrame& frame, Heartbeat& hb) {
  if (!is_heartbeat_frame(spec, frame) || frame.dlc < 3) return false;
  if (frame.data[1] > static_cast<std::uint8_t>(HeartbeatState::kFault)) return false;
  hb.counter = frame.data[0];
  hb.state = static_cast<HeartbeatState>(frame.data[1]);
  hb.reason = frame.data[2];
  return true;
}

bool HeartbeatMonitor::on_frame(const CanFrame& frame, double t_s) {
  if (!is_heartbeat_frame(spec_, frame)) return false;
  Heartbeat hb;
  if (!decode_heartbeat(spec_, frame, hb)) {
    ++malformed_;
    return true;
  }
  ++messages_;
  const bool advanced = have_last_ && hb.counter == static_cast<std::uint8_t>(last_.counter + 1);
  if (have_last_ && !advanced) ++sequence_errors_;
  last_ = hb;
  have_last_ = true;
  if (advanced && hb.state == HeartbeatState::kEnabled) {
    refreshed_s_ = t_s;
  } else if (hb.state != HeartbeatState::kEnabled) {
    refreshed_s_ = -1e300;  // the sender says: do not move
  }
  return true;
}

bool HeartbeatMonitor::alive(double t_s) {
  const bool now_alive = t_s - refreshed_s_ <= spec_.timeout_s;
  if (was_alive_ && !now_alive) ++losses_;
  was_alive_ = now_alive;
  return now_alive;
}

}  // namespace craneassist::can
