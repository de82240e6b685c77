// The DDS settings (config/telemetry/default.yaml, docs/telemetry.md): domain, transport, each
// telemetry topic's rate and QoS, and the DDS command input with its DDS Security files.
// Strict reader: unknown fields, unknown QoS names and out-of-range values are errors naming
// file, line and field.
//
// This header is plain C++17 (no Eigen, no yaml-cpp): the DDS module, compiled as C++17 because
// Debian's Fast CDR 1.0 headers do not compile as C++20, includes it.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "craneassist/dynamics/enum_names.hpp"

namespace craneassist::config {

enum class Reliability { kBestEffort, kReliable };
inline constexpr std::array kReliabilities{Reliability::kBestEffort, Reliability::kReliable};
const char* to_string(Reliability r);  // "best_effort", "reliable"
inline std::optional<Reliability> parse_reliability(std::string_view text) {
  return parse_name(kReliabilities, text);
}

enum class Durability { kVolatile, kTransientLocal };
inline constexpr std::array kDurabilities{Durability::kVolatile, Durability::kTransientLocal};
const char* to_string(Durability d);  // "volatile", "transient_local"
inline std::optional<Durability> parse_durability(std::string_view text) {
  return parse_name(kDurabilities, text);
}

enum class DdsTransport { kDefault, kUdp, kShm };
inline constexpr std::array kDdsTransports{DdsTransport::kDefault, DdsTransport::kUdp,
                                           DdsTransport::kShm};
const char* to_string(DdsTransport t);  // "default", "udp", "shm"
inline std::optional<DdsTransport> parse_dds_transport(std::string_view text) {
  return parse_name(kDdsTransports, text);
}

struct TopicSettings {
  double rate_hz = 50.0;  // published at most this often (the loop runs at the control rate)
  Reliability reliability = Reliability::kBestEffort;
  Durability durability = Durability::kVolatile;
  int depth = 1;  // KEEP_LAST history depth
};

// The DDS Security files of a participant (docs/remote-commands.md). Paths are
// resolved against the config file's folder. All empty: no security.
struct SecurityFiles {
  std::string identity_ca;           // CA certificate that signed every identity (PEM)
  std::string identity_certificate;  // this participant's certificate (PEM)
  std::string private_key;           // its private key (PEM)
  std::string permissions_ca;        // CA certificate that signed governance and permissions
  std::string governance;            // signed governance document (S/MIME, .p7s)
  std::string permissions;           // signed permissions document (S/MIME, .p7s)
  // The six files with their field names, in the settings file's order.
  std::array<std::pair<const char*, const std::string*>, 6> files() const {
    return {{{"identity_ca", &identity_ca},
             {"identity_certificate", &identity_certificate},
             {"private_key", &private_key},
             {"permissions_ca", &permissions_ca},
             {"governance", &governance},
             {"permissions", &permissions}}};
  }
  bool empty() const { return missing_count() == 6; }
  bool complete() const { return missing_count() == 0; }
  // The field names of the files not given, comma-separated, each after prefix ("" when every
  // file is given).
  std::string missing(const char* prefix = "") const {
    std::string names;
    for (const auto& [name, path] : files()) {
      if (path->empty()) names += (names.empty() ? "" : ", ") + std::string(prefix) + name;
    }
    return names;
  }

 private:
  int missing_count() const {
    int n = 0;
    for (const auto& file : files()) n += file.second->empty();
    return n;
  }
};

struct CommandInputSettings {
  // Off by default. When on, the command input needs DDS Security (every file of `security`):
  // a participant without valid credentials cannot command the crane.
  bool enabled = false;
  TopicSettings topic{0.0, Reliability::kBestEffort, Durability::kVolatile, 1};
  SecurityFiles security;
};

// What a participant announces about its types in discovery (docs/telemetry.md#interoperability).
// Every craneassist participant (telemetry, the command input, echo, dashboard, remote) uses the
// same. The default is the interoperable one: Fast DDS 2.9's XTypes TYPE_INFORMATION record is
// rejected as invalid by other DDS implementations (Eclipse Cyclone DDS), whose endpoints then
// never match craneassist's.
struct TypePropagation {
  // The type object (the legacy TYPE_OBJECT and TYPE_ID parameters of the endpoint's discovery
  // data): Fast DDS 2.x's dynamic-type readers build the type from it. Other implementations
  // ignore it.
  bool type_object = true;
  // XTypes 1.3 TYPE_INFORMATION, with Fast DDS's TypeLookup service behind it. Off: Cyclone DDS
  // and other implementations reject Fast DDS 2.9's record as invalid and match nothing.
  bool type_information = false;
};

// The standard ROS 2 topics beside craneassist's own (docs/ros.md): ROS 2's naming on the wire
// (topic "rt/<namespace>/joint_states", type "sensor_msgs::msg::dds_::JointState_"), so RViz,
// Foxglove, PlotJuggler and `ros2 topic echo` read them without a bridge.
struct Ros2Settings {
  bool enabled = false;
  // The ROS 2 namespace of the topics: "" or "/name[/name...]" (ROS name characters).
  std::string ros_namespace;
  // The node ROS 2 sees the topics belong to (`ros2 node list`: <namespace>/<node_name>), named
  // on the graph's ros_discovery_info topic: letters, digits and '_', not starting with a digit.
  std::string node_name = "craneassist";
  // /joint_states: sensor_msgs/msg/JointState, the joints by their URDF names.
  TopicSettings joint_states{50.0, Reliability::kReliable, Durability::kVolatile, 1};
  // /craneassist/tip_velocity/command and .../reference: geometry_msgs/msg/TwistStamped in
  // base_link (the URDF's root).
  TopicSettings tip_velocity{50.0, Reliability::kReliable, Durability::kVolatile, 1};

  // The DDS topic name of a ROS 2 topic name under the namespace: "rt" + namespace + "/" + name.
  std::string dds_topic(std::string_view ros_name) const {
    return "rt" + ros_namespace + "/" + std::string(ros_name);
  }
};

// Why `text` is not a ROS 2 node name (letters, digits and '_', not empty, not starting with a
// digit); "" when it is one.
std::string ros_node_name_error(std::string_view text);

// Why `text` is not a ROS 2 namespace ("" or "/a/b" from letters, digits and '_', no segment
// starting with a digit, no empty segment, no trailing '/'); "" when it is one.
std::string ros_namespace_error(std::string_view text);

struct TelemetryConfig {
  bool enabled = true;  // telemetry publishing (open, unauthenticated: read-only data)
  int domain_id = 0;
  std::string participant_name = "craneassist";
  DdsTransport transport = DdsTransport::kDefault;
  TypePropagation type_propagation;
  TopicSettings status{10.0, Reliability::kReliable, Durability::kTransientLocal, 1};
  TopicSettings joints{50.0, Reliability::kBestEffort, Durability::kVolatile, 1};
  TopicSettings hydraulics{50.0, Reliability::kBestEffort, Durability::kVolatile, 1};
  TopicSettings command_path{50.0, Reliability::kBestEffort, Durability::kVolatile, 1};
  CommandInputSettings commands;
  Ros2Settings ros2;
  std::string source_name;  // file the settings came from, or "<embedded ...>"
};

// Both throw ConfigError.
TelemetryConfig load_telemetry_config(const std::filesystem::path& path);
TelemetryConfig parse_telemetry_config(std::string_view yaml_text, std::string_view source_name,
                                       const std::filesystem::path& base_dir = {});

// The shipped default, embedded (config/telemetry/default.yaml).
TelemetryConfig default_telemetry_config();

}  // namespace craneassist::config
