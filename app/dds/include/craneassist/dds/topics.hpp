// The DDS topic names and type names of craneassist (docs/telemetry.md).
#pragma once

#include <string_view>

namespace craneassist::dds {

enum class Topic { kStatus, kJoints, kHydraulics, kCommandPath, kOperatorCommand, kBase, kFields };

struct TopicInfo {
  Topic topic;
  std::string_view short_name;  // what `craneassist echo` takes: status, joints, ...
  std::string_view dds_name;    // the DDS topic name
  std::string_view type_name;   // the registered type name (the IDL's)
};

inline constexpr TopicInfo kTopics[] = {
    {Topic::kStatus, "status", "craneassist/status", "craneassist::msg::Status"},
    {Topic::kJoints, "joints", "craneassist/joints", "craneassist::msg::JointState"},
    {Topic::kHydraulics, "hydraulics", "craneassist/hydraulics", "craneassist::msg::Hydraulics"},
    {Topic::kCommandPath, "command_path", "craneassist/command_path",
     "craneassist::msg::CommandPath"},
    {Topic::kOperatorCommand, "operator_command", "craneassist/operator_command",
     "craneassist::msg::OperatorCommand"},
    {Topic::kBase, "base", "craneassist/base", "craneassist::msg::BaseState"},
    {Topic::kFields, "fields", "craneassist/fields", "craneassist::msg::FieldValues"},
};

// The entry of a short or DDS name; nullptr when there is none.
inline const TopicInfo* find_topic(std::string_view name) {
  for (const auto& t : kTopics) {
    if (t.short_name == name || t.dds_name == name) return &t;
  }
  return nullptr;
}

inline const TopicInfo& topic_info(Topic topic) {
  for (const auto& t : kTopics) {
    if (t.topic == topic) return t;
  }
  return kTopics[0];
}

}  // namespace craneassist::dds
