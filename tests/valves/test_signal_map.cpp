// DBC-style signals: cantools' motohawk.dbc vectors (from cantools' own test suite), hand-computed
// Intel and Motorola layouts (crossing bytes, 64 bits, signed), encode rules, no allocation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "allocation_counter.hpp"
#include "craneassist/can/signal_map.hpp"

using namespace craneassist::can;

namespace {

SignalSpec spec(std::uint16_t start, std::uint16_t length, ByteOrder order, bool is_signed,
                double scale = 1.0, double offset = 0.0) {
  SignalSpec s;
  s.id = 0x1F0;
  s.start_bit = start;
  s.length = length;
  s.byte_order = order;
  s.is_signed = is_signed;
  s.scale = scale;
  s.offset = offset;
  return s;
}

CanFrame empty_frame(std::uint32_t id = 0x1F0, std::uint8_t dlc = 8) {
  CanFrame f;
  f.id = id;
  f.dlc = dlc;
  return f;
}

CanFrame bytes(std::array<std::uint8_t, 8> d) {
  CanFrame f = empty_frame();
  f.data = d;
  return f;
}

constexpr auto kIntel = ByteOrder::kLittleEndian;
constexpr auto kMotorola = ByteOrder::kBigEndian;

// motohawk.dbc (cantools tests/files/dbc/motohawk.dbc), message ExampleMessage 0x1F0:
//   SG_ Enable : 7|1@0+ (1,0) [0|0] "-"
//   SG_ AverageRadius : 6|6@0+ (0.1,0) [0|5] "m"
//   SG_ Temperature : 0|12@0- (0.01,250) [229.52|270.47] "degK"
SignalSpec enable() {
  return spec(7, 1, kMotorola, false);
}
SignalSpec average_radius() {
  SignalSpec s = spec(6, 6, kMotorola, false, 0.1, 0.0);
  s.minimum = 0.0;
  s.maximum = 5.0;
  return s;
}
SignalSpec temperature() {
  SignalSpec s = spec(0, 12, kMotorola, true, 0.01, 250.0);
  s.minimum = 229.52;
  s.maximum = 270.47;
  return s;
}

void expect_data(const CanFrame& f, std::array<std::uint8_t, 8> expected) {
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], expected[i]) << "byte " << i;
}

// raw inserted into an empty frame gives the bytes `expected`, and extracted from them, raw.
void expect_round_trip(const SignalSpec& s, std::uint64_t raw,
                       std::array<std::uint8_t, 8> expected) {
  CanFrame f = empty_frame();
  ASSERT_TRUE(insert_raw(s, raw, f));
  expect_data(f, expected);
  std::uint64_t back = 0;
  ASSERT_TRUE(extract_raw(s, f, back));
  EXPECT_EQ(back, raw);
}

}  // namespace

TEST(SignalMap, CantoolsMotohawkEncode) {
  // cantools: {Temperature 250.55, AverageRadius 3.2, Enable 1} <-> c0 06 e0 00 00 00 00 00
  CanFrame f = empty_frame();
  EXPECT_EQ(encode(temperature(), 250.55, f), SignalStatus::kOk);
  EXPECT_EQ(encode(average_radius(), 3.2, f), SignalStatus::kOk);
  EXPECT_EQ(encode(enable(), 1.0, f), SignalStatus::kOk);
  expect_data(f, {0xC0, 0x06, 0xE0, 0, 0, 0, 0, 0});

  // cantools: {229.53, 0, 0} <-> 01 00 20 00 ... (the temperature raw value is negative)
  CanFrame g = empty_frame();
  EXPECT_EQ(encode(temperature(), 229.53, g), SignalStatus::kOk);
  EXPECT_EQ(encode(average_radius(), 0.0, g), SignalStatus::kOk);
  EXPECT_EQ(encode(enable(), 0.0, g), SignalStatus::kOk);
  expect_data(g, {0x01, 0x00, 0x20, 0, 0, 0, 0, 0});
}

