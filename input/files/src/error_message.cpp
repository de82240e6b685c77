#include "craneassist/files/error_message.hpp"

namespace craneassist::files {

std::string error_message(const std::string& file, std::size_t line, const std::string& field,
                          const std::string& reason) {
  std::string msg = file;
  if (line > 0) msg.append(":").append(std::to_string(line));
  msg.append(": ");
  if (!field.empty()) msg.append("field '").append(field).append("': ");
  msg.append(reason);
  return msg;
}

}  // namespace craneassist::files
