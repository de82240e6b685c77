// ISO 11783-7 auxiliary valve messages: known vectors from the layout table in
// iso11783_valve.hpp (hand-computed), round trips, errors, no allocation.
#include <gtest/gtest.h>

#include <cmath>

#include "allocation_counter.hpp"
#include "craneassist/can/iso11783_valve.hpp"

using namespace craneassist::can;
using namespace craneassist::can::iso11783;

namespace {

void expect_bytes(const CanFrame& f, std::array<std::uint8_t, 8> expected) {
  ASSERT_EQ(f.dlc, 8);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(f.data[i], expected[i]) << "byte " << i + 1;
  }
}

AuxValveCommand command(std::uint8_t valve, double flow, ValveState state,
                        FailSafeMode fail_safe = AuxValveCommand{}.fail_safe) {
  AuxValveCommand c;
  c.valve = valve;
  c.flow = flow;
  c.state = state;
  c.fail_safe = fail_safe;
  return c;
}

// A flow message from source address 0x10 (priority 3) is the frame `id` with the bytes
// `expected` (out: f), and that frame decodes (into d) from 0x10 again.
template <class Message>
void expect_known_vector(const Message& m, std::uint32_t id, std::array<std::uint8_t, 8> expected,
                         CanFrame& f, Message& d) {
  ASSERT_EQ(encode(m, 0x10, 3, f), CodecStatus::kOk);
  EXPECT_EQ(f.id, id);
  expect_bytes(f, expected);
  std::uint8_t sa = 0;
  ASSERT_EQ(decode(f, d, sa), CodecStatus::kOk);
  EXPECT_EQ(sa, 0x10);
}

}  // namespace

TEST(AuxValveCommand, KnownVectorHalfFlowExtend) {
  const AuxValveCommand c = command(0, 0.5, ValveState::kExtend, FailSafeMode::kBlock);
  CanFrame f;
  ASSERT_EQ(encode(c, 0x80, 3, f), CodecStatus::kOk);
  EXPECT_TRUE(f.extended);
  EXPECT_EQ(f.id, 0x0CFE3080u);  // priority 3, PGN 65072, SA 0x80
  // 125 = 50 % at 0.4 %/bit; resolution mode 01 with reserved ones; state 1 | reserved 11 |
  // fail-safe 00; 32000 = 0x7D00 little endian; reserved 0xFF.
  expect_bytes(f, {0x7D, 0xFD, 0x31, 0x00, 0x7D, 0xFF, 0xFF, 0xFF});
}

TEST(AuxValveCommand, KnownVectorFullRetractFloatStandardOnly) {
  AuxValveCommand c = command(15, 1.0, ValveState::kRetract, FailSafeMode::kFloat);
  c.extended_resolution = false;
  CanFrame f;
  ASSERT_EQ(encode(c, 0x27, 3, f), CodecStatus::kOk);
  EXPECT_EQ(f.id, 0x0CFE3F27u);
  expect_bytes(f, {0xFA, 0xFC, 0x72, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF});
}

TEST(AuxValveCommand, BlockAndFloatAndDontCare) {
  CanFrame f;
  AuxValveCommand c = command(3, 0.0, ValveState::kBlock);
  ASSERT_EQ(encode(c, 0x80, 6, f), CodecStatus::kOk);
  EXPECT_EQ(f.id, 0x18FE3380u);
  expect_bytes(f, {0x00, 0xFD, 0x30, 0x00, 0x00, 0xFF, 0xFF, 0xFF});
  c.state = ValveState::kFloat;
  c.fail_safe = FailSafeMode::kDontCare;
  ASSERT_EQ(encode(c, 0x80, 6, f), CodecStatus::kOk);
  EXPECT_EQ(f.data[2], 0xF3);
  c.state = ValveState::kNotAvailable;
  ASSERT_EQ(encode(c, 0x80, 6, f), CodecStatus::kOk);
  EXPECT_EQ(f.data[2], 0xFF);
}

