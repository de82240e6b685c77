// Text helpers shared by the input readers (replays, tip paths, joint trajectories): the common
// rules of docs/replay-format.md for fields, numbers and the file text quoted in messages.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace craneassist::input::detail {

// Spaces and tabs removed from both ends.
std::string_view trim(std::string_view s);

// Text from the file, quoted for an error message: control and non-ASCII bytes escaped, long text
// shortened, so that a binary file or a stray '\r' cannot garble the message.
std::string quoted(std::string_view s);

// Shortest round-trip decimal form, locale-independent. The shortest form of a double has at
// most 24 characters ("-2.2250738585072014e-308").
inline constexpr std::size_t kMaxNumberChars = 32;
std::string_view format_number(double value, std::array<char, kMaxNumberChars>& buffer);
std::string number(double value);

// A field as a finite number. On failure returns false with the reason for the message
// ("missing value", "not a number: 'x'", "number out of range: ...", "not a finite number: ...").
bool parse_number(std::string_view text, double& value, std::string& reason);

// Splits a line at commas into at most N trimmed fields; returns the total count.
template <std::size_t N>
std::size_t split_fields(std::string_view line, std::array<std::string_view, N>& fields) {
  std::size_t count = 0;
  while (true) {
    const std::size_t comma = line.find(',');
    if (count < N) fields[count] = trim(line.substr(0, comma));
    ++count;
    if (comma == std::string_view::npos) return count;
    line.remove_prefix(comma + 1);
  }
}

}  // namespace craneassist::input::detail
