#include "ros2_writers.hpp"

#include <time.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "craneassist/dds/telemetry_publisher.hpp"
#include "participant.hpp"
#include "ros2_msgsPubSubTypes.h"
#include "ros2_msgsTypeObject.h"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;

namespace {

constexpr const char* kTopicNames[Ros2Writers::kTopics] = {
    "joint_states", "craneassist/tip_velocity/command", "craneassist/tip_velocity/reference"};
constexpr const char* kTypeNames[Ros2Writers::kTopics] = {
    "sensor_msgs::msg::dds_::JointState_", "geometry_msgs::msg::dds_::TwistStamped_",
    "geometry_msgs::msg::dds_::TwistStamped_"};
constexpr const char* kTypeHashes[Ros2Writers::kTopics] = {
    kJointStateTypeHash, kTwistStampedTypeHash, kTwistStampedTypeHash};

// An endpoint's USER_DATA as ROS 2 writes it: "typehash=RIHS01_<hex>;" (no NUL).
void set_type_hash(fdds::DataWriterQos& qos, const char* hash) {
  const std::string text = std::string("typehash=") + hash + ";";
  qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(text.begin(), text.end()));
}

// A GUID as ROS 2's 16-byte Gid: the prefix, then the entity id.
rmw_dds_common::msg::dds_::Gid_ gid_of(const eprosima::fastrtps::rtps::GUID_t& guid) {
  rmw_dds_common::msg::dds_::Gid_ gid;
  std::array<std::uint8_t, 16> data{};
  std::copy(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), data.begin());
  std::copy(std::begin(guid.entityId.value), std::end(guid.entityId.value), data.begin() + 12);
  gid.data(data);
  return gid;
}

// The frame's monotonic stamp on the wall clock (ROS 2 stamps messages with the system time).
builtin_interfaces::msg::dds_::Time_ wall_stamp(std::int64_t monotonic_stamp_ns) {
  timespec wall{};
  clock_gettime(CLOCK_REALTIME, &wall);
  const std::int64_t wall_ns = static_cast<std::int64_t>(wall.tv_sec) * 1000000000 + wall.tv_nsec;
  const std::int64_t ns = monotonic_stamp_ns + (wall_ns - monotonic_ns());
  builtin_interfaces::msg::dds_::Time_ t;
  t.sec(static_cast<std::int32_t>(ns / 1000000000));
  t.nanosec(static_cast<std::uint32_t>(ns % 1000000000));
  return t;
}

}  // namespace

void register_ros2_types(fdds::DomainParticipant& p, const config::TypePropagation& propagation) {
  static std::once_flag type_objects;
  std::call_once(type_objects, [] { registerros2_msgsTypes(); });
  register_type_support<sensor_msgs::msg::dds_::JointState_PubSubType>(p, propagation);
  register_type_support<geometry_msgs::msg::dds_::TwistStamped_PubSubType>(p, propagation);
  register_type_support<rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_PubSubType>(p,
                                                                                       propagation);
}

Ros2Writers::Ros2Writers(fdds::DomainParticipant& participant, fdds::Publisher& publisher,
                         const config::Ros2Settings& settings, const TelemetryInfo& info)
    : pacers_{TopicPacer(settings.joint_states.rate_hz), TopicPacer(settings.tip_velocity.rate_hz),
              TopicPacer(settings.tip_velocity.rate_hz)},
      base_from_crane_(info.base_from_crane) {
  const config::TopicSettings* qos[kTopics] = {&settings.joint_states, &settings.tip_velocity,
                                               &settings.tip_velocity};
  for (int i = 0; i < kTopics; ++i) {
    const std::string name = settings.dds_topic(kTopicNames[i]);
    fdds::Topic* topic = find_or_create_topic(participant, name, kTypeNames[i]);
    fdds::DataWriterQos wqos = writer_qos(*qos[i]);
    set_type_hash(wqos, kTypeHashes[i]);
    writers_[i] = publisher.create_datawriter(topic, wqos);
    if (writers_[i] == nullptr)
      throw std::runtime_error("DDS: cannot create the writer of " + name);
  }
  std::vector<std::string> names = info.joint_names;
  names.insert(names.end(), info.hanger_joint_names.begin(), info.hanger_joint_names.end());
  joint_state_.name(names);
  hangers_ = std::min(info.hanger_joint_names.size(), std::size_t{2});
  announce_node(participant, publisher, settings);
}

