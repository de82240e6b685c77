#include "craneassist/config/config_error.hpp"

namespace craneassist::config {
namespace {

std::string format_message(const std::string& file, int line, const std::string& field,
                           const std::string& reason) {
  std::string msg;
  msg.append(file);
  if (line > 0) msg.append(":").append(std::to_string(line));
  msg.append(": ");
  if (!field.empty()) msg.append("field '").append(field).append("': ");
  msg.append(reason);
  return msg;
}

}  // namespace

ConfigError::ConfigError(std::string file, int line, std::string field, std::string reason)
    : std::runtime_error(format_message(file, line, field, reason)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)),
      reason_(std::move(reason)) {}

}  // namespace craneassist::config