TEST(AuxValveCommand, RoundsToNearestAndClamps) {
  AuxValveCommand c;
  c.state = ValveState::kExtend;
  CanFrame f;
  c.flow = 1.0 / 3.0;  // 83.33 -> 83; 21333.3 -> 21333 = 0x5355
  ASSERT_EQ(encode(c, 0x80, 3, f), CodecStatus::kOk);
  EXPECT_EQ(f.data[0], 83);
  EXPECT_EQ(f.data[3], 0x55);
  EXPECT_EQ(f.data[4], 0x53);
  c.flow = 0.0061;  // 1.525 -> 2
  ASSERT_EQ(encode(c, 0x80, 3, f), CodecStatus::kOk);
  EXPECT_EQ(f.data[0], 2);
  c.flow = 1.2;
  ASSERT_EQ(encode(c, 0x80, 3, f), CodecStatus::kClamped);
  EXPECT_EQ(f.data[0], 250);
  EXPECT_EQ(f.data[3] | (f.data[4] << 8), 64000);
  c.flow = -0.1;
  ASSERT_EQ(encode(c, 0x80, 3, f), CodecStatus::kClamped);
  EXPECT_EQ(f.data[0], 0);
}

TEST(AuxValveCommand, InvalidArgumentsWriteNothing) {
  CanFrame f;
  f.id = 0x123;
  AuxValveCommand c;
  c.flow = std::nan("");
  EXPECT_EQ(encode(c, 0x80, 3, f), CodecStatus::kInvalidArgument);
  c.flow = INFINITY;
  EXPECT_EQ(encode(c, 0x80, 3, f), CodecStatus::kInvalidArgument);
  c.flow = 0.5;
  c.valve = 16;
  EXPECT_EQ(encode(c, 0x80, 3, f), CodecStatus::kInvalidArgument);
  c.valve = 0;
  EXPECT_EQ(encode(c, 0x80, 8, f), CodecStatus::kInvalidArgument);
  c.state = ValveState::kError;
  EXPECT_EQ(encode(c, 0x80, 3, f), CodecStatus::kInvalidArgument);
  c.state = ValveState::kBlock;
  c.fail_safe = FailSafeMode::kReserved;
  EXPECT_EQ(encode(c, 0x80, 3, f), CodecStatus::kInvalidArgument);
  c.fail_safe = static_cast<FailSafeMode>(9);
  EXPECT_EQ(encode(c, 0x80, 3, f), CodecStatus::kInvalidArgument);
  EXPECT_EQ(f.id, 0x123u);
}

TEST(AuxValveCommand, RoundTripsEveryValveStateAndMode) {
  for (std::uint8_t valve = 0; valve < kAuxValveCount; ++valve) {
    for (ValveState state : {ValveState::kBlock, ValveState::kExtend, ValveState::kRetract,
                             ValveState::kFloat, ValveState::kNotAvailable}) {
      for (FailSafeMode fs :
           {FailSafeMode::kBlock, FailSafeMode::kFloat, FailSafeMode::kDontCare}) {
        for (bool ext : {true, false}) {
          AuxValveCommand c = command(valve, 0.01 * valve * 6.0 + 0.0123, state, fs);
          c.extended_resolution = ext;
          CanFrame f;
          ASSERT_EQ(encode(c, 0x81, 3, f), CodecStatus::kOk);
          AuxValveCommand d;
          std::uint8_t sa = 0;
          ASSERT_EQ(decode(f, d, sa), CodecStatus::kOk);
          EXPECT_EQ(sa, 0x81);
          EXPECT_EQ(d.valve, valve);
          EXPECT_EQ(d.state, state);
          EXPECT_EQ(d.fail_safe, fs);
          EXPECT_EQ(d.extended_resolution, ext);
          EXPECT_NEAR(d.flow, c.flow, ext ? kExtendedFlowPerBit / 2 : kStandardFlowPerBit / 2);
        }
      }
    }
  }
}

