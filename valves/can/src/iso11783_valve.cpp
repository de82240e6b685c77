#include "craneassist/can/iso11783_valve.hpp"

#include <cmath>
#include <limits>

#include "craneassist/can/j1939.hpp"

namespace craneassist::can::iso11783 {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint32_t kMaxValid8 = 250;      // J1939-71: 0xFB..0xFF are special
constexpr std::uint32_t kMaxValid16 = 0xFAFF;  // J1939-71: 0xFB00..0xFFFF are special
constexpr std::uint32_t kFullFlow16 = 64000;   // the 16-bit port flow's 100 %

// Raw value of a scaled field, rounded to nearest and clamped to [0, max_raw].
std::uint32_t to_raw(double value, double per_bit, double offset, std::uint32_t max_raw,
                     bool& clamped) {
  const double r = std::round((value - offset) / per_bit);
  if (r < 0.0) {
    clamped = true;
    return 0;
  }
  if (r > static_cast<double>(max_raw)) {
    clamped = true;
    return max_raw;
  }
  return static_cast<std::uint32_t>(r);
}

// A J1939 field: NaN is sent as not available (all ones).
std::uint32_t to_raw_or_na(double value, double per_bit, double offset, std::uint32_t max_raw,
                           std::uint32_t not_available, bool& clamped) {
  if (std::isnan(value)) return not_available;
  return to_raw(value, per_bit, offset, max_raw, clamped);
}

double from_raw8(std::uint8_t raw, double per_bit, double offset) {
  return raw <= kMaxValid8 ? raw * per_bit + offset : kNaN;
}

double from_raw16(std::uint32_t raw, double per_bit, double offset) {
  return raw <= kMaxValid16 ? raw * per_bit + offset : kNaN;
}

std::uint32_t le16(const CanFrame& f, std::size_t i) {
  return static_cast<std::uint32_t>(f.data[i]) | (static_cast<std::uint32_t>(f.data[i + 1]) << 8);
}

void put_le16(CanFrame& f, std::size_t i, std::uint32_t v) {
  f.data[i] = static_cast<std::uint8_t>(v & 0xFFu);
  f.data[i + 1] = static_cast<std::uint8_t>((v >> 8) & 0xFFu);
}

bool finite_or_nan(double v) {
  return std::isfinite(v) || std::isnan(v);
}

// Identifier of PGN base + valve; false if priority or valve is out of range.
bool make_frame(std::uint32_t pgn_base, std::uint8_t valve, std::uint8_t source,
                std::uint8_t priority, CanFrame& frame) {
  if (valve >= kAuxValveCount) return false;
  std::uint32_t raw = 0;
  if (j1939::make_id(priority, pgn_base + valve, source, j1939::kGlobalAddress, raw) !=
      j1939::IdStatus::kOk) {
    return false;
  }
  frame.id = raw;
  frame.extended = true;
  frame.dlc = 8;
  frame.data.fill(0xFF);
  return true;
}

// Checks the identifier and length of a frame of PGNs base..base+15; valve and source out (set
// only when the frame is one).
CodecStatus check_frame(const CanFrame& frame, std::uint32_t pgn_base, std::uint8_t& valve,
                        std::uint8_t& source) {
  if (!frame.extended || frame.id > kMaxExtendedId) return CodecStatus::kWrongIdentifier;
  const j1939::Identifier id = j1939::decompose(frame.id);
  const std::uint32_t p = j1939::pgn(id);
  if (p < pgn_base || p >= pgn_base + kAuxValveCount) return CodecStatus::kWrongIdentifier;
  if (frame.dlc != 8) return CodecStatus::kBadLength;
  valve = static_cast<std::uint8_t>(p - pgn_base);
  source = id.source_address;
  return CodecStatus::kOk;
}

bool valid_state_code(std::uint8_t code) {
  return code <= 3 || code >= 14;
}

// Bytes 0 and 1 of the measured and the estimated flow messages: the extend and the retract
// port's flow, 1 %/bit from -125 %.
constexpr double kPortFlowPerBit = 0.01;
constexpr double kPortFlowOffset = -1.25;

void put_port_flows(double extend_flow, double retract_flow, CanFrame& out, bool& clamped) {
  out.data[0] = static_cast<std::uint8_t>(
      to_raw_or_na(extend_flow, kPortFlowPerBit, kPortFlowOffset, kMaxValid8, 0xFF, clamped));
  out.data[1] = static_cast<std::uint8_t>(
      to_raw_or_na(retract_flow, kPortFlowPerBit, kPortFlowOffset, kMaxValid8, 0xFF, clamped));
}

void get_port_flows(const CanFrame& frame, double& extend_flow, double& retract_flow) {
  extend_flow = from_raw8(frame.data[0], kPortFlowPerBit, kPortFlowOffset);
  retract_flow = from_raw8(frame.data[1], kPortFlowPerBit, kPortFlowOffset);
}

// The limit status in the top 3 bits of a byte, the rest not available.
std::uint8_t limit_byte(LimitStatus limit) {
  return static_cast<std::uint8_t>((static_cast<std::uint8_t>(limit) << 5) | 0x1F);
}

LimitStatus limit_of(std::uint8_t byte) {
  return static_cast<LimitStatus>((byte >> 5) & 0x7u);
}

}  // namespace

