// SAE J1939-71 joystick messages: the Basic Joystick Message (BJM1-3, PGN 64982/64984/64986) and
// the Extended Joystick Message (EJM1-3, PGN 64983/64985/64987), as an armrest's CAN joysticks
// send them (PDU2 broadcasts, priority 3, 8 bytes, "100 ms or on change, not faster than 20 ms";
// Danfoss JS6000 and Walvoil every 20 ms, Danfoss JS1-H 50 ms).
//
// Sources (the standard itself was not available; ../shared/design/references-2026-12.md): the
// J1939-71 BJM1 layout as quoted on the Enovation forum, Danfoss JS6000 technical information
// pp. 23-26, Akron 6032 p. 29, Danfoss JS1-H manual pp. 12-13, malachi-iot/j1939 bjm1.hpp.
//
// One axis is 16 bits, little endian, bits counted from the lowest (LSB0):
//   bits 0-1   neutral position status       00 off, 01 on, 10 error, 11 not available
//   bits 2-3   negative position status      (X: left, Y: back)
//   bits 4-5   positive position status      (X: right, Y: forward)
//   bits 6-15  position magnitude, 0.1 %/bit, 0..1000 = 0..100 %; 1022 error, 1023 not available
// BJM: X in bytes 1-2, Y in bytes 3-4 (1-based J1939 byte numbers); byte 5 bits 1-4 the vendor's,
// bits 5-6 the Y detent, 7-8 the X detent; bytes 6-8 twelve buttons, 2 bits each, with the same
// four states: byte 6 buttons 4, 3, 2, 1 from its lowest bits up, byte 7 buttons 8..5, byte 8
// buttons 12..9.
// EJM: grip X in bytes 1-2, grip Y in bytes 3-4, theta (the grip's twist) in bytes 5-6, detents in
// byte 7 (their layout not confirmed: not decoded), byte 8 reserved; no buttons.
//
// What a receiver must not take for a position (the decoder says which): an error or
// not-available magnitude or status, a magnitude above 1000, and a position that contradicts its
// status bits: the neutral bit with a non-zero magnitude or with a direction bit, both directions
// at once, or no bit at all. Decoding neither allocates nor throws.
#pragma once

#include <array>
#include <cstdint>

#include "craneassist/can/can_frame.hpp"

namespace craneassist::can::j1939_joystick {

inline constexpr std::uint32_t kPgnBjm1 = 64982;  // 0xFDD6
inline constexpr std::uint32_t kPgnEjm1 = 64983;
inline constexpr std::uint32_t kPgnBjm2 = 64984;
inline constexpr std::uint32_t kPgnEjm2 = 64985;
inline constexpr std::uint32_t kPgnBjm3 = 64986;
inline constexpr std::uint32_t kPgnEjm3 = 64987;
inline constexpr std::uint8_t kDefaultPriority = 3;
inline constexpr std::uint16_t kMaxMagnitude = 1000;  // 100.0 %
inline constexpr std::uint16_t kMagnitudeError = 1022;
inline constexpr std::uint16_t kMagnitudeNotAvailable = 1023;
inline constexpr int kButtons = 12;

// A 2-bit state (a status bit of an axis, a detent, a button).
enum class Switch : std::uint8_t { kOff = 0, kOn = 1, kError = 2, kNotAvailable = 3 };

enum class AxisStatus : std::uint8_t {
  kOk,            // value is the stick's position
  kError,         // the stick reports an error (a field at "error", a magnitude of 1001..1022)
  kNotAvailable,  // the stick has no such axis or cannot say (a field at "not available")
  kContradiction  // the magnitude and the status bits disagree
};

struct Axis {
  double value = 0.0;  // -1..1 (positive: right, forward, clockwise), 0 unless status is kOk
  AxisStatus status = AxisStatus::kNotAvailable;
  bool neutral = false;  // the stick says it is in its neutral position (status kOk)
  // The raw fields, for diagnostics and the encoder.
  Switch neutral_bit = Switch::kNotAvailable, negative_bit = Switch::kNotAvailable,
         positive_bit = Switch::kNotAvailable;
  std::uint16_t magnitude = kMagnitudeNotAvailable;
};

enum class Kind : std::uint8_t { kBasic, kExtended };

struct JoystickMessage {
  Kind kind = Kind::kBasic;
  int instance = 1;            // 1..3: BJM1/EJM1 .. BJM3/EJM3
  std::array<Axis, 3> axes{};  // BJM: X, Y (the third not available); EJM: X, Y, theta
  Switch x_detent = Switch::kNotAvailable, y_detent = Switch::kNotAvailable;  // BJM only
  std::array<Switch, kButtons> buttons{};  // buttons[0] is button 1; BJM only (else not available)
};

enum class DecodeStatus : std::uint8_t {
  kOk,
  kNotJoystick,  // not a BJM/EJM PGN, or an 11-bit identifier
  kShortFrame,   // fewer than 8 data bytes
};

// The kind and instance of a joystick PGN; false for any other PGN.
bool joystick_pgn(std::uint32_t pgn, Kind& kind, int& instance);
// The PGN of a kind and instance (1..3).
std::uint32_t joystick_pgn(Kind kind, int instance);

// One axis from its 16 bits (the layout above).
Axis decode_axis(std::uint16_t bits);
// The 16 bits of an axis: from value (clamped to -1..1; neutral at 0) when status is kOk, else
// the fields as they are in `axis` (to send errors and contradictions in tests and emulators).
std::uint16_t encode_axis(const Axis& axis);
// An axis at a position, with its status bits set as the standard says.
Axis axis_at(double value);

// Decodes a BJM or EJM frame (its source address and priority are the caller's to check).
DecodeStatus decode(const CanFrame& frame, JoystickMessage& out);
// The frame of a message from source address `source`.
void encode(const JoystickMessage& message, std::uint8_t source, CanFrame& out,
            std::uint8_t priority = kDefaultPriority);

const char* to_string(AxisStatus status);
const char* to_string(DecodeStatus status);

}  // namespace craneassist::can::j1939_joystick
