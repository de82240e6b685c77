// A classic CAN frame independent of the Linux headers, and the candump log line format.
//
// The log format is what `candump -L` writes and `canplayer` reads (can-utils, lib.c
// snprintf_can_frame / parse_canframe):
//
//   (1700000000.123456) vcan0 18FE3080#0102030405060708
//
// a timestamp in seconds with six decimals in parentheses, the interface, then the identifier in
// hex (three digits: an 11-bit identifier; eight digits: a 29-bit identifier), '#', and 0 to 8
// data bytes as pairs of hex digits. Remote frames (`123#R`), CAN FD (`123##1...`) and error
// frames (identifier with the error flag 0x20000000) are reported as unsupported, never
// misread. Nothing here allocates or throws.
//
// A line may end in the direction mark of `candump -l -x` (can-utils 2023.03 and later): " T"
// for a frame this host sent, " R" for one it received:
//
//   (1700000000.123456) vcan0 18FF0080#0101000000000000 T
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace craneassist::can {

inline constexpr std::uint32_t kMaxStandardId = 0x7FFu;       // 11 bits
inline constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFFu;  // 29 bits
inline constexpr std::uint8_t kMaxDlc = 8;

struct CanFrame {
  std::uint32_t id = 0;   // 11-bit or 29-bit identifier, without flags
  bool extended = false;  // true: 29-bit identifier (CAN 2.0B)
  std::uint8_t dlc = 0;   // 0..8 data bytes
  std::array<std::uint8_t, 8> data{};
};

// The identifier fits its format and the dlc is 0..8.
bool is_valid(const CanFrame& frame);

// Equal identifier, format, dlc and the first dlc data bytes (bytes past dlc are ignored).
bool same_frame(const CanFrame& a, const CanFrame& b);

// The longest line format_candump writes: "(" 20 digits "." 6 digits ") " interface (at most
// kMaxInterfaceLength) " " 8 id digits "#" 16 data digits, plus a terminating NUL.
inline constexpr std::size_t kMaxInterfaceLength = 15;  // IFNAMSIZ - 1 on Linux
inline constexpr std::size_t kCandumpLineCapacity =
    1 + 20 + 1 + 6 + 2 + kMaxInterfaceLength + 1 + 8 + 1 + 16 + 2 + 1;

// The direction mark at the end of a line: none (plain candump -L), " T" sent, " R" received.
enum class CandumpDirection { kNone, kTx, kRx };

enum class CandumpStatus {
  kOk,
  kBufferTooSmall,      // format: the output buffer cannot hold the line
  kInvalidFrame,        // format: the frame is not valid (is_valid)
  kBadInterface,        // empty, too long, or containing blanks, '#' or parentheses
  kBadTimestamp,        // "(sec.frac)" missing or malformed, or negative
  kBadIdentifier,       // not 3 or 8 hex digits, or out of range
  kBadData,             // odd number of hex digits, a non-hex digit, or more than 8 bytes
  kUnsupportedFrame,    // remote, CAN FD or error frame
  kTrailingCharacters,  // anything but blanks after the data
};
const char* to_string(CandumpStatus status);

// Microseconds since the Unix epoch (candump's timestamps are gettimeofday values).
using TimestampUs = std::int64_t;

// Writes one line without the newline, NUL-terminated, into out; `written` is the length without
// the NUL. On failure nothing usable is written and written is 0.
CandumpStatus format_candump(const CanFrame& frame, TimestampUs timestamp, std::string_view iface,
                             std::span<char> out, std::size_t& written,
                             CandumpDirection direction = CandumpDirection::kNone);

struct CandumpRecord {
  TimestampUs timestamp = 0;
  std::string_view iface;  // points into the parsed line
  CanFrame frame;
  CandumpDirection direction = CandumpDirection::kNone;
};

// Parses one line (a trailing '\n' or "\r\n" and surrounding blanks are accepted). On failure
// `record` is left in an unspecified but valid state.
CandumpStatus parse_candump(std::string_view line, CandumpRecord& record);

}  // namespace craneassist::can
