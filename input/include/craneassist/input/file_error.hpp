// The one error type of the input file formats (replays, prescribed paths, joint trajectories;
// docs/replay-format.md, docs/path-format.md, docs/trajectory-format.md): a file that was
// rejected, with the file, the line and the field at fault.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace craneassist::input {

// what() is "FILE:LINE: field 'NAME': REASON", or "FILE:LINE: REASON" when the problem is not tied
// to one field. LINE is 1-based and counts every line of the file; 0 means the file could not be
// read (or is over its size limit), and what() is then "FILE: REASON", as config::ConfigError's.
class FileError : public std::runtime_error {
 public:
  FileError(std::string file, std::size_t line, std::string field, std::string reason);

  const std::string& file() const noexcept { return file_; }
  std::size_t line() const noexcept { return line_; }
  // Column name (e.g. "t", "v_x", "q_2"), or empty when the error concerns no single field.
  const std::string& field() const noexcept { return field_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string field_;
  std::string reason_;
};

}  // namespace craneassist::input
