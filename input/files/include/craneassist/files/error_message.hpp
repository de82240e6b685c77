// The one layout of an error in a file the user gave: "FILE:LINE: field 'NAME': REASON", without
// ":LINE" at line 0 (the whole file) and without the field when it is empty. Shared by
// config::ConfigError and input::FileError.
#pragma once

#include <cstddef>
#include <string>

namespace craneassist::files {

std::string error_message(const std::string& file, std::size_t line, const std::string& field,
                          const std::string& reason);

}  // namespace craneassist::files
