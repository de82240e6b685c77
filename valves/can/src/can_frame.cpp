#include "craneassist/can/can_frame.hpp"

#include <algorithm>
#include <cstdio>

namespace craneassist::can {
namespace {

constexpr char kHex[] = "0123456789ABCDEF";

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

bool valid_interface(std::string_view iface) {
  if (iface.empty() || iface.size() > kMaxInterfaceLength) return false;
  return std::none_of(iface.begin(), iface.end(), [](char c) {
    return is_blank(c) || c == '#' || c == '(' || c == ')' || c == '\0';
  });
}

// Appends s to out at pos; false if it does not fit (leaving room for the NUL).
bool append(std::span<char> out, std::size_t& pos, std::string_view s) {
  if (pos + s.size() + 1 > out.size()) return false;
  std::copy(s.begin(), s.end(), out.begin() + static_cast<std::ptrdiff_t>(pos));
  pos += s.size();
  return true;
}

}  // namespace

bool is_valid(const CanFrame& frame) {
  const std::uint32_t max_id = frame.extended ? kMaxExtendedId : kMaxStandardId;
  return frame.id <= max_id && frame.dlc <= kMaxDlc;
}

bool same_frame(const CanFrame& a, const CanFrame& b) {
  if (a.id != b.id || a.extended != b.extended || a.dlc != b.dlc) return false;
  const std::size_t n = std::min<std::size_t>(a.dlc, kMaxDlc);
  return std::equal(a.data.begin(), a.data.begin() + static_cast<std::ptrdiff_t>(n),
                    b.data.begin());
}

const char* to_string(CandumpStatus status) {
  switch (status) {
    case CandumpStatus::kOk:
      return "ok";
    case CandumpStatus::kBufferTooSmall:
      return "output buffer too small";
    case CandumpStatus::kInvalidFrame:
      return "invalid frame (identifier out of range or dlc above 8)";
    case CandumpStatus::kBadInterface:
      return "missing or malformed interface name";
    case CandumpStatus::kBadTimestamp:
      return "missing or malformed timestamp, expected (SECONDS.FRACTION)";
    case CandumpStatus::kBadIdentifier:
      return "malformed identifier, expected 3 or 8 hex digits";
    case CandumpStatus::kBadData:
      return "malformed data, expected up to 8 bytes as hex digit pairs";
    case CandumpStatus::kUnsupportedFrame:
      return "unsupported frame (remote, CAN FD or error frame)";
    case CandumpStatus::kTrailingCharacters:
      return "unexpected characters after the data";
  }
  return "unknown";
}

CandumpStatus format_candump(const CanFrame& frame, TimestampUs timestamp, std::string_view iface,
                             std::span<char> out, std::size_t& written,
                             CandumpDirection direction) {
  written = 0;
  if (!is_valid(frame)) return CandumpStatus::kInvalidFrame;
  if (!valid_interface(iface)) return CandumpStatus::kBadInterface;
  if (timestamp < 0) return CandumpStatus::kBadTimestamp;

  // "(sec.usec) ": std::snprintf with a fixed local buffer does not allocate.
  char head[40];
  const int n = std::snprintf(head, sizeof(head), "(%lld.%06lld) ",
                              static_cast<long long>(timestamp / 1000000),
                              static_cast<long long>(timestamp % 1000000));
  if (n <= 0 || static_cast<std::size_t>(n) >= sizeof(head)) return CandumpStatus::kBadTimestamp;

  char body[8 + 1 + 2 * kMaxDlc];
  std::size_t b = 0;
  const std::size_t dlc = std::min<std::size_t>(frame.dlc, kMaxDlc);  // is_valid checked it
  const int id_digits = frame.extended ? 8 : 3;
  for (int i = id_digits - 1; i >= 0; --i) body[b++] = kHex[(frame.id >> (4 * i)) & 0xFu];
  body[b++] = '#';
  for (std::size_t i = 0; i < dlc; ++i) {
    body[b++] = kHex[frame.data[i] >> 4];
    body[b++] = kHex[frame.data[i] & 0xFu];
  }

  std::size_t pos = 0;
  if (!append(out, pos, std::string_view(head, static_cast<std::size_t>(n))) ||
      !append(out, pos, iface) || !append(out, pos, " ") ||
      !append(out, pos, std::string_view(body, b)) ||
      !append(out, pos,
              direction == CandumpDirection::kTx   ? " T"
              : direction == CandumpDirection::kRx ? " R"
                                                   : "")) {
    if (!out.empty()) out[0] = '\0';
    return CandumpStatus::kBufferTooSmall;
  }
  out[pos] = '\0';
  written = pos;
  return CandumpStatus::kOk;
}

CandumpStatus parse_candump(std::string_view line, CandumpRecord& record) {
  std::string_view s = trim(line);

  // Timestamp "(digits.digits)".
  if (s.empty() || s.front() != '(') return CandumpStatus::kBadTimestamp;
  const std::size_t close = s.find(')');
  if (close == std::string_view::npos) return CandumpStatus::kBadTimestamp;
  const std::string_view ts = s.substr(1, close - 1);
  const std::size_t dot = ts.find('.');
  if (dot == std::string_view::npos || dot == 0 || dot + 1 == ts.size() || dot > 18) {
    return CandumpStatus::kBadTimestamp;
  }
  std::int64_t seconds = 0;
  for (std::size_t i = 0; i < dot; ++i) {
    if (ts[i] < '0' || ts[i] > '9') return CandumpStatus::kBadTimestamp;
    seconds = seconds * 10 + (ts[i] - '0');
  }
  std::int64_t micros = 0;
  std::size_t frac_digits = 0;
  for (std::size_t i = dot + 1; i < ts.size(); ++i) {
    if (ts[i] < '0' || ts[i] > '9') return CandumpStatus::kBadTimestamp;
    if (frac_digits < 6) micros = micros * 10 + (ts[i] - '0');  // further digits truncated
    ++frac_digits;
  }
  for (std::size_t i = frac_digits; i < 6; ++i) micros *= 10;
  if (seconds > (INT64_MAX - 999999) / 1000000) return CandumpStatus::kBadTimestamp;
  record.timestamp = seconds * 1000000 + micros;
  s.remove_prefix(close + 1);

  // Interface.
  const std::size_t iface_begin = s.find_first_not_of(" \t");
  if (iface_begin == 0 || iface_begin == std::string_view::npos) {
    return CandumpStatus::kBadInterface;
  }
  s.remove_prefix(iface_begin);
  const std::size_t iface_end = s.find_first_of(" \t");
  if (iface_end == std::string_view::npos) return CandumpStatus::kBadInterface;
  record.iface = s.substr(0, iface_end);
  if (!valid_interface(record.iface)) return CandumpStatus::kBadInterface;
  s.remove_prefix(iface_end);
  s = trim(s);

  // Identifier.
  const std::size_t hash = s.find('#');
  if (hash == std::string_view::npos) return CandumpStatus::kBadIdentifier;
  const std::string_view id_text = s.substr(0, hash);
  if (id_text.size() != 3 && id_text.size() != 8) return CandumpStatus::kBadIdentifier;
  std::uint32_t id = 0;
  for (char c : id_text) {
    const int v = hex_value(c);
    if (v < 0) return CandumpStatus::kBadIdentifier;
    id = (id << 4) | static_cast<std::uint32_t>(v);
  }
  CanFrame frame;
  frame.extended = id_text.size() == 8;
  if (frame.extended && (id & 0x20000000u) != 0) return CandumpStatus::kUnsupportedFrame;
  if (id > (frame.extended ? kMaxExtendedId : kMaxStandardId)) {
    return CandumpStatus::kBadIdentifier;
  }
  frame.id = id;
  s.remove_prefix(hash + 1);

  // Data.
  if (!s.empty() && (s.front() == '#' || s.front() == 'R' || s.front() == 'r')) {
    return CandumpStatus::kUnsupportedFrame;
  }
  std::size_t i = 0;
  std::uint8_t dlc = 0;
  while (i < s.size() && !is_blank(s[i])) {
    if (s[i] == '.') {  // candump -l may separate bytes with '.'; accept it between bytes
      ++i;
      continue;
    }
    if (i + 1 >= s.size()) return CandumpStatus::kBadData;
    const int hi = hex_value(s[i]);
    const int lo = hex_value(s[i + 1]);
    if (hi < 0 || lo < 0) return CandumpStatus::kBadData;
    if (dlc == kMaxDlc) return CandumpStatus::kBadData;
    frame.data[dlc++] = static_cast<std::uint8_t>((hi << 4) | lo);
    i += 2;
  }
  frame.dlc = dlc;
  // The direction mark of candump -l -x, after a blank: "T" or "R".
  const std::string_view rest = trim(s.substr(i));
  record.direction = CandumpDirection::kNone;
  if (rest == "T") {
    record.direction = CandumpDirection::kTx;
  } else if (rest == "R") {
    record.direction = CandumpDirection::kRx;
  } else if (!rest.empty()) {
    return CandumpStatus::kTrailingCharacters;
  }
  record.frame = frame;
  return CandumpStatus::kOk;
}

}  // namespace craneassist::can
