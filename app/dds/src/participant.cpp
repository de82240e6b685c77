#include "participant.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "checked_types.hpp"
#include "craneassist_msgsTypeObject.h"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;

ParticipantOptions participant_options(const config::TelemetryConfig& c) {
  ParticipantOptions o;
  o.domain_id = c.domain_id;
  o.name = c.participant_name;
  o.transport = c.transport;
  o.type_propagation = c.type_propagation;
  if (c.ros2.enabled) {
    const char enclave[] = "enclave=/;";  // with its NUL
    o.user_data.assign(enclave, enclave + sizeof enclave);
  }
  return o;
}

void ParticipantDeleter::operator()(fdds::DomainParticipant* p) const {
  if (p == nullptr) return;
  p->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(p);
}

namespace {

void add_property(fdds::DomainParticipantQos& qos, const std::string& name,
                  const std::string& value) {
  qos.properties().properties().emplace_back(name, value);
}

// Fast DDS 2.9 takes security files as "file://PATH" (it drops the 7 characters of "file://"):
// an absolute path, so that the participant does not depend on the working directory.
std::string file_uri(const std::string& path) {
  return "file://" + std::filesystem::absolute(path).lexically_normal().string();
}

}  // namespace

ParticipantPtr make_participant(const ParticipantOptions& options) {
  static std::once_flag type_objects;
  std::call_once(type_objects, [] { registercraneassist_msgsTypes(); });

  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.name(options.name);
  if (!options.user_data.empty()) {
    qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(options.user_data.begin(),
                                                                          options.user_data.end()));
  }
  // TYPE_INFORMATION names the types; the TypeLookup service answers a remote reader that asks
  // for them (and for the nested ones) from it.
  qos.wire_protocol().builtin.typelookup_config.use_server =
      options.type_propagation.type_information;
  if (options.transport != config::DdsTransport::kDefault) {
    qos.transport().use_builtin_transports = false;
    if (options.transport == config::DdsTransport::kUdp) {
      qos.transport().user_transports.push_back(
          std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
    } else {
      qos.transport().user_transports.push_back(
          std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
    }
  }
  const auto& sec = options.security;
  if (!sec.empty()) {
    if (!sec.complete()) {
      throw std::runtime_error(
          "DDS Security: every file is needed (identity_ca, identity_certificate, private_key, "
          "permissions_ca, governance, permissions)");
    }
    add_property(qos, "dds.sec.auth.plugin", "builtin.PKI-DH");
    add_property(qos, "dds.sec.auth.builtin.PKI-DH.identity_ca", file_uri(sec.identity_ca));
    add_property(qos, "dds.sec.auth.builtin.PKI-DH.identity_certificate",
                 file_uri(sec.identity_certificate));
    add_property(qos, "dds.sec.auth.builtin.PKI-DH.private_key", file_uri(sec.private_key));
    add_property(qos, "dds.sec.access.plugin", "builtin.Access-Permissions");
    add_property(qos, "dds.sec.access.builtin.Access-Permissions.permissions_ca",
                 file_uri(sec.permissions_ca));
    add_property(qos, "dds.sec.access.builtin.Access-Permissions.governance",
                 file_uri(sec.governance));
    add_property(qos, "dds.sec.access.builtin.Access-Permissions.permissions",
                 file_uri(sec.permissions));
    add_property(qos, "dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  }
  ParticipantPtr p(fdds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<fdds::DomainId_t>(options.domain_id), qos));
  if (!p) {
    throw std::runtime_error(
        sec.empty() ? "DDS: cannot create the domain participant (domain " +
                          std::to_string(options.domain_id) + ")"
                    : "DDS Security: cannot create the secure participant (check the "
                      "certificates, the key, and that governance and permissions are signed by "
                      "the permissions CA; Fast DDS logs the reason above)");
  }
  if (!options.register_types) return p;
  // Every reader of the participant deserializes with these: a malformed sample is dropped and
  // counted, never an exception on Fast DDS's thread (checked_types.hpp).
  const config::TypePropagation& types = options.type_propagation;
  register_type_support<CheckedPubSubType<craneassist::msg::StatusPubSubType>>(*p, types);
  register_type_support<CheckedPubSubType<craneassist::msg::JointStatePubSubType>>(*p, types);
  register_type_support<CheckedPubSubType<craneassist::msg::HydraulicsPubSubType>>(*p, types);
  register_type_support<CheckedPubSubType<craneassist::msg::CommandPathPubSubType>>(*p, types);
  register_type_support<CheckedPubSubType<craneassist::msg::OperatorCommandPubSubType>>(*p, types);
  register_type_support<CheckedPubSubType<craneassist::msg::BaseStatePubSubType>>(*p, types);
  register_type_support<CheckedPubSubType<craneassist::msg::FieldValuesPubSubType>>(*p, types);
  return p;
}

fdds::Topic* find_or_create_topic(fdds::DomainParticipant& p, const std::string& name,
                                  const std::string& type_name) {
  if (fdds::TopicDescription* existing = p.lookup_topicdescription(name)) {
    return static_cast<fdds::Topic*>(existing);
  }
  fdds::Topic* t = p.create_topic(name, type_name, fdds::TOPIC_QOS_DEFAULT);
  if (t == nullptr) throw std::runtime_error("DDS: cannot create topic " + name);
  return t;
}

fdds::Topic* get_topic(fdds::DomainParticipant& p, Topic topic) {
  const TopicInfo& info = topic_info(topic);
  return find_or_create_topic(p, std::string(info.dds_name), std::string(info.type_name));
}

namespace {

// The reliability, durability and history depth of a topic's settings, on a writer's or a
// reader's QoS.
template <class Qos>
Qos with_topic_settings(Qos q, const config::TopicSettings& s) {
  q.reliability().kind = s.reliability == config::Reliability::kReliable
                             ? fdds::RELIABLE_RELIABILITY_QOS
                             : fdds::BEST_EFFORT_RELIABILITY_QOS;
  q.durability().kind = s.durability == config::Durability::kTransientLocal
                            ? fdds::TRANSIENT_LOCAL_DURABILITY_QOS
                            : fdds::VOLATILE_DURABILITY_QOS;
  q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = s.depth;
  return q;
}

}  // namespace

fdds::DataWriterQos writer_qos(const config::TopicSettings& s) {
  fdds::DataWriterQos q = with_topic_settings(fdds::DATAWRITER_QOS_DEFAULT, s);
  // A reliable writer whose history is full waits at most this long (on the publisher thread,
  // never the control loop), then the sample is counted as an error.
  q.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(0, 10000000);
  return q;
}

fdds::DataReaderQos reader_qos(const config::TopicSettings& s) {
  return with_topic_settings(fdds::DATAREADER_QOS_DEFAULT, s);
}

config::TopicSettings default_reader_settings(Topic topic) {
  (void)topic;
  // A best-effort, volatile reader matches every writer whatever its configured QoS (a reliable
  // reader would not match a best-effort writer; a transient-local one not a volatile writer).
  config::TopicSettings s;
  s.reliability = config::Reliability::kBestEffort;
  s.durability = config::Durability::kVolatile;
  s.depth = 8;
  return s;
}

}  // namespace craneassist::dds