TEST(SignalMap, CantoolsMotohawkDecode) {
  double v = 0.0;
  const CanFrame f = bytes({0xC0, 0x06, 0xE0, 0, 0, 0, 0, 0});
  ASSERT_EQ(decode(temperature(), f, v), SignalStatus::kOk);
  EXPECT_NEAR(v, 250.55, 1e-9);
  ASSERT_EQ(decode(average_radius(), f, v), SignalStatus::kOk);
  EXPECT_NEAR(v, 3.2, 1e-12);
  ASSERT_EQ(decode(enable(), f, v), SignalStatus::kOk);
  EXPECT_EQ(v, 1.0);

  const CanFrame g = bytes({0x01, 0x00, 0x20, 0, 0, 0, 0, 0});
  ASSERT_EQ(decode(temperature(), g, v), SignalStatus::kOk);
  EXPECT_NEAR(v, 229.53, 1e-9);

  // cantools, unscaled: {Temperature 3, AverageRadius 2, Enable 1} <-> 84 00 60 00 ...
  const CanFrame h = bytes({0x84, 0x00, 0x60, 0, 0, 0, 0, 0});
  std::uint64_t raw = 0;
  ASSERT_TRUE(extract_raw(temperature(), h, raw));
  EXPECT_EQ(raw, 3u);
  ASSERT_TRUE(extract_raw(average_radius(), h, raw));
  EXPECT_EQ(raw, 2u);
  ASSERT_TRUE(extract_raw(enable(), h, raw));
  EXPECT_EQ(raw, 1u);
}

TEST(SignalMap, IntelLayouts) {
  // 16 bits at 0: 0x1234 -> 34 12.
  expect_round_trip(spec(0, 16, kIntel, false), 0x1234, {0x34, 0x12, 0, 0, 0, 0, 0, 0});
  // 12 bits at 4: 0xABC -> byte 0 high nibble C, byte 1 AB; byte 0 low nibble untouched.
  CanFrame f = bytes({0x05, 0, 0, 0, 0, 0, 0, 0});
  ASSERT_TRUE(insert_raw(spec(4, 12, kIntel, false), 0xABC, f));
  expect_data(f, {0xC5, 0xAB, 0, 0, 0, 0, 0, 0});
  // 20 bits at 13, across three bytes: 0xABCDE << 13 = 0x1579BC000 -> 00 C0 9B 57 01.
  expect_round_trip(spec(13, 20, kIntel, false), 0xABCDE, {0x00, 0xC0, 0x9B, 0x57, 0x01, 0, 0, 0});
}

TEST(SignalMap, MotorolaLayouts) {
  // 16 bits, start (MSB) 7: 0x1234 -> 12 34.
  expect_round_trip(spec(7, 16, kMotorola, false), 0x1234, {0x12, 0x34, 0, 0, 0, 0, 0, 0});
  // 12 bits, start 3: bits 3..0 of byte 0 hold A, byte 1 holds BC.
  expect_round_trip(spec(3, 12, kMotorola, false), 0xABC, {0x0A, 0xBC, 0, 0, 0, 0, 0, 0});
  // 20 bits, start 13 (byte 1 bit 5), across three bytes:
  // 1010 1011 1100 1101 1110 -> byte 1 bits 5..0 = 101010 (0x2A), byte 2 = 11110011 (0xF3),
  // byte 3 bits 7..2 = 011110 (0x78).
  expect_round_trip(spec(13, 20, kMotorola, false), 0xABCDE, {0x00, 0x2A, 0xF3, 0x78, 0, 0, 0, 0});
  // Ending exactly at byte 7 bit 0: start 55 (byte 6 bit 7), 16 bits.
  expect_round_trip(spec(55, 16, kMotorola, false), 0xBEEF, {0, 0, 0, 0, 0, 0, 0xBE, 0xEF});
  EXPECT_EQ(required_dlc(spec(55, 16, kMotorola, false)), 8);
  EXPECT_EQ(required_dlc(spec(7, 16, kMotorola, false)), 2);
  EXPECT_EQ(required_dlc(spec(13, 20, kMotorola, false)), 4);
}

