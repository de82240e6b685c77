#include "craneassist/input/file_error.hpp"

#include <utility>

namespace craneassist::input {
namespace {

// "FILE:LINE: field 'NAME': REASON"; without ":LINE" at line 0, without the field when empty.
std::string format_message(const std::string& file, std::size_t line, const std::string& field,
                           const std::string& reason) {
  std::string msg = file;
  if (line > 0) msg.append(":").append(std::to_string(line));
  msg.append(": ");
  if (!field.empty()) msg.append("field '").append(field).append("': ");
  msg.append(reason);
  return msg;
}

}  // namespace

FileError::FileError(std::string file, std::size_t line, std::string field, std::string reason)
    : std::runtime_error(format_message(file, line, field, reason)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

}  // namespace craneassist::input