void Ros2Writers::announce_node(fdds::DomainParticipant& participant, fdds::Publisher& publisher,
                                const config::Ros2Settings& settings) {
  // As rmw_fastrtps does: the DDS topic without the rt/ prefix, reliable, transient local, keep
  // last 1, the type's hash in USER_DATA; one node, named by the settings, with the three writers.
  fdds::Topic* topic = find_or_create_topic(participant, "ros_discovery_info",
                                            "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = 1;
  set_type_hash(qos, kParticipantEntitiesInfoTypeHash);
  discovery_ = publisher.create_datawriter(topic, qos);
  if (discovery_ == nullptr) {
    throw std::runtime_error("DDS: cannot create the writer of ros_discovery_info");
  }
  rmw_dds_common::msg::dds_::NodeEntitiesInfo_ node;
  node.node_namespace(settings.ros_namespace.empty() ? "/" : settings.ros_namespace);
  node.node_name(settings.node_name);
  for (auto* w : writers_) node.writer_gid_seq().push_back(gid_of(w->guid()));
  rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_ info;
  info.gid(gid_of(participant.guid()));
  info.node_entities_info_seq().push_back(node);
  if (!discovery_->write(&info)) {
    throw std::runtime_error("DDS: cannot write ros_discovery_info");
  }
  twist_.header().frame_id("base_link");
}

bool Ros2Writers::publish(const TelemetryFrame& f, bool force) {
  bool ok = true;
  std::optional<builtin_interfaces::msg::dds_::Time_> stamp;  // one per frame, when one is due
  for (int i = 0; i < kTopics; ++i) {
    if (!pacers_[i].due(f, force)) continue;
    if (!stamp) stamp = wall_stamp(f.stamp_ns);
    const bool wrote = i == 0   ? write_joint_states(f, *stamp)
                       : i == 1 ? write_twist(i, f.command_m_s, *stamp)
                                : write_twist(i, f.reference_m_s, *stamp);
    if (wrote) written_[i].fetch_add(1, std::memory_order_relaxed);
    ok = ok && wrote;
  }
  return ok;
}

bool Ros2Writers::write_joint_states(const TelemetryFrame& f, const Stamp& stamp) {
  const auto n = static_cast<std::size_t>(std::min(f.dof, kMaxJoints));
  joint_state_.header().stamp(stamp);
  joint_state_.position().assign(f.q.begin(), f.q.begin() + static_cast<std::ptrdiff_t>(n));
  joint_state_.velocity().assign(f.qdot.begin(), f.qdot.begin() + static_cast<std::ptrdiff_t>(n));
  for (std::size_t k = 0; k < hangers_; ++k) {
    joint_state_.position().push_back(f.hanger_rad[k]);
    joint_state_.velocity().push_back(f.hanger_rate_rad_s[k]);
  }
  return writers_[0]->write(&joint_state_);
}

bool Ros2Writers::write_twist(int topic, const std::array<double, 3>& v_crane, const Stamp& stamp) {
  const auto& r = base_from_crane_;
  twist_.header().stamp(stamp);
  auto& linear = twist_.twist().linear();
  linear.x(r[0] * v_crane[0] + r[1] * v_crane[1] + r[2] * v_crane[2]);
  linear.y(r[3] * v_crane[0] + r[4] * v_crane[1] + r[5] * v_crane[2]);
  linear.z(r[6] * v_crane[0] + r[7] * v_crane[1] + r[8] * v_crane[2]);
  return writers_[topic]->write(&twist_);
}

int Ros2Writers::matched_readers() const {
  int n = 0;
  for (auto* w : writers_) {
    fdds::PublicationMatchedStatus m;
    if (w != nullptr && w->get_publication_matched_status(m) == ReturnCode_t::RETCODE_OK) {
      n += m.current_count;
    }
  }
  return n;
}

}  // namespace craneassist::dds
