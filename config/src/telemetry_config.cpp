#include "craneassist/config/telemetry_config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "craneassist/config/quantity.hpp"
#include "craneassist/config/yaml_reader.hpp"
#include "embedded_configs.hpp"

namespace craneassist::config {
namespace {

constexpr const char* kFormat = "craneassist-telemetry/1";

class Reader : public YamlReader {
 public:
  Reader(std::string file, std::filesystem::path base_dir)
      : YamlReader(std::move(file)), base_dir_(std::move(base_dir)) {}

  int integer(const YAML::Node& map, const std::string& key, const std::string& path, int lo,
              int hi, int fallback) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) return fallback;
    const std::string field = join(path, key);
    if (!node.IsScalar()) fail(node, field, "expected a whole number");
    const std::string& s = node.Scalar();
    std::size_t used = 0;
    long v = 0;
    try {
      v = std::stol(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size())
      fail(node, field, "expected a whole number, got '" + s + "'");
    if (v < lo || v > hi) {
      fail(node, field, "must be in " + std::to_string(lo) + ".." + std::to_string(hi));
    }
    return static_cast<int>(v);
  }

  double rate(const YAML::Node& map, const std::string& key, const std::string& path,
              double fallback) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) return fallback;
    const std::string field = join(path, key);
    if (!node.IsScalar()) fail(node, field, "expected a rate, e.g. 50 Hz");
    std::string error;
    const auto q = parse_quantity(node.Scalar(), Dimension::kFrequency, error);
    if (!q) fail(node, field, error);
    if (q->si_values.size() != 1) fail(node, field, "expected one value");
    const double v = q->si_values[0];
    if (!(v > 0.0 && v <= 1000.0)) fail(node, field, "must be in (0, 1000] Hz");
    return v;
  }

  // One of the values, by its to_string() name.
  template <typename Enum, std::size_t N>
  Enum choice(const YAML::Node& map, const std::string& key, const std::string& path,
              const std::array<Enum, N>& values, Enum fallback) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined() || node.IsNull()) return fallback;
    const std::string field = join(path, key);
    if (!node.IsScalar()) fail(node, field, "expected a single value");
    if (const auto value = parse_name(values, node.Scalar())) return *value;
    std::string list;
    for (const std::string& name : names_of(values)) list += (list.empty() ? "" : ", ") + name;
    fail(node, field, "unknown value '" + node.Scalar() + "' (expected one of: " + list + ")");
  }

  // A file path relative to the config file's folder; must exist when given.
  std::string file_path(const YAML::Node& map, const std::string& key,
                        const std::string& path) const {
    std::string p = optional_text(map, key, path);
    if (p.empty()) return p;
    std::filesystem::path full(p);
    if (full.is_relative() && !base_dir_.empty()) full = base_dir_ / full;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(full, ec)) {
      fail(map[key], join(path, key), "no such file: " + full.string());
    }
    return full.string();
  }

 private:
  std::filesystem::path base_dir_;
};

TopicSettings read_topic(const Reader& r, const YAML::Node& node, const std::string& path,
                         TopicSettings t, bool with_rate) {
  if (with_rate) {
    r.check_keys(node, path, {"rate", "reliability", "durability", "depth"});
    t.rate_hz = r.rate(node, "rate", path, t.rate_hz);
    t.durability = r.choice(node, "durability", path, kDurabilities, t.durability);
  }
  t.reliability = r.choice(node, "reliability", path, kReliabilities, t.reliability);
  t.depth = r.integer(node, "depth", path, 1, 1000, t.depth);
  return t;
}

