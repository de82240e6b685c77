// The one error type of config loading: it names the file, the line and the field.
#pragma once

#include <stdexcept>
#include <string>

namespace craneassist::config {

class ConfigError : public std::runtime_error {
 public:
  // line is 1-based; 0 when the error is not about one line (e.g. the file cannot be read).
  ConfigError(std::string file, int line, std::string field, std::string reason);

  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  int line_;
  std::string field_;
  std::string reason_;
};

}  // namespace craneassist::config
