#include "craneassist/input/file_error.hpp"

#include <utility>

#include "craneassist/files/error_message.hpp"

namespace craneassist::input {

FileError::FileError(std::string file, std::size_t line, std::string field, std::string reason)
    : std::runtime_error(files::error_message(file, line, field, reason)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

}  // namespace craneassist::input