TelemetryConfig read_config(const Reader& r, const YAML::Node& root, std::string_view source) {
  TelemetryConfig c;
  c.source_name = std::string(source);
  r.check_keys(root, "",
               {"format", "enabled", "domain_id", "participant_name", "transport",
                "type_propagation", "topics", "commands", "ros2"});
  const YAML::Node format = r.child(root, "format", "");
  if (!format.IsScalar() || format.Scalar() != kFormat) {
    r.fail(format, "format", std::string("expected ") + kFormat);
  }
  c.enabled = r.flag(root, "enabled", "", c.enabled);
  c.domain_id = r.integer(root, "domain_id", "", 0, 232, c.domain_id);
  if (const std::string name = r.optional_text(root, "participant_name", ""); !name.empty()) {
    c.participant_name = name;
  }
  c.transport = r.choice(root, "transport", "", kDdsTransports, c.transport);
  if (const YAML::Node tp = root["type_propagation"]; tp.IsDefined() && !tp.IsNull()) {
    r.check_keys(tp, "type_propagation", {"type_object", "type_information"});
    c.type_propagation.type_object =
        r.flag(tp, "type_object", "type_propagation", c.type_propagation.type_object);
    c.type_propagation.type_information =
        r.flag(tp, "type_information", "type_propagation", c.type_propagation.type_information);
  }
  if (const YAML::Node topics = root["topics"]; topics.IsDefined() && !topics.IsNull()) {
    r.check_keys(topics, "topics", {"status", "joints", "hydraulics", "command_path"});
    const std::pair<const char*, TopicSettings*> all[] = {{"status", &c.status},
                                                          {"joints", &c.joints},
                                                          {"hydraulics", &c.hydraulics},
                                                          {"command_path", &c.command_path}};
    for (const auto& [name, settings] : all) {
      const YAML::Node t = topics[name];
      if (t.IsDefined() && !t.IsNull()) {
        *settings = read_topic(r, t, Reader::join("topics", name), *settings, true);
      }
    }
  }
  if (const YAML::Node cmd = root["commands"]; cmd.IsDefined() && !cmd.IsNull()) {
    r.check_keys(cmd, "commands", {"enabled", "reliability", "depth", "security"});
    c.commands.enabled = r.flag(cmd, "enabled", "commands", false);
    c.commands.topic = read_topic(r, cmd, "commands", c.commands.topic, false);
    if (const YAML::Node sec = cmd["security"]; sec.IsDefined() && !sec.IsNull()) {
      const std::string p = "commands.security";
      r.check_keys(sec, p,
                   {"identity_ca", "identity_certificate", "private_key", "permissions_ca",
                    "governance", "permissions"});
      auto& s = c.commands.security;
      s.identity_ca = r.file_path(sec, "identity_ca", p);
      s.identity_certificate = r.file_path(sec, "identity_certificate", p);
      s.private_key = r.file_path(sec, "private_key", p);
      s.permissions_ca = r.file_path(sec, "permissions_ca", p);
      s.governance = r.file_path(sec, "governance", p);
      s.permissions = r.file_path(sec, "permissions", p);
      if (!s.empty() && !s.complete()) {
        r.fail(sec, p,
               "give every file (identity_ca, identity_certificate, private_key, "
               "permissions_ca, governance, permissions) or none; missing: " +
                   s.missing() + " (docs/remote-commands.md)");
      }
    }
    if (c.commands.enabled && !c.commands.security.complete()) {
      r.fail(cmd["enabled"], "commands.enabled",
             "the DDS command input needs DDS Security: give every file of commands.security "
             "(docs/remote-commands.md)");
    }
  }
  if (const YAML::Node ros = root["ros2"]; ros.IsDefined() && !ros.IsNull()) {
    r.check_keys(ros, "ros2",
                 {"enabled", "namespace", "node_name", "joint_states", "tip_velocity"});
    c.ros2.enabled = r.flag(ros, "enabled", "ros2", c.ros2.enabled);
    c.ros2.ros_namespace = r.optional_text(ros, "namespace", "ros2");
    if (const std::string why = ros_namespace_error(c.ros2.ros_namespace); !why.empty()) {
      r.fail(ros["namespace"], "ros2.namespace", why);
    }
    if (ros["node_name"].IsDefined()) {
      c.ros2.node_name = r.text(ros, "node_name", "ros2");
      if (const std::string why = ros_node_name_error(c.ros2.node_name); !why.empty()) {
        r.fail(ros["node_name"], "ros2.node_name", why);
      }
    }
    const std::pair<const char*, TopicSettings*> all[] = {{"joint_states", &c.ros2.joint_states},
                                                          {"tip_velocity", &c.ros2.tip_velocity}};
    for (const auto& [name, settings] : all) {
      const YAML::Node t = ros[name];
      if (t.IsDefined() && !t.IsNull()) {
        *settings = read_topic(r, t, Reader::join("ros2", name), *settings, true);
      }
    }
  }
  return c;
}

}  // namespace

namespace {

bool is_digit(char ch) {
  return ch >= '0' && ch <= '9';
}

// A character of a ROS 2 name (a node name, a namespace's segment): an ASCII letter, digit or '_'.
bool is_ros_name_char(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || is_digit(ch) || ch == '_';
}

}  // namespace

std::string ros_node_name_error(std::string_view text) {
  const std::string hint = " (e.g. craneassist or crane_1)";
  if (text.empty()) return "must not be empty" + hint;
  if (is_digit(text.front())) return "must not start with a digit" + hint;
  if (!std::all_of(text.begin(), text.end(), is_ros_name_char)) {
    return "may hold only letters, digits and '_'" + hint;
  }
  return "";
}

std::string ros_namespace_error(std::string_view text) {
  if (text.empty()) return "";
  const std::string hint = " (e.g. /crane1; \"\" for none)";
  if (text.front() != '/') return "must start with '/'" + hint;
  if (text.back() == '/') return "must not end with '/'" + hint;
  bool segment_start = true;
  for (std::size_t i = 1; i < text.size(); ++i) {
    const char ch = text[i];
    if (ch == '/') {
      if (segment_start) return "has an empty segment ('//')" + hint;
      segment_start = true;
      continue;
    }
    if (!is_ros_name_char(ch)) return "may hold only letters, digits, '_' and '/'" + hint;
    if (segment_start && is_digit(ch)) return "a segment may not start with a digit" + hint;
    segment_start = false;
  }
  return "";
}

const char* to_string(Reliability r) {
  return r == Reliability::kReliable ? "reliable" : "best_effort";
}
const char* to_string(Durability d) {
  return d == Durability::kTransientLocal ? "transient_local" : "volatile";
}
const char* to_string(DdsTransport t) {
  switch (t) {
    case DdsTransport::kUdp:
      return "udp";
    case DdsTransport::kShm:
      return "shm";
    case DdsTransport::kDefault:
      break;
  }
  return "default";
}

TelemetryConfig parse_telemetry_config(std::string_view yaml_text, std::string_view source_name,
                                       const std::filesystem::path& base_dir) {
  const Reader reader{std::string(source_name), base_dir};
  return read_yaml(yaml_text, source_name,
                   [&](const YAML::Node& root) { return read_config(reader, root, source_name); });
}

TelemetryConfig load_telemetry_config(const std::filesystem::path& path) {
  return parse_telemetry_config(read_yaml_file(path, "telemetry config"), path.string(),
                                path.parent_path());
}

TelemetryConfig default_telemetry_config() {
  return parse_telemetry_config(embedded::kTelemetryYaml,
                                "<embedded config/telemetry/default.yaml>");
}

}  // namespace craneassist::config
