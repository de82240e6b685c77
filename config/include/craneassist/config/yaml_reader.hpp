// The checks every craneassist YAML file shares (crane configs, CAN mappings): fail with file,
// line and field; reject duplicate and unknown keys; require a child. Readers of a file format
// derive from it and add their own value conversions. Needs yaml-cpp in the including target.
#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "craneassist/config/config_error.hpp"
#include "craneassist/dynamics/enum_names.hpp"

namespace craneassist::config {

class YamlReader {
 public:
  explicit YamlReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field,
                         const std::string& reason) const {
    const int line = node.IsDefined() ? node.Mark().line + 1 : 0;
    throw ConfigError(file_, line, field, reason);
  }

  // Rejects keys that are not in `allowed` (catches typos such as "bor:").
  void check_keys(const YAML::Node& map, const std::string& path,
                  std::initializer_list<const char*> allowed) const {
    if (!map.IsMap()) fail(map, path, "expected a mapping of fields");
    for (const auto& kv : map) {
      const auto key = kv.first.as<std::string>();
      bool ok = false;
      std::string list;
      for (const char* a : allowed) {
        ok = ok || key == a;
        list += list.empty() ? a : std::string(", ") + a;
      }
      if (!ok) fail(kv.first, join(path, key), "unknown field (expected one of: " + list + ")");
    }
  }

  // An optional section: its node when the file gives it (a mapping with only `allowed` fields),
  // nothing when it is left out or null.
  std::optional<YAML::Node> optional_section(const YAML::Node& map, const std::string& key,
                                             const std::string& path,
                                             std::initializer_list<const char*> allowed) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) return std::nullopt;
    check_keys(node, join(path, key), allowed);
    return node;
  }

  YAML::Node child(const YAML::Node& map, const std::string& key, const std::string& path) const {
    if (!map.IsMap()) fail(map, path, "expected a mapping of fields");
    YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) fail(map, join(path, key), "missing");
    return node;
  }

  // A required single value.
  std::string text(const YAML::Node& map, const std::string& key, const std::string& path) const {
    const YAML::Node node = child(map, key, path);
    if (!node.IsScalar()) fail(node, join(path, key), "expected a single value");
    return node.Scalar();
  }

  // An optional single value ("" when absent or empty).
  std::string optional_text(const YAML::Node& map, const std::string& key,
                            const std::string& path) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) return "";
    if (!node.IsScalar()) fail(node, join(path, key), "expected a single value");
    return node.Scalar();
  }

  // true or false; fallback when the key is absent. Else a failure "expected true or false"
  // (", got 'X'" for a single value).
  bool flag(const YAML::Node& map, const std::string& key, const std::string& path,
            bool fallback) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined()) return fallback;
    if (node.IsScalar() && (node.Scalar() == "true" || node.Scalar() == "false")) {
      return node.Scalar() == "true";
    }
    fail(node, join(path, key),
         node.IsScalar() ? "expected true or false, got '" + node.Scalar() + "'"
                         : std::string("expected true or false"));
  }

  // One of `values` by its name (required); else a failure "expected A, B or C, got 'X'".
  template <typename Enum, std::size_t N>
  Enum one_of(const YAML::Node& map, const std::string& key, const std::string& path,
              const std::array<Enum, N>& values) const {
    const std::string name = text(map, key, path);
    if (const auto value = parse_name(values, name)) return *value;
    fail(map[key], join(path, key), "expected " + alternatives(values) + ", got '" + name + "'");
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// Throws ConfigError at the second of two equal keys in one mapping, anywhere in the tree
// ("file:12: field 'control.rate': duplicate key (first at line 9)"): yaml-cpp keeps both, and a
// lookup would silently take the first. Each node is visited once, so aliases cost nothing.
void check_unique_keys(const YAML::Node& root, std::string_view source_name);

// Parses YAML text, checks that no mapping repeats a key, and reads it with read(root): a syntax
// error, a duplicate key, or a conversion yaml-cpp refuses inside read, becomes a ConfigError
// naming the source and the line.
template <typename Read>
auto read_yaml(std::string_view yaml_text, std::string_view source_name, Read&& read)
    -> decltype(read(std::declval<const YAML::Node&>())) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::ParserException& e) {
    throw ConfigError(std::string(source_name), e.mark.line + 1, "", "YAML syntax: " + e.msg);
  }
  check_unique_keys(root, source_name);
  try {
    return read(root);
  } catch (const YAML::Exception& e) {  // a conversion yaml-cpp refused; report where
    throw ConfigError(std::string(source_name), e.mark.line + 1, "", e.msg);
  }
}

// A YAML file's text, at most files::kMaxYamlBytes (1 MiB) of it: the bounded read of
// craneassist/files/text_file.hpp. ConfigError naming the file (line 0) when it cannot be read or
// is larger; `kind` names the file in that message ("crane config": "FILE: larger than 1 MiB (the
// limit for crane config files)").
std::string read_yaml_file(const std::filesystem::path& path, std::string_view kind);

}  // namespace craneassist::config
