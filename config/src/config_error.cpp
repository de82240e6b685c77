#include "craneassist/config/config_error.hpp"

#include <cstddef>
#include <utility>

#include "craneassist/files/error_message.hpp"

namespace craneassist::config {

ConfigError::ConfigError(std::string file, int line, std::string field, std::string reason)
    : std::runtime_error(
          files::error_message(file, line > 0 ? static_cast<std::size_t>(line) : 0, field, reason)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

}  // namespace craneassist::config
