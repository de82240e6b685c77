// CAN frames, the candump log line format and J1939 identifiers.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "allocation_counter.hpp"
#include "craneassist/can/can_frame.hpp"
#include "craneassist/can/j1939.hpp"

using namespace craneassist::can;

namespace {

CanFrame frame(std::uint32_t id, bool extended, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.extended = extended;
  for (std::uint8_t b : bytes) f.data[f.dlc++] = b;
  return f;
}

std::string format(const CanFrame& f, TimestampUs t, std::string_view iface) {
  std::array<char, kCandumpLineCapacity> buf{};
  std::size_t n = 0;
  EXPECT_EQ(format_candump(f, t, iface, buf, n), CandumpStatus::kOk);
  return std::string(buf.data(), n);
}

}  // namespace

TEST(CanFrame, Validity) {
  EXPECT_TRUE(is_valid(frame(0x7FF, false, {})));
  EXPECT_FALSE(is_valid(frame(0x800, false, {})));
  EXPECT_TRUE(is_valid(frame(0x1FFFFFFF, true, {1, 2, 3, 4, 5, 6, 7, 8})));
  EXPECT_FALSE(is_valid(frame(0x20000000, true, {})));
  CanFrame f = frame(0x123, false, {});
  f.dlc = 9;
  EXPECT_FALSE(is_valid(f));
}

TEST(Candump, WritesTheCandumpLogFormat) {
  EXPECT_EQ(format(frame(0x18FE3080, true, {1, 2, 3, 4, 5, 6, 7, 8}), 1700000000123456, "vcan0"),
            "(1700000000.123456) vcan0 18FE3080#0102030405060708");
  EXPECT_EQ(format(frame(0x7A, false, {0xAB, 0xCD}), 5, "can1"), "(0.000005) can1 07A#ABCD");
  EXPECT_EQ(format(frame(0x100, false, {}), 1000000, "vcan0"), "(1.000000) vcan0 100#");
  EXPECT_EQ(format(frame(0x1, true, {0}), 0, "vcan0"), "(0.000000) vcan0 00000001#00");
}

// candump -l -x's direction mark (can-utils 2023.03+): " T" sent, " R" received; parsed back.
TEST(Candump, MarksAndReadsTheDirection) {
  std::array<char, kCandumpLineCapacity> buf{};
  std::size_t n = 0;
  const CanFrame longest = frame(0x1FFFFFFF, true, {1, 2, 3, 4, 5, 6, 7, 8});
  ASSERT_EQ(format_candump(longest, 1700000000123456, "vcan0", buf, n, CandumpDirection::kTx),
            CandumpStatus::kOk);
  EXPECT_EQ(std::string(buf.data(), n), "(1700000000.123456) vcan0 1FFFFFFF#0102030405060708 T");
  ASSERT_EQ(format_candump(frame(0x301, false, {0xAB}), 5, "can1", buf, n, CandumpDirection::kRx),
            CandumpStatus::kOk);
  EXPECT_EQ(std::string(buf.data(), n), "(0.000005) can1 301#AB R");
  const std::pair<const char*, CandumpDirection> lines[] = {
      {"(1.5) vcan0 123#00 T", CandumpDirection::kTx},
      {"(1.5) vcan0 123#00 R\n", CandumpDirection::kRx},
      {"(1.5) vcan0 123# T", CandumpDirection::kTx},
      {"(1.5) vcan0 123#00", CandumpDirection::kNone}};
  for (const auto& [line, direction] : lines) {
    CandumpRecord r;
    ASSERT_EQ(parse_candump(line, r), CandumpStatus::kOk) << line;
    EXPECT_EQ(r.direction, direction) << line;
    EXPECT_EQ(r.frame.id, 0x123u);
  }
}

