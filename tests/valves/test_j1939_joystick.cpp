// SAE J1939-71 joystick messages (BJM/EJM): known frames hand-computed from the layout table in
// j1939_joystick.hpp (../shared/design/references-2026-12.md), every state a receiver must not
// take for a position, round trips, no allocation.
#include <gtest/gtest.h>

#include <cmath>

#include "allocation_counter.hpp"
#include "craneassist/can/j1939.hpp"
#include "craneassist/can/j1939_joystick.hpp"

using namespace craneassist::can;
using namespace craneassist::can::j1939_joystick;

namespace {

CanFrame frame(std::uint32_t pgn, std::uint8_t source, std::array<std::uint8_t, 8> data) {
  CanFrame f;
  f.extended = true;
  f.dlc = 8;
  std::uint32_t raw = 0;
  EXPECT_EQ(j1939::make_id(3, pgn, source, j1939::kGlobalAddress, raw), j1939::IdStatus::kOk);
  f.id = raw;
  f.data = data;
  return f;
}

}  // namespace

TEST(J1939Joystick, PgnsNameKindAndInstance) {
  const std::uint32_t pgns[] = {kPgnBjm1, kPgnEjm1, kPgnBjm2, kPgnEjm2, kPgnBjm3, kPgnEjm3};
  for (int k = 0; k < 6; ++k) {
    Kind kind{};
    int instance = 0;
    ASSERT_TRUE(joystick_pgn(pgns[k], kind, instance));
    EXPECT_EQ(kind, k % 2 == 0 ? Kind::kBasic : Kind::kExtended);
    EXPECT_EQ(instance, k / 2 + 1);
    EXPECT_EQ(joystick_pgn(kind, instance), pgns[k]);
  }
  Kind kind{};
  int instance = 0;
  EXPECT_FALSE(joystick_pgn(kPgnBjm1 - 1, kind, instance));
  EXPECT_FALSE(joystick_pgn(kPgnEjm3 + 1, kind, instance));
  // BJM1 from source 0x33 at priority 3: 0x0CFDD633.
  EXPECT_EQ(frame(kPgnBjm1, 0x33, {}).id, 0x0CFDD633u);
}

TEST(J1939Joystick, DecodesAKnownBasicFrame) {
  // X 50.0 % right: positive bit (bits 4-5 = 01), magnitude 500 in bits 6-15:
  // 500 << 6 | 1 << 4 = 0x7D10 -> bytes 0x10 0x7D. Y 25.0 % back: negative bit (bits 2-3 = 01),
  // 250 << 6 | 1 << 2 = 0x3E84 -> 0x84 0x3E. Byte 5: vendor bits 0xF, Y detent off, X detent on
  // (bits 6-7 = 01) -> 0x4F. Byte 6: button 1 on (bits 6-7), button 4 error (bits 0-1 = 10),
  // buttons 2, 3 off -> 0x42. Byte 7: button 5 not available (bits 6-7 = 11), the rest off -> 0xC0.
  // Byte 8: button 12 on (bits 0-1) -> 0x01.
  JoystickMessage m;
  ASSERT_EQ(decode(frame(kPgnBjm2, 0x23, {0x10, 0x7D, 0x84, 0x3E, 0x4F, 0x42, 0xC0, 0x01}), m),
            DecodeStatus::kOk);
  EXPECT_EQ(m.kind, Kind::kBasic);
  EXPECT_EQ(m.instance, 2);
  EXPECT_EQ(m.axes[0].status, AxisStatus::kOk);
  EXPECT_DOUBLE_EQ(m.axes[0].value, 0.5);
  EXPECT_FALSE(m.axes[0].neutral);
  EXPECT_EQ(m.axes[1].status, AxisStatus::kOk);
  EXPECT_DOUBLE_EQ(m.axes[1].value, -0.25);
  EXPECT_EQ(m.axes[2].status, AxisStatus::kNotAvailable);  // a BJM has two axes
  EXPECT_EQ(m.y_detent, Switch::kOff);
  EXPECT_EQ(m.x_detent, Switch::kOn);
  EXPECT_EQ(m.buttons[0], Switch::kOn);
  EXPECT_EQ(m.buttons[1], Switch::kOff);
  EXPECT_EQ(m.buttons[2], Switch::kOff);
  EXPECT_EQ(m.buttons[3], Switch::kError);
  EXPECT_EQ(m.buttons[4], Switch::kNotAvailable);
  for (int b = 5; b < 11; ++b) EXPECT_EQ(m.buttons[static_cast<std::size_t>(b)], Switch::kOff);
  EXPECT_EQ(m.buttons[11], Switch::kOn);
}