TEST(AuxValveCommand, DecodeErrors) {
  AuxValveCommand c;
  c.flow = 0.5;
  CanFrame f;
  ASSERT_EQ(encode(c, 0x80, 3, f), CodecStatus::kOk);
  AuxValveCommand d;
  std::uint8_t sa = 0;

  CanFrame g = f;
  g.dlc = 7;
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kBadLength);
  g = f;
  g.extended = false;
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kWrongIdentifier);
  g = f;
  g.id = 0x0CFE2080;  // measured flow, not a command
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kWrongIdentifier);
  g.id = 0x0CFE4080;  // PGN 65088: past valve 15
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kWrongIdentifier);

  // Resolution mode 00: the 8-bit field; 0xFE there is an error indicator.
  g = f;
  g.data[1] = 0xFC;
  g.data[0] = 0xFE;
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kBadField);
  EXPECT_TRUE(std::isnan(d.flow));
  // Mode 01 but the 16-bit field not available: falls back to the 8-bit field.
  g = f;
  g.data[3] = 0xFF;
  g.data[4] = 0xFF;
  ASSERT_EQ(decode(g, d, sa), CodecStatus::kOk);
  EXPECT_FALSE(d.extended_resolution);
  EXPECT_DOUBLE_EQ(d.flow, 0.5);
  // A reserved state code.
  g = f;
  g.data[2] = 0x35;
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kBadField);
  // Found by fuzz_can_frames: the 16-bit flow holds 64000 at 100 %; 64001..0xFAFF decoded to a
  // flow above 1 (up to 100.4 %) with kOk instead of a bad field.
  g = f;
  g.data[3] = 0x00;  // 64000 = 0xFA00: full flow
  g.data[4] = 0xFA;
  ASSERT_EQ(decode(g, d, sa), CodecStatus::kOk);
  EXPECT_DOUBLE_EQ(d.flow, 1.0);
  g.data[3] = 0x01;  // 64001: beyond 100 %
  EXPECT_EQ(decode(g, d, sa), CodecStatus::kBadField);
  EXPECT_TRUE(std::isnan(d.flow));
}

TEST(AuxValveMeasuredFlow, KnownVectorAndRoundTrip) {
  AuxValveMeasuredFlow m;
  m.valve = 9;
  m.extend_flow = 0.5;            // 175
  m.retract_flow = -0.5;          // 75
  m.extend_pressure_pa = 20e6;    // 4000 = 0x0FA0
  m.retract_pressure_pa = 1e6;    // 200 = 0x00C8
  m.return_pressure_pa = 0.32e6;  // 20
  m.limit = LimitStatus::kNotLimited;
  CanFrame f;
  AuxValveMeasuredFlow d;
  expect_known_vector(m, 0x0CFE2910u /* PGN 65065 */,
                      {0xAF, 0x4B, 0xA0, 0x0F, 0xC8, 0x00, 0x14, 0x1F}, f, d);
  EXPECT_EQ(d.valve, 9);
  EXPECT_DOUBLE_EQ(d.extend_flow, 0.5);
  EXPECT_DOUBLE_EQ(d.retract_flow, -0.5);
  EXPECT_DOUBLE_EQ(d.extend_pressure_pa, 20e6);
  EXPECT_DOUBLE_EQ(d.retract_pressure_pa, 1e6);
  EXPECT_DOUBLE_EQ(d.return_pressure_pa, 0.32e6);
  EXPECT_EQ(d.limit, LimitStatus::kNotLimited);
}

