#include "craneassist/can/valve_frames.hpp"

#include <algorithm>
#include <cmath>

namespace craneassist::can {

namespace {
constexpr double kNeutralBand = 1e-6;

bool signal_frame(const SignalSpec& spec, CanFrame& frame) {
  frame = CanFrame{};
  frame.id = spec.id;
  frame.extended = spec.extended;
  frame.dlc = required_dlc(spec);
  return frame.dlc > 0;
}
}  // namespace

double valve_full_scale(const SignalSpec& signal) {
  double full = 0.0;
  if (signal.minimum) full = std::max(full, std::abs(*signal.minimum));
  if (signal.maximum) full = std::max(full, std::abs(*signal.maximum));
  return full > 0.0 ? full : 1.0;
}

bool encode_valve_command(const ValveOutput& valve, double spool, CanFrame& frame) {
  if (!std::isfinite(spool)) spool = 0.0;
  spool = std::clamp(spool, -1.0, 1.0);
  if (valve.kind == ValveOutputKind::kIso11783Avc) {
    iso11783::AuxValveCommand cmd;
    cmd.valve = valve.avc.valve;
    cmd.fail_safe = valve.avc.fail_safe;
    cmd.extended_resolution = valve.avc.extended_resolution;
    if (spool > kNeutralBand) {
      cmd.state = iso11783::ValveState::kExtend;
      cmd.flow = spool;
    } else if (spool < -kNeutralBand) {
      cmd.state = iso11783::ValveState::kRetract;
      cmd.flow = -spool;
    } else {
      cmd.state = iso11783::ValveState::kBlock;
      cmd.flow = 0.0;
    }
    const auto s = iso11783::encode(cmd, valve.avc.source_address, valve.avc.priority, frame);
    return s == iso11783::CodecStatus::kOk || s == iso11783::CodecStatus::kClamped;
  }
  const SignalSpec& spec = valve.signal.signal;
  if (!signal_frame(spec, frame)) return false;
  const auto s = encode(spec, spool * valve_full_scale(spec), frame);
  return s == SignalStatus::kOk || s == SignalStatus::kClamped;
}

bool encode_valve_block(const ValveOutput& valve, CanFrame& frame) {
  return encode_valve_command(valve, 0.0, frame);
}

bool is_valve_frame(const ValveOutput& valve, const CanFrame& frame) {
  if (valve.kind == ValveOutputKind::kIso11783Avc) {
    if (!frame.extended) return false;
    CanFrame expected;
    if (!encode_valve_block(valve, expected)) return false;
    // Same PGN and source address; the priority may differ.
    return (frame.id & 0x03FFFFFFu) == (expected.id & 0x03FFFFFFu);
  }
  return frame.extended == valve.signal.signal.extended && frame.id == valve.signal.signal.id;
}

bool decode_valve_command(const ValveOutput& valve, const CanFrame& frame, double& spool,
                          bool& block) {
  if (valve.kind == ValveOutputKind::kIso11783Avc) {
    iso11783::AuxValveCommand cmd;
    std::uint8_t source = 0;
    if (iso11783::decode(frame, cmd, source) != iso11783::CodecStatus::kOk) return false;
    if (!std::isfinite(cmd.flow)) return false;
    block = false;
    switch (cmd.state) {
      case iso11783::ValveState::kExtend:
        spool = std::clamp(cmd.flow, 0.0, 1.0);
        return true;
      case iso11783::ValveState::kRetract:
        spool = -std::clamp(cmd.flow, 0.0, 1.0);
        return true;
      case iso11783::ValveState::kBlock:
        block = true;
        spool = 0.0;
        return true;
      case iso11783::ValveState::kFloat:
        spool = 0.0;
        return true;
      default:
        return false;
    }
  }
  double value = 0.0;
  const auto s = decode(valve.signal.signal, frame, value);
  if (s != SignalStatus::kOk && s != SignalStatus::kOutOfRange) return false;
  spool = std::clamp(value / valve_full_scale(valve.signal.signal), -1.0, 1.0);
  block = std::abs(spool) <= kNeutralBand;
  return true;
}

}  // namespace craneassist::can