const char* to_string(ValveState state) {
  switch (state) {
    case ValveState::kBlock:
      return "block";
    case ValveState::kExtend:
      return "extend";
    case ValveState::kRetract:
      return "retract";
    case ValveState::kFloat:
      return "float";
    case ValveState::kError:
      return "error";
    case ValveState::kNotAvailable:
      return "not available";
  }
  return "reserved";
}

const char* to_string(FailSafeMode mode) {
  switch (mode) {
    case FailSafeMode::kBlock:
      return "block";
    case FailSafeMode::kFloat:
      return "float";
    case FailSafeMode::kReserved:
      return "reserved";
    case FailSafeMode::kDontCare:
      return "don't care";
  }
  return "reserved";
}

const char* to_string(CodecStatus status) {
  switch (status) {
    case CodecStatus::kOk:
      return "ok";
    case CodecStatus::kClamped:
      return "value clamped to its range";
    case CodecStatus::kInvalidArgument:
      return "invalid argument";
    case CodecStatus::kWrongIdentifier:
      return "wrong identifier";
    case CodecStatus::kBadLength:
      return "wrong data length";
    case CodecStatus::kBadField:
      return "a field holds an error, not-available or reserved code";
  }
  return "unknown";
}

CodecStatus encode(const AuxValveCommand& command, std::uint8_t source_address,
                   std::uint8_t priority, CanFrame& frame) {
  const auto state = static_cast<std::uint8_t>(command.state);
  const auto fail_safe = static_cast<std::uint8_t>(command.fail_safe);
  if (!std::isfinite(command.flow) || !(state <= 3 || state == 15) || fail_safe == 2 ||
      fail_safe > 3) {
    return CodecStatus::kInvalidArgument;
  }
  CanFrame out;
  if (!make_frame(kPgnAuxValveCommand0, command.valve, source_address, priority, out)) {
    return CodecStatus::kInvalidArgument;
  }
  bool clamped = false;
  out.data[0] =
      static_cast<std::uint8_t>(to_raw(command.flow, kStandardFlowPerBit, 0.0, 250, clamped));
  const std::uint8_t resolution_mode = command.extended_resolution ? 0x1 : 0x0;
  out.data[1] = static_cast<std::uint8_t>(0xFC | resolution_mode);
  out.data[2] = static_cast<std::uint8_t>((fail_safe << 6) | 0x30 | state);
  if (command.extended_resolution) {
    put_le16(out, 3, to_raw(command.flow, kExtendedFlowPerBit, 0.0, 64000, clamped));
  }
  frame = out;
  return clamped ? CodecStatus::kClamped : CodecStatus::kOk;
}

CodecStatus decode(const CanFrame& frame, AuxValveCommand& command, std::uint8_t& source_address) {
  const CodecStatus s = check_frame(frame, kPgnAuxValveCommand0, command.valve, source_address);
  if (s != CodecStatus::kOk) return s;
  const std::uint8_t resolution_mode = frame.data[1] & 0x3u;
  const std::uint32_t extended = le16(frame, 3);
  command.extended_resolution = resolution_mode == 0x1 && extended <= kMaxValid16;
  // 64001..0xFAFF are valid J1939 values but beyond the parameter's 100 %: a bad field, like
  // 251..255 of the 8-bit one.
  command.flow = !command.extended_resolution ? from_raw8(frame.data[0], kStandardFlowPerBit, 0.0)
                 : extended <= kFullFlow16    ? extended * kExtendedFlowPerBit
                                              : kNaN;
  const std::uint8_t state = frame.data[2] & 0x0Fu;
  command.state = static_cast<ValveState>(state);
  command.fail_safe = static_cast<FailSafeMode>((frame.data[2] >> 6) & 0x3u);
  if (std::isnan(command.flow) || !valid_state_code(state)) return CodecStatus::kBadField;
  return CodecStatus::kOk;
}

