// Fast DDS set-up shared by the publisher, the command input and the subscribers (internal to
// the dds module: includes Fast DDS headers, compiled as C++17).
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <memory>
#include <string>

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

// The topic of `topic` on the participant (created on first use).
eprosima::fastdds::dds::Topic* get_topic(eprosima::fastdds::dds::DomainParticipant& p, Topic topic);

eprosima::fastdds::dds::DataWriterQos writer_qos(const config::TopicSettings& s);
eprosima::fastdds::dds::DataReaderQos reader_qos(const config::TopicSettings& s);

// The QoS a subscriber (echo, dashboard) uses: best effort and volatile, which match every
// writer whatever QoS its config gives it.
config::TopicSettings default_reader_settings(Topic topic);

}  // namespace craneassist::dds