TEST(SignalMap, SixtyFourBitSignals) {
  const SignalSpec intel = spec(0, 64, kIntel, false);
  const SignalSpec moto = spec(7, 64, kMotorola, false);
  CanFrame f = empty_frame();
  ASSERT_TRUE(insert_raw(intel, 0x0123456789ABCDEFull, f));
  expect_data(f, {0xEF, 0xCD, 0xAB, 0x89, 0x67, 0x45, 0x23, 0x01});
  f = empty_frame();
  ASSERT_TRUE(insert_raw(moto, 0x0123456789ABCDEFull, f));
  expect_data(f, {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF});
  std::uint64_t raw = 0;
  ASSERT_TRUE(extract_raw(moto, f, raw));
  EXPECT_EQ(raw, 0x0123456789ABCDEFull);

  // Signed 64-bit: -2 is FE FF .. FF (Intel).
  const SignalSpec s64 = spec(0, 64, kIntel, true);
  f = empty_frame();
  ASSERT_EQ(encode(s64, -2.0, f), SignalStatus::kOk);
  expect_data(f, {0xFE, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF});
  double v = 0.0;
  ASSERT_EQ(decode(s64, f, v), SignalStatus::kOk);
  EXPECT_EQ(v, -2.0);
  // Saturation at the 64-bit limits, without undefined behaviour.
  EXPECT_EQ(encode(s64, 1e30, f), SignalStatus::kClamped);
  ASSERT_TRUE(extract_raw(s64, f, raw));
  EXPECT_EQ(raw, 0x7FFFFFFFFFFFFFFFull);
  EXPECT_EQ(encode(s64, -1e30, f), SignalStatus::kClamped);
  ASSERT_TRUE(extract_raw(s64, f, raw));
  EXPECT_EQ(raw, 0x8000000000000000ull);
  EXPECT_EQ(encode(intel, 1e30, f), SignalStatus::kClamped);
  ASSERT_TRUE(extract_raw(intel, f, raw));
  EXPECT_EQ(raw, ~0ull);
  EXPECT_EQ(encode(intel, 4096.0, f), SignalStatus::kOk);
  ASSERT_TRUE(extract_raw(intel, f, raw));
  EXPECT_EQ(raw, 4096u);
}

TEST(SignalMap, SignedValues) {
  // Intel 8 bits at 8, scale 0.5: -1.5 -> raw -3 -> FD in byte 1.
  const SignalSpec s = spec(8, 8, kIntel, true, 0.5);
  CanFrame f = empty_frame();
  ASSERT_EQ(encode(s, -1.5, f), SignalStatus::kOk);
  expect_data(f, {0, 0xFD, 0, 0, 0, 0, 0, 0});
  double v = 0.0;
  ASSERT_EQ(decode(s, f, v), SignalStatus::kOk);
  EXPECT_EQ(v, -1.5);
  // Motorola 10 bits at 1: -1 -> all ones: byte 0 bits 1..0, byte 1 bits 7..0.
  const SignalSpec m = spec(1, 10, kMotorola, true);
  f = empty_frame();
  ASSERT_EQ(encode(m, -1.0, f), SignalStatus::kOk);
  expect_data(f, {0x03, 0xFF, 0, 0, 0, 0, 0, 0});
  ASSERT_EQ(decode(m, f, v), SignalStatus::kOk);
  EXPECT_EQ(v, -1.0);
  // Limits of a signed 10-bit signal: -512 .. 511.
  EXPECT_EQ(encode(m, -512.0, f), SignalStatus::kOk);
  EXPECT_EQ(encode(m, -513.0, f), SignalStatus::kClamped);
  ASSERT_EQ(decode(m, f, v), SignalStatus::kOk);
  EXPECT_EQ(v, -512.0);
  EXPECT_EQ(encode(m, 600.0, f), SignalStatus::kClamped);
  ASSERT_EQ(decode(m, f, v), SignalStatus::kOk);
  EXPECT_EQ(v, 511.0);
  EXPECT_EQ(sign_extend(0x3FF, 10), -1);
  EXPECT_EQ(sign_extend(0x1FF, 10), 511);
  EXPECT_EQ(sign_extend(0x1, 1), -1);
}