CodecStatus encode(const AuxValveMeasuredFlow& m, std::uint8_t source_address,
                   std::uint8_t priority, CanFrame& frame) {
  for (double v : {m.extend_flow, m.retract_flow, m.extend_pressure_pa, m.retract_pressure_pa,
                   m.return_pressure_pa}) {
    if (!finite_or_nan(v)) return CodecStatus::kInvalidArgument;
  }
  if (static_cast<std::uint8_t>(m.limit) > 7) return CodecStatus::kInvalidArgument;
  CanFrame out;
  if (!make_frame(kPgnAuxValveMeasuredFlow0, m.valve, source_address, priority, out)) {
    return CodecStatus::kInvalidArgument;
  }
  bool clamped = false;
  put_port_flows(m.extend_flow, m.retract_flow, out, clamped);
  put_le16(out, 2, to_raw_or_na(m.extend_pressure_pa, 5000.0, 0.0, kMaxValid16, 0xFFFF, clamped));
  put_le16(out, 4, to_raw_or_na(m.retract_pressure_pa, 5000.0, 0.0, kMaxValid16, 0xFFFF, clamped));
  out.data[6] = static_cast<std::uint8_t>(
      to_raw_or_na(m.return_pressure_pa, 16000.0, 0.0, kMaxValid8, 0xFF, clamped));
  out.data[7] = limit_byte(m.limit);
  frame = out;
  return clamped ? CodecStatus::kClamped : CodecStatus::kOk;
}

CodecStatus decode(const CanFrame& frame, AuxValveMeasuredFlow& m, std::uint8_t& source_address) {
  const CodecStatus s = check_frame(frame, kPgnAuxValveMeasuredFlow0, m.valve, source_address);
  if (s != CodecStatus::kOk) return s;
  get_port_flows(frame, m.extend_flow, m.retract_flow);
  m.extend_pressure_pa = from_raw16(le16(frame, 2), 5000.0, 0.0);
  m.retract_pressure_pa = from_raw16(le16(frame, 4), 5000.0, 0.0);
  m.return_pressure_pa = from_raw8(frame.data[6], 16000.0, 0.0);
  m.limit = limit_of(frame.data[7]);
  return CodecStatus::kOk;
}

CodecStatus encode(const AuxValveEstimatedFlow& m, std::uint8_t source_address,
                   std::uint8_t priority, CanFrame& frame) {
  const auto state = static_cast<std::uint8_t>(m.state);
  const auto fail_safe = static_cast<std::uint8_t>(m.fail_safe);
  if (!finite_or_nan(m.extend_flow) || !finite_or_nan(m.retract_flow) || !valid_state_code(state) ||
      state > 15 || fail_safe > 3 || static_cast<std::uint8_t>(m.limit) > 7) {
    return CodecStatus::kInvalidArgument;
  }
  CanFrame out;
  if (!make_frame(kPgnAuxValveEstimatedFlow0, m.valve, source_address, priority, out)) {
    return CodecStatus::kInvalidArgument;
  }
  bool clamped = false;
  put_port_flows(m.extend_flow, m.retract_flow, out, clamped);
  out.data[2] = static_cast<std::uint8_t>((fail_safe << 6) | 0x30 | state);
  out.data[3] = limit_byte(m.limit);
  frame = out;
  return clamped ? CodecStatus::kClamped : CodecStatus::kOk;
}

CodecStatus decode(const CanFrame& frame, AuxValveEstimatedFlow& m, std::uint8_t& source_address) {
  const CodecStatus s = check_frame(frame, kPgnAuxValveEstimatedFlow0, m.valve, source_address);
  if (s != CodecStatus::kOk) return s;
  get_port_flows(frame, m.extend_flow, m.retract_flow);
  const std::uint8_t state = frame.data[2] & 0x0Fu;
  m.state = static_cast<ValveState>(state);
  m.fail_safe = static_cast<FailSafeMode>((frame.data[2] >> 6) & 0x3u);
  m.limit = limit_of(frame.data[3]);
  return valid_state_code(state) ? CodecStatus::kOk : CodecStatus::kBadField;
}

}  // namespace craneassist::can::iso11783
