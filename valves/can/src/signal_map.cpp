#include "craneassist/can/signal_map.hpp"

#include <cmath>

namespace craneassist::can {
namespace {

// Position p = 0..63 of the i-th bit (i = 0 the least significant) in DBC bit numbering.
// Intel: start + i. Motorola: the MSB sits at start; counted in "big-endian linear" order
// (L = byte * 8 + 7 - bit), the signal occupies L_msb .. L_msb + length - 1.
struct Layout {
  int first_linear = 0;  // Motorola: linear index of the MSB; Intel: the start bit
  int last = 0;          // highest byte index touched
};

bool layout(const SignalSpec& spec, Layout& out) {
  if (spec.length < 1 || spec.length > 64 || spec.start_bit > 63) return false;
  if (spec.byte_order == ByteOrder::kLittleEndian) {
    const int end = spec.start_bit + spec.length - 1;
    if (end > 63) return false;
    out.first_linear = spec.start_bit;
    out.last = end / 8;
  } else {
    const int msb_linear = (spec.start_bit / 8) * 8 + (7 - spec.start_bit % 8);
    const int lsb_linear = msb_linear + spec.length - 1;
    if (lsb_linear > 63) return false;
    out.first_linear = msb_linear;
    out.last = lsb_linear / 8;
  }
  return true;
}

// Bit position (DBC numbering) of bit i (0 = LSB) of the signal.
int bit_position(const SignalSpec& spec, const Layout& l, int i) {
  if (spec.byte_order == ByteOrder::kLittleEndian) return l.first_linear + i;
  const int linear = l.first_linear + (spec.length - 1 - i);
  return (linear / 8) * 8 + (7 - linear % 8);
}

bool covers(const Layout& l, const CanFrame& frame) {
  return l.last < frame.dlc;
}

std::uint64_t mask(std::uint16_t length) {
  return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1;
}

constexpr double kTwo64 = 18446744073709551616.0;  // 2^64

}  // namespace

const char* to_string(SignalStatus status) {
  switch (status) {
    case SignalStatus::kOk:
      return "ok";
    case SignalStatus::kClamped:
      return "value clamped";
    case SignalStatus::kOutOfRange:
      return "value outside the signal's range";
    case SignalStatus::kInvalidValue:
      return "value not finite";
    case SignalStatus::kInvalidSpec:
      return "invalid signal spec";
    case SignalStatus::kWrongIdentifier:
      return "frame identifier differs from the signal's";
    case SignalStatus::kShortFrame:
      return "frame too short for the signal";
  }
  return "unknown";
}

const char* to_string(SpecError error) {
  switch (error) {
    case SpecError::kNone:
      return "ok";
    case SpecError::kBadLength:
      return "length must be 1..64 bits";
    case SpecError::kBadStartBit:
      return "start bit must be 0..63";
    case SpecError::kDoesNotFit:
      return "the signal runs past the 8th data byte";
    case SpecError::kBadIdentifier:
      return "identifier out of range (11 bits standard, 29 bits extended)";
    case SpecError::kBadScale:
      return "scale must be finite and nonzero";
    case SpecError::kBadOffset:
      return "offset must be finite";
    case SpecError::kBadRange:
      return "minimum must be at most maximum, both finite";
  }
  return "unknown";
}

SpecError validate(const SignalSpec& spec) {
  if (spec.length < 1 || spec.length > 64) return SpecError::kBadLength;
  if (spec.start_bit > 63) return SpecError::kBadStartBit;
  Layout l;
  if (!layout(spec, l)) return SpecError::kDoesNotFit;
  if (spec.id > (spec.extended ? kMaxExtendedId : kMaxStandardId)) {
    return SpecError::kBadIdentifier;
  }
  if (!std::isfinite(spec.scale) || spec.scale == 0.0) return SpecError::kBadScale;
  if (!std::isfinite(spec.offset)) return SpecError::kBadOffset;
  if ((spec.minimum && !std::isfinite(*spec.minimum)) ||
      (spec.maximum && !std::isfinite(*spec.maximum)) ||
      (spec.minimum && spec.maximum && *spec.minimum > *spec.maximum)) {
    return SpecError::kBadRange;
  }
  return SpecError::kNone;
}

std::uint8_t required_dlc(const SignalSpec& spec) {
  Layout l;
  if (validate(spec) != SpecError::kNone || !layout(spec, l)) return 0;
  return static_cast<std::uint8_t>(l.last + 1);
}

bool extract_raw(const SignalSpec& spec, const CanFrame& frame, std::uint64_t& raw) {
  Layout l;
  if (validate(spec) != SpecError::kNone || !layout(spec, l) || !covers(l, frame)) return false;
  std::uint64_t r = 0;
  for (int i = 0; i < spec.length; ++i) {
    const int p = bit_position(spec, l, i);
    const std::uint64_t bit = (frame.data[static_cast<std::size_t>(p / 8)] >> (p % 8)) & 1u;
    r |= bit << i;
  }
  raw = r;
  return true;
}

bool insert_raw(const SignalSpec& spec, std::uint64_t raw, CanFrame& frame) {
  Layout l;
  if (validate(spec) != SpecError::kNone || !layout(spec, l) || !covers(l, frame)) return false;
  for (int i = 0; i < spec.length; ++i) {
    const int p = bit_position(spec, l, i);
    auto& byte = frame.data[static_cast<std::size_t>(p / 8)];
    const auto bit = static_cast<std::uint8_t>(1u << (p % 8));
    if ((raw >> i) & 1u) {
      byte = static_cast<std::uint8_t>(byte | bit);
    } else {
      byte = static_cast<std::uint8_t>(byte & ~bit);
    }
  }
  return true;
}

std::int64_t sign_extend(std::uint64_t raw, std::uint16_t length) {
  if (length >= 64) return static_cast<std::int64_t>(raw);
  raw &= mask(length);
  const std::uint64_t sign = std::uint64_t{1} << (length - 1);
  if (raw & sign) raw |= ~mask(length);
  return static_cast<std::int64_t>(raw);
}

SignalStatus decode(const SignalSpec& spec, const CanFrame& frame, double& value) {
  if (validate(spec) != SpecError::kNone) return SignalStatus::kInvalidSpec;
  if (frame.id != spec.id || frame.extended != spec.extended) {
    return SignalStatus::kWrongIdentifier;
  }
  std::uint64_t raw = 0;
  if (!extract_raw(spec, frame, raw)) return SignalStatus::kShortFrame;
  const double r = spec.is_signed ? static_cast<double>(sign_extend(raw, spec.length))
                                  : static_cast<double>(raw);
  value = r * spec.scale + spec.offset;
  if ((spec.minimum && value < *spec.minimum) || (spec.maximum && value > *spec.maximum)) {
    return SignalStatus::kOutOfRange;
  }
  return SignalStatus::kOk;
}

SignalStatus encode(const SignalSpec& spec, double value, CanFrame& frame) {
  if (validate(spec) != SpecError::kNone) return SignalStatus::kInvalidSpec;
  if (!std::isfinite(value)) return SignalStatus::kInvalidValue;
  if (frame.id != spec.id || frame.extended != spec.extended) {
    return SignalStatus::kWrongIdentifier;
  }
  if (required_dlc(spec) > frame.dlc) return SignalStatus::kShortFrame;

  bool clamped = false;
  if (spec.minimum && value < *spec.minimum) {
    value = *spec.minimum;
    clamped = true;
  }
  if (spec.maximum && value > *spec.maximum) {
    value = *spec.maximum;
    clamped = true;
  }
  const double r = std::round((value - spec.offset) / spec.scale);

  std::uint64_t raw = 0;
  if (spec.is_signed) {
    // Representable: -2^(n-1) .. 2^(n-1) - 1.
    const double lo = -std::ldexp(1.0, spec.length - 1);
    const double hi_excl = std::ldexp(1.0, spec.length - 1);
    std::int64_t v = 0;
    if (r < lo) {
      clamped = true;
      v = spec.length >= 64 ? INT64_MIN : -(std::int64_t{1} << (spec.length - 1));
    } else if (r >= hi_excl) {
      clamped = true;
      v = spec.length >= 64 ? INT64_MAX : (std::int64_t{1} << (spec.length - 1)) - 1;
    } else {
      v = static_cast<std::int64_t>(r);  // |r| < 2^63 here
    }
    raw = static_cast<std::uint64_t>(v) & mask(spec.length);
  } else {
    const double hi_excl = spec.length >= 64 ? kTwo64 : std::ldexp(1.0, spec.length);
    if (r < 0.0) {
      clamped = true;
      raw = 0;
    } else if (r >= hi_excl) {
      clamped = true;
      raw = mask(spec.length);
    } else {
      raw = static_cast<std::uint64_t>(r);
    }
  }
  insert_raw(spec, raw, frame);
  return clamped ? SignalStatus::kClamped : SignalStatus::kOk;
}

}  // namespace craneassist::can