TEST(Candump, FormatErrors) {
  std::array<char, kCandumpLineCapacity> buf{};
  std::size_t n = 7;
  EXPECT_EQ(format_candump(frame(0x800, false, {}), 0, "vcan0", buf, n),
            CandumpStatus::kInvalidFrame);
  EXPECT_EQ(n, 0u);
  EXPECT_EQ(format_candump(frame(0x1, false, {}), 0, "", buf, n), CandumpStatus::kBadInterface);
  EXPECT_EQ(format_candump(frame(0x1, false, {}), 0, "a b", buf, n), CandumpStatus::kBadInterface);
  EXPECT_EQ(format_candump(frame(0x1, false, {}), 0, "sixteen_chars_xx", buf, n),
            CandumpStatus::kBadInterface);
  EXPECT_EQ(format_candump(frame(0x1, false, {}), -1, "vcan0", buf, n),
            CandumpStatus::kBadTimestamp);
  std::array<char, 20> small{};
  EXPECT_EQ(format_candump(frame(0x1, false, {1, 2, 3}), 0, "vcan0", small, n),
            CandumpStatus::kBufferTooSmall);
}

TEST(Candump, LongestLineFitsTheCapacity) {
  std::array<char, kCandumpLineCapacity> buf{};
  std::size_t n = 0;
  EXPECT_EQ(format_candump(frame(0x1FFFFFFF, true, {1, 2, 3, 4, 5, 6, 7, 8}), INT64_MAX,
                           "abcdefghijklmno", buf, n, CandumpDirection::kTx),
            CandumpStatus::kOk);
  EXPECT_LE(n + 1, kCandumpLineCapacity);
  EXPECT_EQ(buf[n], '\0');
}

TEST(Candump, ParsesLines) {
  CandumpRecord r;
  ASSERT_EQ(parse_candump("(1700000000.123456) vcan0 18FE3080#0102030405060708\n", r),
            CandumpStatus::kOk);
  EXPECT_EQ(r.timestamp, 1700000000123456);
  EXPECT_EQ(r.iface, "vcan0");
  EXPECT_TRUE(same_frame(r.frame, frame(0x18FE3080, true, {1, 2, 3, 4, 5, 6, 7, 8})));

  ASSERT_EQ(parse_candump("(0.5) can0 07a#abcd\r\n", r), CandumpStatus::kOk);
  EXPECT_EQ(r.timestamp, 500000);
  EXPECT_TRUE(same_frame(r.frame, frame(0x7A, false, {0xAB, 0xCD})));

  ASSERT_EQ(parse_candump("(12.1234567) vcan0 123#", r), CandumpStatus::kOk);
  EXPECT_EQ(r.timestamp, 12123456);  // digits past microseconds truncated
  EXPECT_EQ(r.frame.dlc, 0);
}

TEST(Candump, RoundTripsEveryDlcAndBothFormats) {
  for (int dlc = 0; dlc <= 8; ++dlc) {
    for (bool ext : {false, true}) {
      CanFrame f;
      f.id = ext ? 0x1ABCDEF0u + static_cast<std::uint32_t>(dlc)
                 : 0x700u + static_cast<std::uint32_t>(dlc);
      f.extended = ext;
      f.dlc = static_cast<std::uint8_t>(dlc);
      for (int i = 0; i < dlc; ++i)
        f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(0x11 * i + 0x0F);
      const std::string line = format(f, 1700000000000001 + dlc, "vcan0");
      CandumpRecord r;
      ASSERT_EQ(parse_candump(line, r), CandumpStatus::kOk) << line;
      EXPECT_TRUE(same_frame(r.frame, f)) << line;
      EXPECT_EQ(r.timestamp, 1700000000000001 + dlc);
    }
  }
}