TEST(AuxValveMeasuredFlow, NotAvailableFieldsAndClamping) {
  AuxValveMeasuredFlow m;
  m.extend_flow = std::nan("");
  m.retract_flow = 2.0;  // clamped to 125 %
  m.extend_pressure_pa = std::nan("");
  m.retract_pressure_pa = 400e6;  // clamped to 0xFAFF * 5 kPa
  m.return_pressure_pa = std::nan("");
  m.limit = LimitStatus::kLimitedHigh;
  CanFrame f;
  ASSERT_EQ(encode(m, 0x10, 3, f), CodecStatus::kClamped);
  expect_bytes(f, {0xFF, 0xFA, 0xFF, 0xFF, 0xFF, 0xFA, 0xFF, 0x5F});
  AuxValveMeasuredFlow d;
  std::uint8_t sa = 0;
  ASSERT_EQ(decode(f, d, sa), CodecStatus::kOk);
  EXPECT_TRUE(std::isnan(d.extend_flow));
  EXPECT_DOUBLE_EQ(d.retract_flow, 1.25);
  EXPECT_TRUE(std::isnan(d.extend_pressure_pa));
  EXPECT_DOUBLE_EQ(d.retract_pressure_pa, 0xFAFF * 5000.0);
  EXPECT_TRUE(std::isnan(d.return_pressure_pa));
  EXPECT_EQ(d.limit, LimitStatus::kLimitedHigh);
  m.extend_flow = INFINITY;
  EXPECT_EQ(encode(m, 0x10, 3, f), CodecStatus::kInvalidArgument);
}

TEST(AuxValveEstimatedFlow, KnownVectorAndRoundTrip) {
  AuxValveEstimatedFlow m;
  m.valve = 1;
  m.extend_flow = 0.25;  // 150
  m.retract_flow = std::nan("");
  m.state = ValveState::kExtend;
  m.fail_safe = FailSafeMode::kFloat;
  m.limit = LimitStatus::kLimitedHigh;
  CanFrame f;
  AuxValveEstimatedFlow d;
  expect_known_vector(m, 0x0CFE1110u /* PGN 65041 */,
                      {0x96, 0xFF, 0x71, 0x5F, 0xFF, 0xFF, 0xFF, 0xFF}, f, d);
  std::uint8_t sa = 0;
  EXPECT_EQ(d.valve, 1);
  EXPECT_DOUBLE_EQ(d.extend_flow, 0.25);
  EXPECT_TRUE(std::isnan(d.retract_flow));
  EXPECT_EQ(d.state, ValveState::kExtend);
  EXPECT_EQ(d.fail_safe, FailSafeMode::kFloat);
  EXPECT_EQ(d.limit, LimitStatus::kLimitedHigh);
  // An error indication in the state field decodes; a reserved code is a bad field.
  f.data[2] = 0x3E;
  ASSERT_EQ(decode(f, d, sa), CodecStatus::kOk);
  EXPECT_EQ(d.state, ValveState::kError);
  f.data[2] = 0x37;
  EXPECT_EQ(decode(f, d, sa), CodecStatus::kBadField);
}

TEST(AuxValveMessages, DecodersRejectEachOthersFrames) {
  AuxValveCommand c;
  CanFrame cmd;
  ASSERT_EQ(encode(c, 0x80, 3, cmd), CodecStatus::kOk);
  AuxValveMeasuredFlow mf;
  AuxValveEstimatedFlow ef;
  std::uint8_t sa = 0;
  EXPECT_EQ(decode(cmd, mf, sa), CodecStatus::kWrongIdentifier);
  EXPECT_EQ(decode(cmd, ef, sa), CodecStatus::kWrongIdentifier);
}

TEST(AuxValveMessages, EncodeAndDecodeDoNotAllocate) {
  AuxValveCommand c;
  c.flow = 0.42;
  c.state = ValveState::kRetract;
  AuxValveMeasuredFlow m;
  m.extend_pressure_pa = 1e7;
  CanFrame f1, f2;
  std::uint8_t sa = 0;
  const long before = craneassist::test::heap_allocations();
  for (int i = 0; i < 100; ++i) {
    ASSERT_EQ(encode(c, 0x80, 3, f1), CodecStatus::kOk);
    ASSERT_EQ(decode(f1, c, sa), CodecStatus::kOk);
    ASSERT_EQ(encode(m, 0x10, 3, f2), CodecStatus::kOk);
    ASSERT_EQ(decode(f2, m, sa), CodecStatus::kOk);
  }
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}