TEST(SignalMap, EncodeRoundingAndClamping) {
  SignalSpec s = spec(0, 8, kIntel, false, 0.1, -10.0);
  CanFrame f = empty_frame();
  std::uint64_t raw = 0;
  ASSERT_EQ(encode(s, -9.96, f), SignalStatus::kOk);  // 0.4 -> 0
  ASSERT_TRUE(extract_raw(s, f, raw));
  EXPECT_EQ(raw, 0u);
  ASSERT_EQ(encode(s, -9.94, f), SignalStatus::kOk);  // 0.6 -> 1
  ASSERT_TRUE(extract_raw(s, f, raw));
  EXPECT_EQ(raw, 1u);
  ASSERT_EQ(encode(s, -9.75, f), SignalStatus::kOk);  // 2.5 -> 3 (half away from zero)
  ASSERT_TRUE(extract_raw(s, f, raw));
  EXPECT_EQ(raw, 3u);
  EXPECT_EQ(encode(s, -11.0, f), SignalStatus::kClamped);  // below the raw range
  ASSERT_TRUE(extract_raw(s, f, raw));
  EXPECT_EQ(raw, 0u);
  EXPECT_EQ(encode(s, 100.0, f), SignalStatus::kClamped);  // above: 255
  ASSERT_TRUE(extract_raw(s, f, raw));
  EXPECT_EQ(raw, 255u);
  // [minimum, maximum] clamps first.
  s.minimum = -5.0;
  s.maximum = 5.0;
  EXPECT_EQ(encode(s, 7.0, f), SignalStatus::kClamped);
  double v = 0.0;
  ASSERT_EQ(decode(s, f, v), SignalStatus::kOk);
  EXPECT_NEAR(v, 5.0, 1e-12);
  // Decoding outside the range reports it with the value.
  f.data[0] = 200;  // 10.0
  EXPECT_EQ(decode(s, f, v), SignalStatus::kOutOfRange);
  EXPECT_NEAR(v, 10.0, 1e-12);
  // Negative scale (a sensor mounted the other way round).
  const SignalSpec n = spec(0, 16, kIntel, false, -0.01, 0.0);
  ASSERT_EQ(encode(n, -3.0, f), SignalStatus::kOk);
  ASSERT_EQ(decode(n, f, v), SignalStatus::kOk);
  EXPECT_NEAR(v, -3.0, 1e-12);
}

TEST(SignalMap, ErrorsNeverTouchTheFrame) {
  CanFrame f = bytes({1, 2, 3, 4, 5, 6, 7, 8});
  const CanFrame before = f;
  double v = 42.0;
  EXPECT_EQ(encode(spec(0, 8, kIntel, false), NAN, f), SignalStatus::kInvalidValue);
  EXPECT_EQ(encode(spec(0, 8, kIntel, false), INFINITY, f), SignalStatus::kInvalidValue);
  EXPECT_EQ(encode(spec(0, 0, kIntel, false), 1.0, f), SignalStatus::kInvalidSpec);
  EXPECT_EQ(encode(spec(60, 8, kIntel, false), 1.0, f), SignalStatus::kInvalidSpec);
  EXPECT_EQ(encode(spec(0, 8, kIntel, false, 0.0), 1.0, f), SignalStatus::kInvalidSpec);
  SignalSpec other = spec(0, 8, kIntel, false);
  other.id = 0x123;
  EXPECT_EQ(encode(other, 1.0, f), SignalStatus::kWrongIdentifier);
  EXPECT_EQ(decode(other, f, v), SignalStatus::kWrongIdentifier);
  other.id = 0x1F0;
  other.extended = true;
  EXPECT_EQ(decode(other, f, v), SignalStatus::kWrongIdentifier);
  CanFrame short_frame = f;
  short_frame.dlc = 2;
  EXPECT_EQ(decode(spec(7, 24, kMotorola, false), short_frame, v), SignalStatus::kShortFrame);
  EXPECT_EQ(encode(spec(16, 8, kIntel, false), 1.0, short_frame), SignalStatus::kShortFrame);
  EXPECT_EQ(v, 42.0);
  EXPECT_TRUE(same_frame(f, before));
}

TEST(SignalMap, Validation) {
  EXPECT_EQ(validate(spec(0, 64, kIntel, false)), SpecError::kNone);
  EXPECT_EQ(validate(spec(1, 64, kIntel, false)), SpecError::kDoesNotFit);
  EXPECT_EQ(validate(spec(7, 64, kMotorola, false)), SpecError::kNone);
  EXPECT_EQ(validate(spec(6, 64, kMotorola, false)), SpecError::kDoesNotFit);
  EXPECT_EQ(validate(spec(0, 2, kMotorola, false)),
            SpecError::kNone);  // byte 0 bit 0, byte 1 bit 7
  EXPECT_EQ(validate(spec(56, 2, kMotorola, false)), SpecError::kDoesNotFit);
  EXPECT_EQ(validate(spec(0, 65, kIntel, false)), SpecError::kBadLength);
  EXPECT_EQ(validate(spec(64, 1, kIntel, false)), SpecError::kBadStartBit);
  SignalSpec s = spec(0, 8, kIntel, false);
  s.id = 0x800;
  EXPECT_EQ(validate(s), SpecError::kBadIdentifier);
  s.extended = true;
  EXPECT_EQ(validate(s), SpecError::kNone);
  s.offset = NAN;
  EXPECT_EQ(validate(s), SpecError::kBadOffset);
  s.offset = 0.0;
  s.minimum = 2.0;
  s.maximum = 1.0;
  EXPECT_EQ(validate(s), SpecError::kBadRange);
  EXPECT_STRNE(to_string(SpecError::kBadRange), "unknown");
}

