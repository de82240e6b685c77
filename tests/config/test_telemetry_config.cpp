// The telemetry settings file (config/telemetry/default.yaml, docs/telemetry.md): the shipped
// defaults, every field read, and errors that name file, line and field. The command input's
// security fields are tested in test_command_input.
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/telemetry_config.hpp"

namespace {

using namespace craneassist::config;

void expect_topic(const TopicSettings& t, double rate_hz, Reliability reliability,
                  Durability durability) {
  EXPECT_DOUBLE_EQ(t.rate_hz, rate_hz);
  EXPECT_EQ(t.reliability, reliability);
  EXPECT_EQ(t.durability, durability);
}

TEST(TelemetryConfig, ShippedDefaults) {
  const TelemetryConfig c = default_telemetry_config();
  EXPECT_TRUE(c.enabled);
  EXPECT_EQ(c.domain_id, 0);
  EXPECT_EQ(c.participant_name, "craneassist");
  EXPECT_EQ(c.transport, DdsTransport::kDefault);
  // The interoperable choice (docs/telemetry.md#interoperability): no TYPE_INFORMATION.
  EXPECT_TRUE(c.type_propagation.type_object);
  EXPECT_FALSE(c.type_propagation.type_information);
  expect_topic(c.status, 10.0, Reliability::kReliable, Durability::kTransientLocal);
  expect_topic(c.joints, 50.0, Reliability::kBestEffort, Durability::kVolatile);
  EXPECT_DOUBLE_EQ(c.hydraulics.rate_hz, 50.0);
  EXPECT_DOUBLE_EQ(c.command_path.rate_hz, 50.0);
  EXPECT_FALSE(c.commands.enabled);
  EXPECT_TRUE(c.commands.security.empty());
  // ROS 2 topics off; when on, ROS 2's default QoS (reliable, volatile) at 50 Hz.
  EXPECT_FALSE(c.ros2.enabled);
  EXPECT_EQ(c.ros2.ros_namespace, "");
  EXPECT_EQ(c.ros2.node_name, "craneassist");
  expect_topic(c.ros2.joint_states, 50.0, Reliability::kReliable, Durability::kVolatile);
  expect_topic(c.ros2.tip_velocity, 50.0, Reliability::kReliable, Durability::kVolatile);
  EXPECT_EQ(c.ros2.dds_topic("joint_states"), "rt/joint_states");
  EXPECT_EQ(c.source_name, "<embedded config/telemetry/default.yaml>");
}

TEST(TelemetryConfig, Ros2Settings) {
  const TelemetryConfig c = parse_telemetry_config(R"(format: craneassist-telemetry/1
ros2:
  enabled: true
  namespace: /site_3/loader7
  node_name: loader_7
  joint_states: {rate: 20 Hz, reliability: best_effort}
  tip_velocity: {rate: 5 Hz, depth: 4}
)",
                                                   "r.yaml");
  EXPECT_TRUE(c.ros2.enabled);
  EXPECT_EQ(c.ros2.dds_topic("joint_states"), "rt/site_3/loader7/joint_states");
  EXPECT_EQ(c.ros2.node_name, "loader_7");
  expect_topic(c.ros2.joint_states, 20.0, Reliability::kBestEffort, Durability::kVolatile);
  expect_topic(c.ros2.tip_velocity, 5.0, Reliability::kReliable, Durability::kVolatile);
  EXPECT_EQ(c.ros2.tip_velocity.depth, 4);
}

TEST(TelemetryConfig, Ros2NamespaceRules) {
  for (const char* good : {"", "/a", "/crane1", "/_x/y_2/Z"}) {
    EXPECT_EQ(ros_namespace_error(good), "") << good;
  }
  const std::pair<const char*, const char*> bad[] = {{"crane1", "start with '/'"},
                                                     {"/crane1/", "end with '/'"},
                                                     {"/", "end with '/'"},
                                                     {"/a//b", "empty segment"},
                                                     {"/a b", "letters, digits"},
                                                     {"/kran-1", "letters, digits"},
                                                     {"/1crane", "may not start with a digit"},
                                                     {"/a/2b", "may not start with a digit"}};
  for (const auto& [text, why] : bad) {
    EXPECT_NE(ros_namespace_error(text).find(why), std::string::npos)
        << text << ": " << ros_namespace_error(text);
  }
}

