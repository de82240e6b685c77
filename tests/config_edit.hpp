// A shipped crane config with one piece of text replaced, parsed: for tests of config errors
// (file, line, field) and of accepted edits.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/crane_config.hpp"
#include "thrown_error.hpp"

namespace craneassist::test {

inline std::string read_text_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The file's text with, in order, the first occurrence of each edit's `from` replaced by its
// `to` (a failure when a `from` is not there).
inline std::string edited_text(const std::string& path,
                               const std::vector<std::pair<std::string, std::string>>& edits) {
  std::string text = read_text_file(path);
  for (const auto& [from, to] : edits) {
    const auto pos = text.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    if (pos != std::string::npos) text.replace(pos, from.size(), to);
  }
  return text;
}

inline std::string edited_text(const std::string& path, const std::string& from,
                               const std::string& to) {
  return edited_text(path, {{from, to}});
}

// The error parsing the edited file throws (a failure when it parses), as "edited.yaml".
inline config::ConfigError crane_config_error_after_edit(const std::string& path,
                                                         const std::string& from,
                                                         const std::string& to) {
  const std::string text = edited_text(path, from, to);
  return thrown_error<config::ConfigError>(
      [&] { config::parse_crane_config(text, "edited.yaml"); },
      "no error after replacing '" + from + "' with '" + to + "'");
}

}  // namespace craneassist::test
