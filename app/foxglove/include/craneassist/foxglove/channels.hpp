// The channels craneassist offers Foxglove, PlotJuggler and other robotics tools, live over the
// Foxglove WebSocket protocol (`--foxglove`) and recorded in MCAP files (`--mcap`): the same
// channels and the same message bytes in both (docs/foxglove.md).
//
//   /robot_description              std_msgs/msg/String (cdr): the URDF of `craneassist urdf`,
//                                   once (latched)
//   /joint_states                   sensor_msgs/msg/JointState (cdr): the crane's joints, then
//                                   the hanger's when the grapple hangs
//   /tf                             tf2_msgs/msg/TFMessage (cdr): every URDF joint's transform,
//                                   what robot_state_publisher would send, so the 3-D panel
//                                   moves the URDF without it
//   /craneassist/tip_velocity/command, .../reference
//                                   geometry_msgs/msg/TwistStamped (cdr), frame base_link
//   /craneassist/<group>            JSON with a JSON Schema: every value of the field table
//                                   (control/log_fields.hpp) in its group (status, command,
//                                   joints, hydraulics, limits, polytope, loads; base with
//                                   sim --drive)
//
// Message times: machine time (a run that is not real time: log time 0 is the run's start), or
// the wall clock at the run's start plus machine time (a real-time run).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/log_fields.hpp"
#include "craneassist/dynamics/model.hpp"
#include "craneassist/dynamics/urdf.hpp"

namespace craneassist::foxglove {

struct Channel {
  std::string topic;
  std::string message_encoding;  // cdr, json
  std::string schema_name;       // sensor_msgs/msg/JointState, craneassist/status
  std::string schema_encoding;   // ros2msg, jsonschema
  std::string schema;            // the schema's text
  bool latched = false;          // sent once (at the start, or to each new subscriber)
};

// The ROS 2 message definitions of the cdr channels, as Foxglove's ros2msg schemas (the message,
// then each dependency after a line of '=' and "MSG: pkg/Name"), from ROS 2 Jazzy's .msg files.
extern const char* const kJointStateSchema;
extern const char* const kTfMessageSchema;
extern const char* const kTwistStampedSchema;
extern const char* const kStringSchema;

class ChannelSet {
 public:
  // The channels for this crane (with the base's JSON channel when `base`).
  ChannelSet(const dynamics::CraneModel& model, bool base);

  const std::vector<Channel>& channels() const noexcept { return channels_; }
  std::size_t size() const noexcept { return channels_.size(); }

  // Channel k's message for one cycle's row, stamped stamp_ns (header stamps), into out (its
  // bytes replaced). The latched /robot_description gives the URDF whatever the row.
  void encode(std::size_t k, const control::LogRow& row, std::int64_t stamp_ns,
              std::vector<std::uint8_t>& out);

 private:
  enum class Kind { kRobotDescription, kJointStates, kTf, kCommand, kReference, kGroup };
  const dynamics::CraneModel& model_;
  int dof_;
  std::vector<Channel> channels_;
  std::vector<Kind> kinds_;
  std::vector<control::FieldGroup> groups_;  // per channel (kGroup only)
  std::string urdf_;
  std::vector<std::string> joint_names_;  // the crane's, then the hanger's
  std::vector<dynamics::UrdfFrame> frames_;
  dynamics::HangerAxes hanger_axes_;
  std::vector<Eigen::Isometry3d> transforms_;
  Eigen::Matrix3d base_from_crane_;
  std::string json_;
};

}  // namespace craneassist::foxglove
