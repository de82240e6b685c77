// The checks of a rejected input file's FileError (craneassist/input/file_error.hpp), shared by
// test_replay.cpp, test_prescribed_path.cpp and test_input_files.cpp.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <string_view>

#include "craneassist/input/file_error.hpp"

namespace craneassist::test {

// Checks the file, the line, the field, that the reason contains reason_part, and the what()
// layout: "FILE:LINE: field 'NAME': REASON", or "FILE:LINE: REASON" without a field.
inline void expect_file_error(const input::FileError& e, std::string_view file, std::size_t line,
                              std::string_view field, std::string_view reason_part) {
  EXPECT_EQ(e.file(), file);
  EXPECT_EQ(e.line(), line);
  EXPECT_EQ(e.field(), field);
  EXPECT_NE(e.reason().find(reason_part), std::string::npos) << e.reason();
  const std::string where = std::string(file) + ":" + std::to_string(line) + ": ";
  const std::string field_part = field.empty() ? "" : "field '" + std::string(field) + "': ";
  EXPECT_EQ(std::string(e.what()), where + field_part + e.reason());
}

}  // namespace craneassist::test
