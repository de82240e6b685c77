// Text helpers of the input file formats (csv_reader.hpp and the writers): the common rules of
// docs/replay-format.md for fields, numbers and the file text quoted in messages.
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

}  // namespace craneassist::input::detail
