// Fast DDS set-up shared by the publisher, the command input and the subscribers (internal to
// the dds module: includes Fast DDS headers, compiled as C++17).
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/topics.hpp"

namespace craneassist::dds {

struct ParticipantOptions {
  int domain_id = 0;
  std::string name = "craneassist";
  config::DdsTransport transport = config::DdsTransport::kDefault;
  // What discovery announces about the registered types (the settings' type_propagation;
  // default: the interoperable one, no TYPE_INFORMATION).
  config::TypePropagation type_propagation;
  // Non-empty: the participant authenticates with PKI-DH, checks access with signed governance
  // and permissions, and encrypts as governance says (every file must be given).
  config::SecurityFiles security;
  // false: no craneassist type is registered (a test's raw writer registers its own under the
  // same name).
  bool register_types = true;
  // The participant's USER_DATA (empty: none). With the ROS 2 topics on, ROS 2's `enclave=/;`
  // (and its NUL, as rmw writes it): ROS 2's graph takes only participants that carry it.
  std::vector<unsigned char> user_data;
};

ParticipantOptions participant_options(const config::TelemetryConfig& c);

// Deletes the participant and every entity it holds.
struct ParticipantDeleter {
  void operator()(eprosima::fastdds::dds::DomainParticipant* p) const;
};
using ParticipantPtr =
    std::unique_ptr<eprosima::fastdds::dds::DomainParticipant, ParticipantDeleter>;

// Creates the participant and registers every craneassist type on it, announcing what
// options.type_propagation says, unless options.register_types is false. Throws
// std::runtime_error naming what failed (with security: which file, when Fast DDS says).
ParticipantPtr make_participant(const ParticipantOptions& options);

// Registers a type on the participant. type_object: the legacy TYPE_OBJECT and TYPE_ID discovery
// parameters (Fast DDS 2.x's dynamic-type readers use them; other implementations ignore them).
// type_information: the XTypes TYPE_INFORMATION parameter, which Cyclone DDS rejects as invalid
// in Fast DDS 2.9's form: its endpoints then never match ours
// (docs/telemetry.md#interoperability). Throws std::runtime_error naming the type.
template <typename PubSubType>
void register_type_support(eprosima::fastdds::dds::DomainParticipant& p,
                           const config::TypePropagation& propagation) {
  eprosima::fastdds::dds::TypeSupport type(new PubSubType());
  type->auto_fill_type_object(propagation.type_object);
  type->auto_fill_type_information(propagation.type_information);
  if (type.register_type(&p) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("DDS: cannot register type " + std::string(type.get_type_name()));
  }
}

// The topic `name` of type `type_name` on the participant (created on first use); throws
// std::runtime_error naming it when it cannot be created.
eprosima::fastdds::dds::Topic* find_or_create_topic(eprosima::fastdds::dds::DomainParticipant& p,
                                                    const std::string& name,
                                                    const std::string& type_name);

// The topic of `topic` on the participant (created on first use).
eprosima::fastdds::dds::Topic* get_topic(eprosima::fastdds::dds::DomainParticipant& p, Topic topic);

eprosima::fastdds::dds::DataWriterQos writer_qos(const config::TopicSettings& s);
eprosima::fastdds::dds::DataReaderQos reader_qos(const config::TopicSettings& s);

// The QoS a subscriber (echo, dashboard) uses: best effort and volatile, which match every
// writer whatever QoS its config gives it.
config::TopicSettings default_reader_settings(Topic topic);

}  // namespace craneassist::dds
