#include "text_fields.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

namespace craneassist::input::detail {

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::string quoted(std::string_view s) {
  constexpr std::size_t kMaxShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < kMaxShown; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      constexpr std::string_view kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    }
  }
  if (s.size() > kMaxShown) out += "...";
  out += '\'';
  return out;
}

std::string_view format_number(double value, std::array<char, kMaxNumberChars>& buffer) {
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return {buffer.data(), static_cast<std::size_t>(result.ptr - buffer.data())};
}

std::string number(double value) {
  std::array<char, kMaxNumberChars> buffer{};
  return std::string(format_number(value, buffer));
}

bool parse_number(std::string_view text, double& value, std::string& reason) {
  if (text.empty()) {
    reason = "missing value";
    return false;
  }
  const char* const last = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), last, value);
  if (ec == std::errc::invalid_argument || ptr != last) {
    reason = "not a number: " + quoted(text);
    return false;
  }
  if (ec == std::errc::result_out_of_range) {
    reason = "number out of range: " + quoted(text);
    return false;
  }
  if (!std::isfinite(value)) {
    reason = "not a finite number: " + quoted(text);
    return false;
  }
  return true;
}

}  // namespace craneassist::input::detail