// Found by fuzz_signal_map: a spec whose layout fits but which fails validate() (here a zero
// scale, or an identifier above 11 bits) still got a dlc from required_dlc and was read and
// written by extract_raw and insert_raw. Every function refuses a spec validate() refuses.
TEST(SignalMap, AnInvalidSpecIsNeverReadOrWritten) {
  for (int which = 0; which < 2; ++which) {
    SignalSpec s = spec(0, 16, kIntel, false);
    if (which == 0) s.scale = 0.0;
    if (which == 1) s.id = 0x800;
    ASSERT_NE(validate(s), SpecError::kNone);
    EXPECT_EQ(required_dlc(s), 0);
    CanFrame f;
    f.id = s.id;
    f.dlc = 8;
    f.data = {1, 2, 3, 4, 5, 6, 7, 8};
    std::uint64_t raw = 99;
    EXPECT_FALSE(extract_raw(s, f, raw));
    EXPECT_EQ(raw, 99u);
    EXPECT_FALSE(insert_raw(s, 0xFFFF, f));
    EXPECT_EQ(f.data[0], 1);
    EXPECT_EQ(f.data[1], 2);
  }
}

TEST(SignalMap, RandomRoundTripsEveryLayout) {
  // Every start bit, length and byte order that fits, signed and unsigned: encode a random raw
  // value, the other bits of the frame (random) stay, decode returns it.
  std::mt19937_64 rng(5);
  int checked = 0;
  for (ByteOrder order : {kIntel, kMotorola}) {
    for (std::uint16_t start = 0; start < 64; ++start) {
      for (std::uint16_t length = 1; length <= 64; ++length) {
        for (bool is_signed : {false, true}) {
          const SignalSpec s = spec(start, length, order, is_signed);
          if (validate(s) != SpecError::kNone) continue;
          CanFrame f = empty_frame();
          const std::uint64_t noise = rng();
          for (std::size_t i = 0; i < 8; ++i)
            f.data[i] = static_cast<std::uint8_t>(noise >> (8 * i));
          const CanFrame original = f;
          const std::uint64_t mask = length == 64 ? ~0ull : (1ull << length) - 1;
          const std::uint64_t raw = rng() & mask;
          ASSERT_TRUE(insert_raw(s, raw, f));
          std::uint64_t back = 0;
          ASSERT_TRUE(extract_raw(s, f, back));
          ASSERT_EQ(back, raw) << "start " << start << " length " << length;
          // Bits outside the signal are unchanged: re-insert the original bits and compare.
          std::uint64_t orig_raw = 0;
          ASSERT_TRUE(extract_raw(s, original, orig_raw));
          ASSERT_TRUE(insert_raw(s, orig_raw, f));
          ASSERT_TRUE(same_frame(f, original));
          // Through the scaled path for values a double holds exactly.
          if (length <= 52) {
            const double value = is_signed ? static_cast<double>(sign_extend(raw, length))
                                           : static_cast<double>(raw);
            ASSERT_EQ(encode(s, value, f), SignalStatus::kOk);
            double decoded = 0.0;
            ASSERT_EQ(decode(s, f, decoded), SignalStatus::kOk);
            ASSERT_EQ(decoded, value);
          }
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 2 * 2 * (64 * 65 / 2));  // each order: sum over start of (64 - start)
}

TEST(SignalMap, EncodeAndDecodeDoNotAllocate) {
  const SignalSpec t = temperature();
  CanFrame f = empty_frame();
  double v = 0.0;
  const long before = craneassist::test::heap_allocations();
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(encode(t, 250.0 + 0.01 * i, f), SignalStatus::kOk);
    ASSERT_EQ(decode(t, f, v), SignalStatus::kOk);
  }
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}
