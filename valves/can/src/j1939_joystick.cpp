#include "craneassist/can/j1939_joystick.hpp"

#include <algorithm>
#include <cmath>

#include "craneassist/can/j1939.hpp"

namespace craneassist::can::j1939_joystick {
namespace {

Switch switch_at(unsigned bits) {
  return static_cast<Switch>(bits & 3u);
}
unsigned bits_of(Switch s) {
  return static_cast<unsigned>(s) & 3u;
}

std::uint16_t le16(const CanFrame& f, int byte) {
  return static_cast<std::uint16_t>(f.data[static_cast<std::size_t>(byte)] |
                                    (f.data[static_cast<std::size_t>(byte) + 1] << 8));
}
// Where button b (0: button 1) sits: byte 6 holds buttons 4..1, byte 7 buttons 8..5, byte 8
// buttons 12..9 (1-based J1939 bytes), each byte's highest pair being the lowest-numbered button
// of its four. The data byte's index and the pair's shift.
struct ButtonSlot {
  std::size_t byte;
  unsigned shift;
};
ButtonSlot button_slot(int b) {
  return {static_cast<std::size_t>(5 + b / 4), 2u * static_cast<unsigned>(3 - b % 4)};
}

void put_le16(CanFrame& f, int byte, std::uint16_t v) {
  f.data[static_cast<std::size_t>(byte)] = static_cast<std::uint8_t>(v & 0xFFu);
  f.data[static_cast<std::size_t>(byte) + 1] = static_cast<std::uint8_t>(v >> 8);
}

}  // namespace

bool joystick_pgn(std::uint32_t pgn, Kind& kind, int& instance) {
  if (pgn < kPgnBjm1 || pgn > kPgnEjm3) return false;
  const std::uint32_t k = pgn - kPgnBjm1;
  kind = (k % 2 == 0) ? Kind::kBasic : Kind::kExtended;
  instance = static_cast<int>(k / 2) + 1;
  return true;
}

std::uint32_t joystick_pgn(Kind kind, int instance) {
  instance = std::clamp(instance, 1, 3);
  return kPgnBjm1 + 2u * static_cast<std::uint32_t>(instance - 1) +
         (kind == Kind::kExtended ? 1u : 0u);
}

Axis decode_axis(std::uint16_t bits) {
  Axis a;
  a.neutral_bit = switch_at(bits);
  a.negative_bit = switch_at(bits >> 2);
  a.positive_bit = switch_at(bits >> 4);
  a.magnitude = static_cast<std::uint16_t>(bits >> 6);
  const Switch fields[] = {a.neutral_bit, a.negative_bit, a.positive_bit};
  const bool any_error = std::any_of(std::begin(fields), std::end(fields),
                                     [](Switch s) { return s == Switch::kError; });
  const bool any_na = std::any_of(std::begin(fields), std::end(fields),
                                  [](Switch s) { return s == Switch::kNotAvailable; });
  if (any_error || (a.magnitude > kMaxMagnitude && a.magnitude != kMagnitudeNotAvailable)) {
    a.status = AxisStatus::kError;
    return a;
  }
  if (any_na || a.magnitude == kMagnitudeNotAvailable) {
    a.status = AxisStatus::kNotAvailable;
    return a;
  }
  const bool neutral = a.neutral_bit == Switch::kOn, negative = a.negative_bit == Switch::kOn,
             positive = a.positive_bit == Switch::kOn;
  const int set = int{neutral} + int{negative} + int{positive};
  if (set != 1 || (neutral && a.magnitude != 0)) {
    a.status = AxisStatus::kContradiction;
    return a;
  }
  a.status = AxisStatus::kOk;
  a.neutral = neutral;
  a.value =
      (negative ? -1.0 : 1.0) * a.magnitude / static_cast<double>(kMaxMagnitude);  // 0 in neutral
  return a;
}

Axis axis_at(double value) {
  Axis a;
  if (!std::isfinite(value)) value = 0.0;
  value = std::clamp(value, -1.0, 1.0);
  a.magnitude = static_cast<std::uint16_t>(std::lround(std::abs(value) * kMaxMagnitude));
  a.status = AxisStatus::kOk;
  a.neutral = a.magnitude == 0;
  a.neutral_bit = a.neutral ? Switch::kOn : Switch::kOff;
  a.negative_bit = !a.neutral && value < 0.0 ? Switch::kOn : Switch::kOff;
  a.positive_bit = !a.neutral && value > 0.0 ? Switch::kOn : Switch::kOff;
  a.value = a.neutral ? 0.0 : std::copysign(a.magnitude / double{kMaxMagnitude}, value);
  return a;
}

std::uint16_t encode_axis(const Axis& axis) {
  const Axis a = axis.status == AxisStatus::kOk ? axis_at(axis.value) : axis;
  return static_cast<std::uint16_t>(bits_of(a.neutral_bit) | (bits_of(a.negative_bit) << 2) |
                                    (bits_of(a.positive_bit) << 4) | ((a.magnitude & 0x3FFu) << 6));
}

DecodeStatus decode(const CanFrame& frame, JoystickMessage& out) {
  if (!frame.extended) return DecodeStatus::kNotJoystick;
  Kind kind = Kind::kBasic;
  int instance = 1;
  if (!joystick_pgn(j1939::pgn(j1939::decompose(frame.id)), kind, instance)) {
    return DecodeStatus::kNotJoystick;
  }
  if (frame.dlc < 8) return DecodeStatus::kShortFrame;
  out = JoystickMessage{};
  out.kind = kind;
  out.instance = instance;
  out.axes[0] = decode_axis(le16(frame, 0));
  out.axes[1] = decode_axis(le16(frame, 2));
  out.buttons.fill(Switch::kNotAvailable);
  if (kind == Kind::kExtended) {
    out.axes[2] = decode_axis(le16(frame, 4));
    return DecodeStatus::kOk;
  }
  out.axes[2] = Axis{};  // a BJM has no third axis
  out.y_detent = switch_at(frame.data[4] >> 4);
  out.x_detent = switch_at(frame.data[4] >> 6);
  for (int b = 0; b < kButtons; ++b) {
    const ButtonSlot slot = button_slot(b);
    out.buttons[static_cast<std::size_t>(b)] = switch_at(frame.data[slot.byte] >> slot.shift);
  }
  return DecodeStatus::kOk;
}

void encode(const JoystickMessage& message, std::uint8_t source, CanFrame& out,
            std::uint8_t priority) {
  out = CanFrame{};
  out.extended = true;
  out.dlc = 8;
  std::uint32_t raw = 0;
  j1939::make_id(priority, joystick_pgn(message.kind, message.instance), source,
                 j1939::kGlobalAddress, raw);
  out.id = raw;
  out.data.fill(0xFF);
  put_le16(out, 0, encode_axis(message.axes[0]));
  put_le16(out, 2, encode_axis(message.axes[1]));
  if (message.kind == Kind::kExtended) {
    put_le16(out, 4, encode_axis(message.axes[2]));
    return;  // detents and byte 8 not sent (all ones: not available)
  }
  out.data[4] = static_cast<std::uint8_t>(0x0Fu | (bits_of(message.y_detent) << 4) |
                                          (bits_of(message.x_detent) << 6));
  for (int byte = 5; byte < 8; ++byte) out.data[static_cast<std::size_t>(byte)] = 0;
  for (int b = 0; b < kButtons; ++b) {
    const ButtonSlot slot = button_slot(b);
    out.data[slot.byte] |= static_cast<std::uint8_t>(
        bits_of(message.buttons[static_cast<std::size_t>(b)]) << slot.shift);
  }
}

const char* to_string(AxisStatus status) {
  switch (status) {
    case AxisStatus::kOk:
      return "ok";
    case AxisStatus::kError:
      return "error";
    case AxisStatus::kNotAvailable:
      return "not available";
    case AxisStatus::kContradiction:
      return "position contradicts its status bits";
  }
  return "?";
}

const char* to_string(DecodeStatus status) {
  switch (status) {
    case DecodeStatus::kOk:
      return "ok";
    case DecodeStatus::kNotJoystick:
      return "not a J1939 joystick message (BJM/EJM)";
    case DecodeStatus::kShortFrame:
      return "fewer than 8 data bytes";
  }
  return "?";
}

}  // namespace craneassist::can::j1939_joystick