TEST(Candump, ReportsMalformedLinesWithoutCrashing) {
  struct Case {
    const char* line;
    CandumpStatus expected;
  };
  const Case cases[] = {
      {"", CandumpStatus::kBadTimestamp},
      {"vcan0 123#00", CandumpStatus::kBadTimestamp},
      {"(abc.def) vcan0 123#00", CandumpStatus::kBadTimestamp},
      {"(1700000000) vcan0 123#00", CandumpStatus::kBadTimestamp},
      {"(1700000000.5 vcan0 123#00", CandumpStatus::kBadTimestamp},
      {"(-1.5) vcan0 123#00", CandumpStatus::kBadTimestamp},
      {"(99999999999999999999.1) vcan0 123#00", CandumpStatus::kBadTimestamp},
      {"(1.5)vcan0 123#00", CandumpStatus::kBadInterface},
      {"(1.5) vcan0", CandumpStatus::kBadInterface},
      {"(1.5) vcan0 12#00", CandumpStatus::kBadIdentifier},
      {"(1.5) vcan0 1234#00", CandumpStatus::kBadIdentifier},
      {"(1.5) vcan0 12G#00", CandumpStatus::kBadIdentifier},
      {"(1.5) vcan0 800#00", CandumpStatus::kBadIdentifier},
      {"(1.5) vcan0 123 00", CandumpStatus::kBadIdentifier},
      {"(1.5) vcan0 123#0", CandumpStatus::kBadData},
      {"(1.5) vcan0 123#0G", CandumpStatus::kBadData},
      {"(1.5) vcan0 123#010203040506070809", CandumpStatus::kBadData},
      {"(1.5) vcan0 123#R", CandumpStatus::kUnsupportedFrame},
      {"(1.5) vcan0 123##100", CandumpStatus::kUnsupportedFrame},
      {"(1.5) vcan0 20000080#0000000000000000", CandumpStatus::kUnsupportedFrame},
      {"(1.5) vcan0 123#00 junk", CandumpStatus::kTrailingCharacters},
      {"(1.5) vcan0 123#00 X", CandumpStatus::kTrailingCharacters},
      {"(1.5) vcan0 123#00 T R", CandumpStatus::kTrailingCharacters},
      {"(1.5) vcan0 123#00 t", CandumpStatus::kTrailingCharacters},
      {"(1.5) vcan0 123#00T", CandumpStatus::kBadData},
  };
  for (const Case& c : cases) {
    CandumpRecord r;
    EXPECT_EQ(parse_candump(c.line, r), c.expected) << c.line;
    EXPECT_STRNE(to_string(c.expected), "unknown");
  }
  // Every prefix of a valid line is handled (no read past the end).
  const std::string line = "(1700000000.123456) vcan0 18FE3080#0102030405060708";
  for (std::size_t n = 0; n < line.size(); ++n) {
    CandumpRecord r;
    (void)parse_candump(std::string_view(line).substr(0, n), r);
  }
}

TEST(Candump, FormatAndParseDoNotAllocate) {
  const CanFrame f = frame(0x18FE3080, true, {1, 2, 3, 4, 5, 6, 7, 8});
  std::array<char, kCandumpLineCapacity> buf{};
  std::size_t n = 0;
  CandumpRecord r;
  const long before = craneassist::test::heap_allocations();
  ASSERT_EQ(format_candump(f, 1700000000123456, "vcan0", buf, n), CandumpStatus::kOk);
  ASSERT_EQ(parse_candump(std::string_view(buf.data(), n), r), CandumpStatus::kOk);
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}

namespace j1939 = craneassist::can::j1939;

