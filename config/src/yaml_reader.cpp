#include "craneassist/config/yaml_reader.hpp"

#include "craneassist/files/text_file.hpp"

namespace craneassist::config {

std::string read_yaml_file(const std::filesystem::path& path, std::string_view kind) {
  try {
    return files::read_text_file(path, files::kMaxYamlBytes, kind);
  } catch (const files::ReadError& e) {
    throw ConfigError(e.file(), 0, "", e.reason());
  }
}

}  // namespace craneassist::config
