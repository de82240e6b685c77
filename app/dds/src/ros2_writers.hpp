// The standard ROS 2 topics of the telemetry (config ros2, docs/ros.md), internal to the dds
// module: sensor_msgs/msg/JointState on <ns>/joint_states and geometry_msgs/msg/TwistStamped on
// <ns>/craneassist/tip_velocity/{command,reference}, named as ROS 2 names them on the wire
// ("rt/..." topics, "...::msg::dds_::..._" types). Runs on the publisher thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/telemetry_frame.hpp"
#include "ros2_msgs.h"
#include "topic_pacer.hpp"

namespace craneassist::dds {

// The RIHS01 type hashes of the ROS 2 (Jazzy) types craneassist publishes, as rosidl computes
// them: ROS 2 Iron and later read them from each endpoint's USER_DATA (`typehash=...;`).
// tests/interop/ros2_type_hash.py computes them from ROS 2's .msg files and checks them against
// published values (docs/ros.md).
inline constexpr const char* kJointStateTypeHash =
    "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e";
inline constexpr const char* kTwistStampedTypeHash =
    "RIHS01_5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64";
inline constexpr const char* kParticipantEntitiesInfoTypeHash =
    "RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e";

// Registers the ROS 2 types on the participant (as `propagation` says).
void register_ros2_types(eprosima::fastdds::dds::DomainParticipant& p,
                         const config::TypePropagation& propagation);

class Ros2Writers {
 public:
  static constexpr int kTopics = 3;  // joint_states, tip velocity command, tip velocity reference

  // Creates the topics and writers; throws std::runtime_error naming what failed. The types
  // must be registered.
  Ros2Writers(eprosima::fastdds::dds::DomainParticipant& participant,
              eprosima::fastdds::dds::Publisher& publisher, const config::Ros2Settings& settings,
              const TelemetryInfo& info);

  // Writes the topics that are due (TopicPacer); false when a write failed.
  bool publish(const TelemetryFrame& f, bool force);

  std::uint64_t written(int topic) const { return written_[topic].load(); }
  int matched_readers() const;

 private:
  using Stamp = builtin_interfaces::msg::dds_::Time_;
  bool write_joint_states(const TelemetryFrame& f, const Stamp& stamp);
  bool write_twist(int topic, const std::array<double, 3>& v_crane, const Stamp& stamp);

  // ROS 2's graph: the participant's nodes and their endpoints on ros_discovery_info (one
  // sample, transient local: a ROS 2 tool started later gets it too).
  void announce_node(eprosima::fastdds::dds::DomainParticipant& participant,
                     eprosima::fastdds::dds::Publisher& publisher,
                     const config::Ros2Settings& settings);

  eprosima::fastdds::dds::DataWriter* writers_[kTopics] = {};
  eprosima::fastdds::dds::DataWriter* discovery_ = nullptr;
  TopicPacer pacers_[kTopics];
  std::array<double, 9> base_from_crane_;
  sensor_msgs::msg::dds_::JointState_ joint_state_;
  std::size_t hangers_ = 0;  // the hanger joints after the crane's (TelemetryInfo)
  geometry_msgs::msg::dds_::TwistStamped_ twist_;
  std::atomic<std::uint64_t> written_[kTopics] = {};
};

}  // namespace craneassist::dds