TEST(TelemetryConfig, EveryFieldIsRead) {
  const TelemetryConfig c = parse_telemetry_config(R"(format: craneassist-telemetry/1
enabled: false
domain_id: 42
participant_name: loader-7
transport: udp
type_propagation: {type_object: false, type_information: true}
topics:
  status: {rate: 2 Hz, reliability: best_effort, durability: volatile, depth: 3}
  joints: {rate: 100 Hz, reliability: reliable, durability: transient_local, depth: 10}
  hydraulics: {rate: 0.5 Hz}
commands:
  reliability: reliable
  depth: 4
)",
                                                   "t.yaml");
  EXPECT_FALSE(c.enabled);
  EXPECT_EQ(c.domain_id, 42);
  EXPECT_EQ(c.participant_name, "loader-7");
  EXPECT_EQ(c.transport, DdsTransport::kUdp);
  EXPECT_FALSE(c.type_propagation.type_object);
  EXPECT_TRUE(c.type_propagation.type_information);
  expect_topic(c.status, 2.0, Reliability::kBestEffort, Durability::kVolatile);
  EXPECT_EQ(c.status.depth, 3);
  expect_topic(c.joints, 100.0, Reliability::kReliable, Durability::kTransientLocal);
  EXPECT_EQ(c.joints.depth, 10);
  EXPECT_DOUBLE_EQ(c.hydraulics.rate_hz, 0.5);
  EXPECT_EQ(c.hydraulics.reliability, Reliability::kBestEffort);  // default kept
  EXPECT_DOUBLE_EQ(c.command_path.rate_hz, 50.0);                 // not given: default
  EXPECT_EQ(c.commands.topic.reliability, Reliability::kReliable);
  EXPECT_EQ(c.commands.topic.depth, 4);
}

// Each bad value: the error names the file, the line and the field.
void expect_error(const std::string& yaml, int line, const std::string& field,
                  const std::string& reason_part) {
  try {
    parse_telemetry_config("format: craneassist-telemetry/1\n" + yaml, "bad.yaml");
    FAIL() << "accepted: " << yaml;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "bad.yaml");
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(e.reason().find(reason_part), std::string::npos) << e.what();
  }
}

TEST(TelemetryConfig, ErrorsNameFileLineAndField) {
  expect_error("domain_id: 300\n", 2, "domain_id", "0..232");
  expect_error("domain_id: one\n", 2, "domain_id", "whole number");
  expect_error("transport: carrier-pigeon\n", 2, "transport", "expected one of: default, udp, shm");
  expect_error("topics:\n  joints:\n    rate: 50 L/min\n", 4, "topics.joints.rate",
               "not a frequency unit");
  expect_error("topics:\n  joints:\n    rate: 0 Hz\n", 4, "topics.joints.rate", "(0, 1000]");
  expect_error("topics:\n  joints:\n    reliability: sometimes\n", 4, "topics.joints.reliability",
               "best_effort, reliable");
  expect_error("topics:\n  status:\n    depth: 0\n", 4, "topics.status.depth", "1..1000");
  expect_error("topics:\n  jionts:\n    depth: 1\n", 3, "topics.jionts", "unknown field");
  expect_error("enabled: yes\n", 2, "enabled", "true or false");
  expect_error("type_propagation:\n  type_information: maybe\n", 3,
               "type_propagation.type_information", "true or false");
  expect_error("type_propagation:\n  type_objects: true\n", 3, "type_propagation.type_objects",
               "unknown field (expected one of: type_object, type_information)");
  expect_error("type_propagation: none\n", 2, "type_propagation", "expected a mapping");
  expect_error("domian_id: 3\n", 2, "domian_id", "unknown field");
  expect_error("ros2:\n  namespace: crane1\n", 3, "ros2.namespace", "must start with '/'");
  expect_error("ros2:\n  enabled: on\n", 3, "ros2.enabled", "true or false");
  expect_error("ros2:\n  node_name: crane-1\n", 3, "ros2.node_name", "letters, digits and '_'");
  expect_error("ros2:\n  node_name: 7crane\n", 3, "ros2.node_name", "not start with a digit");
  expect_error("ros2:\n  node_name: \"\"\n", 3, "ros2.node_name", "must not be empty");
  expect_error("ros2:\n  joint_states:\n    rate: 2000 Hz\n", 4, "ros2.joint_states.rate",
               "(0, 1000]");
  expect_error("ros2:\n  jointstates: {}\n", 3, "ros2.jointstates", "unknown field");
  expect_error("domain_id: 3\ndomain_id: 4\n", 3, "domain_id", "duplicate key (first at line 2)");
  expect_error("topics:\n  joints:\n    rate: 50 Hz\n    depth: 2\n    rate: 5 Hz\n", 6,
               "topics.joints.rate", "duplicate key (first at line 4)");
  try {
    parse_telemetry_config("format: craneassist-telemetry/9\n", "v.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.field(), "format");
  }
}

TEST(TelemetryConfig, MissingFileIsAnError) {
  try {
    load_telemetry_config("/nonexistent/telemetry.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/telemetry.yaml");
    EXPECT_EQ(std::string(e.what()), "/nonexistent/telemetry.yaml: file not found");
  }
}

}  // namespace