TEST(J1939, DecomposesKnownIdentifiers) {
  // Auxiliary valve 0 command from 0x80 at priority 6: PDU2, PGN 0xFE30 = 65072.
  const j1939::Identifier avc = j1939::decompose(0x18FE3080);
  EXPECT_EQ(avc.priority, 6);
  EXPECT_FALSE(avc.extended_data_page);
  EXPECT_FALSE(avc.data_page);
  EXPECT_EQ(avc.pdu_format, 0xFE);
  EXPECT_EQ(avc.pdu_specific, 0x30);
  EXPECT_EQ(avc.source_address, 0x80);
  EXPECT_EQ(j1939::pgn(avc), 65072u);
  EXPECT_FALSE(j1939::is_pdu1(avc.pdu_format));
  EXPECT_EQ(j1939::destination(avc), j1939::kGlobalAddress);

  // EEC1 (PGN 61444 = 0xF004) from the engine, priority 3: the textbook 0x0CF00400.
  const j1939::Identifier eec1 = j1939::decompose(0x0CF00400);
  EXPECT_EQ(eec1.priority, 3);
  EXPECT_EQ(j1939::pgn(eec1), 61444u);
  EXPECT_EQ(eec1.source_address, 0x00);

  // Request (PGN 59904 = 0xEA00, PDU1) from 0xF9 to 0x00: the destination is not in the PGN.
  const j1939::Identifier req = j1939::decompose(0x18EA00F9);
  EXPECT_TRUE(j1939::is_pdu1(req.pdu_format));
  EXPECT_EQ(j1939::pgn(req), 59904u);
  EXPECT_EQ(j1939::destination(req), 0x00);
  EXPECT_EQ(req.source_address, 0xF9);
  EXPECT_EQ(j1939::pgn(j1939::decompose(0x18EA23F9)), 59904u);
  EXPECT_EQ(j1939::destination(j1939::decompose(0x18EA23F9)), 0x23);

  // Data page 1.
  const j1939::Identifier dp = j1939::decompose(0x19F00411);
  EXPECT_TRUE(dp.data_page);
  EXPECT_EQ(j1939::pgn(dp), 0x1F004u);
}

TEST(J1939, ComposeInvertsDecompose) {
  for (std::uint32_t raw : {0x18FE3080u, 0x0CF00400u, 0x18EA00F9u, 0x1FFFFFFFu, 0x00000000u,
                            0x03FF1234u, 0x1DEF0102u}) {
    EXPECT_EQ(j1939::compose(j1939::decompose(raw)), raw);
  }
  static_assert(j1939::compose(j1939::decompose(0x0CFE3280)) == 0x0CFE3280);
}

TEST(J1939, MakeIdFollowsPdu1AndPdu2Rules) {
  std::uint32_t raw = 0;
  ASSERT_EQ(j1939::make_id(3, 65072 + 2, 0x80, 0x00, raw), j1939::IdStatus::kOk);
  EXPECT_EQ(raw, 0x0CFE3280u);  // PDU2: the destination argument is ignored
  ASSERT_EQ(j1939::make_id(6, 59904, 0xF9, 0x00, raw), j1939::IdStatus::kOk);
  EXPECT_EQ(raw, 0x18EA00F9u);
  ASSERT_EQ(j1939::make_id(6, 59904, 0xF9, 0x23, raw), j1939::IdStatus::kOk);
  EXPECT_EQ(raw, 0x18EA23F9u);
  ASSERT_EQ(j1939::make_id(6, 0x1F004, 0x11, 0xFF, raw), j1939::IdStatus::kOk);
  EXPECT_EQ(raw, 0x19F00411u);
  ASSERT_EQ(j1939::make_id(7, 0x2FE00, 0x01, 0xFF, raw), j1939::IdStatus::kOk);  // EDP page
  EXPECT_EQ(raw, 0x1EFE0001u);

  raw = 42;
  EXPECT_EQ(j1939::make_id(8, 65072, 0x80, 0xFF, raw), j1939::IdStatus::kBadPriority);
  EXPECT_EQ(j1939::make_id(3, 0x40000, 0x80, 0xFF, raw), j1939::IdStatus::kBadPgn);
  EXPECT_EQ(j1939::make_id(3, 0x3FE00, 0x80, 0xFF, raw), j1939::IdStatus::kBadPgn);
  EXPECT_EQ(j1939::make_id(6, 0xEA05, 0x80, 0x00, raw), j1939::IdStatus::kPdu1LowByteSet);
  EXPECT_EQ(raw, 42u);
}
