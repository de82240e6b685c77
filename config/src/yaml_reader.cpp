#include "craneassist/config/yaml_reader.hpp"

#include <map>
#include <set>
#include <string>
#include <utility>

#include "craneassist/files/text_file.hpp"

namespace craneassist::config {
namespace {

// Walks every mapping and sequence below `node` once (an alias shares its anchor's node, which
// the visited set, keyed by where the node starts and its type, walks only the first time).
class KeyCheck {
 public:
  explicit KeyCheck(std::string_view source) : source_(source) {}

  void walk(const YAML::Node& node, const std::string& path) {
    if (!node.IsMap() && !node.IsSequence()) return;
    if (!visited_.emplace(node.Mark().pos, static_cast<int>(node.Type())).second) return;
    if (node.IsSequence()) {
      for (std::size_t i = 0; i < node.size(); ++i) {
        walk(node[i], path + "[" + std::to_string(i) + "]");
      }
      return;
    }
    std::map<std::string, int> keys;  // key, its line
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) continue;  // no format has such keys; the readers refuse them
      const std::string& key = kv.first.Scalar();
      const int line = kv.first.Mark().line + 1;
      const std::string field = YamlReader::join(path, key);
      if (const auto [first, added] = keys.emplace(key, line); !added) {
        throw ConfigError(std::string(source_), line, field,
                          "duplicate key (first at line " + std::to_string(first->second) + ")");
      }
      walk(kv.second, field);
    }
  }

 private:
  std::string_view source_;
  std::set<std::pair<int, int>> visited_;  // Mark().pos, Type()
};

}  // namespace

void check_unique_keys(const YAML::Node& root, std::string_view source_name) {
  KeyCheck(source_name).walk(root, "");
}

std::string read_yaml_file(const std::filesystem::path& path, std::string_view kind) {
  try {
    return files::read_text_file(path, files::kMaxYamlBytes, kind);
  } catch (const files::ReadError& e) {
    throw ConfigError(e.file(), 0, "", e.reason());
  }
}

}  // namespace craneassist::config