TEST(J1939Joystick, DecodesAKnownExtendedFrame) {
  // Grip X neutral (bits 0-1 = 01, magnitude 0) -> 0x01 0x00; grip Y 100 % forward:
  // 1000 << 6 | 1 << 4 = 0xFA10 -> 0x10 0xFA; theta 0.1 % counter-clockwise (negative):
  // 1 << 6 | 1 << 2 = 0x0044 -> 0x44 0x00. Bytes 7, 8 not available.
  JoystickMessage m;
  ASSERT_EQ(decode(frame(kPgnEjm1, 0x13, {0x01, 0x00, 0x10, 0xFA, 0x44, 0x00, 0xFF, 0xFF}), m),
            DecodeStatus::kOk);
  EXPECT_EQ(m.kind, Kind::kExtended);
  EXPECT_EQ(m.instance, 1);
  EXPECT_EQ(m.axes[0].status, AxisStatus::kOk);
  EXPECT_TRUE(m.axes[0].neutral);
  EXPECT_EQ(m.axes[0].value, 0.0);
  EXPECT_DOUBLE_EQ(m.axes[1].value, 1.0);
  EXPECT_DOUBLE_EQ(m.axes[2].value, -0.001);
  for (const Switch b : m.buttons) EXPECT_EQ(b, Switch::kNotAvailable);
}

TEST(J1939Joystick, ErrorAndNotAvailableAreNeverAPosition) {
  struct Case {
    std::uint16_t bits;
    AxisStatus status;
    const char* what;
  };
  const auto bits = [](unsigned neutral, unsigned negative, unsigned positive, unsigned magnitude) {
    return static_cast<std::uint16_t>(neutral | negative << 2 | positive << 4 | magnitude << 6);
  };
  const Case cases[] = {
      {bits(0, 0, 1, 1022), AxisStatus::kError, "magnitude 1022 (error)"},
      {bits(3, 3, 3, 1023), AxisStatus::kNotAvailable, "everything not available"},
      {bits(0, 0, 1, 1023), AxisStatus::kNotAvailable, "magnitude 1023 (not available)"},
      {bits(0, 0, 1, 1001), AxisStatus::kError, "magnitude above 100 %"},
      {bits(0, 0, 1, 1021), AxisStatus::kError, "magnitude in the reserved range"},
      {bits(2, 0, 1, 300), AxisStatus::kError, "neutral status error"},
      {bits(0, 2, 1, 300), AxisStatus::kError, "negative status error"},
      {bits(0, 0, 2, 300), AxisStatus::kError, "positive status error"},
      {bits(0, 0, 3, 300), AxisStatus::kNotAvailable, "positive status not available"},
      {bits(1, 0, 0, 5), AxisStatus::kContradiction, "neutral with a magnitude"},
      {bits(1, 0, 1, 0), AxisStatus::kContradiction, "neutral and positive"},
      {bits(0, 1, 1, 300), AxisStatus::kContradiction, "both directions"},
      {bits(0, 0, 0, 300), AxisStatus::kContradiction, "no status bit at all"},
      {bits(1, 1, 1, 0), AxisStatus::kContradiction, "every status bit"},
  };
  for (const Case& c : cases) {
    const Axis a = decode_axis(c.bits);
    EXPECT_EQ(a.status, c.status) << c.what;
    EXPECT_EQ(a.value, 0.0) << c.what;
    EXPECT_FALSE(a.neutral) << c.what;
  }
  // A direction bit with magnitude 0 is a stick just leaving neutral: a position of 0.
  const Axis leaving = decode_axis(bits(0, 1, 0, 0));
  EXPECT_EQ(leaving.status, AxisStatus::kOk);
  EXPECT_EQ(leaving.value, 0.0);
  EXPECT_FALSE(leaving.neutral);
}

