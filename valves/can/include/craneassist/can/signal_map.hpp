// DBC-style signals: a value at a bit position of a CAN frame, with scale and offset.
//
// Bit numbering is DBC's: bit k is bit (k % 8) of data byte k / 8, bit 0 the least significant.
//  - Intel (little endian, DBC "@1"): start_bit is the least significant bit; the signal runs
//    upwards through the bytes.
//  - Motorola (big endian, DBC "@0"): start_bit is the most significant bit; the signal runs
//    towards bit 0 of that byte, then continues at bit 7 of the next byte (the "sawtooth").
// physical = raw * scale + offset (raw is two's complement when is_signed).
//
// The mapping config converts units as it loads a spec, so scale and offset here already give SI
// values (rad, m, Pa, A); `unit` keeps the unit as the file wrote it, for messages.
//
// Encode rules: a non-finite value writes nothing (kInvalidValue). A value outside
// [minimum, maximum] (when given) is clamped to it, then raw = round((value - offset) / scale)
// to nearest, halves away from zero (cantools uses Python's round, which rounds halves to even:
// the two differ only on exact ties), then clamped to what length bits hold; either clamp
// returns kClamped with the frame written. Decode reports kOutOfRange with the value filled in
// when it lies outside [minimum, maximum]. Neither allocates nor throws.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "craneassist/can/can_frame.hpp"

namespace craneassist::can {

enum class ByteOrder : std::uint8_t { kLittleEndian, kBigEndian };  // Intel, Motorola

struct SignalSpec {
  std::uint32_t id = 0;
  bool extended = false;
  std::uint16_t start_bit = 0;  // 0..63, DBC convention (see above)
  std::uint16_t length = 1;     // 1..64 bits
  ByteOrder byte_order = ByteOrder::kLittleEndian;
  bool is_signed = false;
  double scale = 1.0;
  double offset = 0.0;
  std::optional<double> minimum;
  std::optional<double> maximum;
  std::string unit;      // as written in the source file; scale/offset are already SI
  double unit_si = 1.0;  // the SI value of one `unit` (1 deg = 0.01745 rad), to write it back
};

enum class SignalStatus {
  kOk,
  kClamped,          // encode: clamped to [minimum, maximum] or to the raw range; written
  kOutOfRange,       // decode: outside [minimum, maximum]; the value is still returned
  kInvalidValue,     // encode: NaN or infinite
  kInvalidSpec,      // the spec fails validate()
  kWrongIdentifier,  // the frame's identifier or format differs from the spec's
  kShortFrame,       // the frame's dlc does not cover the signal
};
const char* to_string(SignalStatus status);

enum class SpecError {
  kNone,
  kBadLength,      // not 1..64
  kBadStartBit,    // above 63
  kDoesNotFit,     // runs past byte 8
  kBadIdentifier,  // above 11 bits (standard) or 29 bits (extended)
  kBadScale,       // zero or not finite
  kBadOffset,      // not finite
  kBadRange,       // minimum above maximum, or not finite
};
const char* to_string(SpecError error);

SpecError validate(const SignalSpec& spec);

// The smallest dlc whose bytes hold the signal (1..8), or 0 if the spec is invalid.
std::uint8_t required_dlc(const SignalSpec& spec);

// Raw access, no scaling: the bits as an unsigned number (for signed signals, the two's
// complement bit pattern zero-extended to 64 bits). Preconditions: validate(spec) == kNone and
// the frame covers the signal; the functions return false (doing nothing) otherwise.
bool extract_raw(const SignalSpec& spec, const CanFrame& frame, std::uint64_t& raw);
bool insert_raw(const SignalSpec& spec, std::uint64_t raw, CanFrame& frame);
// Sign-extended value of the raw bits (for unsigned signals just the raw value, which must fit).
std::int64_t sign_extend(std::uint64_t raw, std::uint16_t length);

SignalStatus decode(const SignalSpec& spec, const CanFrame& frame, double& value);
// Writes the signal's bits into frame.data, leaving the other bits as they are (several signals
// share a frame). The frame must already carry the spec's identifier and a dlc covering it.
SignalStatus encode(const SignalSpec& spec, double value, CanFrame& frame);

}  // namespace craneassist::can