TEST(J1939Joystick, RejectsOtherFramesWithoutTouchingTheMessage) {
  JoystickMessage m;
  m.instance = 3;
  CanFrame other = frame(65072, 0x80, {});  // an ISO 11783-7 valve command
  EXPECT_EQ(decode(other, m), DecodeStatus::kNotJoystick);
  CanFrame standard = frame(kPgnBjm1, 0x33, {});
  standard.extended = false;
  EXPECT_EQ(decode(standard, m), DecodeStatus::kNotJoystick);
  CanFrame shorter = frame(kPgnBjm1, 0x33, {});
  shorter.dlc = 7;
  EXPECT_EQ(decode(shorter, m), DecodeStatus::kShortFrame);
  EXPECT_EQ(m.instance, 3);
}

TEST(J1939Joystick, EveryPositionRoundTrips) {
  for (int k = -1000; k <= 1000; ++k) {
    JoystickMessage sent;
    sent.kind = k % 2 == 0 ? Kind::kBasic : Kind::kExtended;
    sent.instance = 1 + (k + 1000) % 3;
    sent.axes[0] = axis_at(k / 1000.0);
    sent.axes[1] = axis_at(-k / 1000.0);
    sent.axes[2] = axis_at(0.5 * k / 1000.0);
    sent.buttons.fill(Switch::kOff);
    sent.buttons[static_cast<std::size_t>((k + 1000) % kButtons)] = Switch::kOn;
    sent.x_detent = k == 0 ? Switch::kOn : Switch::kOff;
    sent.y_detent = Switch::kOff;
    CanFrame f;
    encode(sent, 0x31, f);
    JoystickMessage got;
    ASSERT_EQ(decode(f, got), DecodeStatus::kOk);
    EXPECT_EQ(j1939::decompose(f.id).source_address, 0x31);
    EXPECT_EQ(got.kind, sent.kind);
    EXPECT_EQ(got.instance, sent.instance);
    const int axes = sent.kind == Kind::kExtended ? 3 : 2;
    for (int a = 0; a < axes; ++a) {
      const auto i = static_cast<std::size_t>(a);
      EXPECT_EQ(got.axes[i].status, AxisStatus::kOk);
      EXPECT_NEAR(got.axes[i].value, sent.axes[i].value, 1e-12) << k << " axis " << a;
      EXPECT_EQ(got.axes[i].neutral, sent.axes[i].value == 0.0);
    }
    if (sent.kind == Kind::kBasic) {
      EXPECT_EQ(got.buttons, sent.buttons);
      EXPECT_EQ(got.x_detent, sent.x_detent);
    }
  }
}

TEST(J1939Joystick, EncodesFaultsAsGiven) {
  // What an emulator sends to test a receiver: an axis in error, a contradicting one.
  JoystickMessage m;
  m.axes[0].status = AxisStatus::kError;
  m.axes[0].neutral_bit = Switch::kOff;
  m.axes[0].negative_bit = Switch::kOff;
  m.axes[0].positive_bit = Switch::kOn;
  m.axes[0].magnitude = kMagnitudeError;
  m.axes[1].status = AxisStatus::kContradiction;
  m.axes[1].neutral_bit = Switch::kOn;
  m.axes[1].negative_bit = Switch::kOff;
  m.axes[1].positive_bit = Switch::kOff;
  m.axes[1].magnitude = 200;
  CanFrame f;
  encode(m, 0x33, f);
  JoystickMessage got;
  ASSERT_EQ(decode(f, got), DecodeStatus::kOk);
  EXPECT_EQ(got.axes[0].status, AxisStatus::kError);
  EXPECT_EQ(got.axes[1].status, AxisStatus::kContradiction);
  EXPECT_EQ(got.axes[1].magnitude, 200);
}

TEST(J1939Joystick, AxisAtClampsAndRejectsNaN) {
  EXPECT_EQ(axis_at(2.0).magnitude, 1000);
  EXPECT_EQ(axis_at(-7.0).negative_bit, Switch::kOn);
  const Axis nan = axis_at(std::nan(""));
  EXPECT_TRUE(nan.neutral);
  EXPECT_EQ(nan.magnitude, 0);
}

TEST(J1939Joystick, DecodingAllocatesNothing) {
  const CanFrame f = frame(kPgnBjm1, 0x33, {0x10, 0x7D, 0x84, 0x3E, 0x4F, 0x42, 0xC0, 0x01});
  JoystickMessage m;
  const long before = craneassist::test::heap_allocations();
  for (int i = 0; i < 100; ++i) ASSERT_EQ(decode(f, m), DecodeStatus::kOk);
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}
