// C++17 like the dds module: it serializes craneassist's generated types with Fast CDR.
#include "dds_raw_writer.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <stdexcept>

#include "craneassist_msgs.h"
#include "craneassist_msgsPubSubTypes.h"
#include "participant.hpp"

namespace craneassist::test {

namespace fdds = eprosima::fastdds::dds;
namespace msg = craneassist::msg;
using eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

// The bytes Fast DDS would send for `sample` (encapsulation header and CDR body).
template <typename PubSubType>
Payload serialized(const typename PubSubType::type& sample) {
  PubSubType type;
  auto& data = const_cast<typename PubSubType::type&>(sample);
  SerializedPayload_t payload(type.getSerializedSizeProvider(&data)());
  if (!type.serialize(&data, &payload)) throw std::runtime_error("serialize failed");
  return Payload(payload.data, payload.data + payload.length);
}

msg::Header header_of(std::uint64_t cycle) {
  msg::Header h;
  h.cycle(cycle);
  h.t_s(0.01 * static_cast<double>(cycle));
  h.stamp_ns(1000000000LL + static_cast<long long>(cycle) * 10000000LL);
  return h;
}

msg::Status status_sample(std::uint64_t cycle) {
  msg::Status m;
  m.header(header_of(cycle));
  m.crane("Raw crane");
  m.backend("sim");
  m.state("running");
  m.active_limit("none");
  m.pump_limit("none");
  m.input_source("dds");
  m.deadman(false);
  m.scale(1.0);
  return m;
}

msg::JointState joints_sample(std::uint64_t cycle, std::size_t joints) {
  msg::JointState m;
  m.header(header_of(cycle));
  for (std::size_t i = 0; i < joints; ++i) {
    m.names().push_back("j" + std::to_string(i));
    m.prismatic().push_back(false);
    for (auto* v : {&m.q(), &m.q_ref(), &m.qdot(), &m.cylinder_pos_m(), &m.cylinder_vel_m_s(),
                    &m.load_pressure_pa(), &m.spool()}) {
      v->push_back(0.1 * static_cast<double>(i));
    }
  }
  m.tip_m({5.0, 2.5, 0.0});
  return m;
}

msg::Hydraulics hydraulics_sample(std::uint64_t cycle) {
  msg::Hydraulics m;
  m.header(header_of(cycle));
  m.pump_mode("load-sensing");
  m.power_w(1000.0);
  m.power_limit_w(35e3);
  m.flow_limit_m3_s(2e-3);
  m.pump_limit("none");
  return m;
}

msg::BaseState base_sample(std::uint64_t cycle) {
  msg::BaseState m;
  m.header(header_of(cycle));
  m.pose({1.0, 2.0, 0.1});
  m.velocity({0.3, 0.01});
  m.command({0.3, 0.01});
  m.motor_flow_m3_s({2e-4, 2e-4, 2e-4, 2e-4});
  m.motor_flow_sum_m3_s(8e-4);
  m.drive_max_flow_m3_s(1.05e-3);
  m.shared_pump(false);
  return m;
}

msg::FieldValues fields_sample(std::uint64_t cycle) {
  msg::FieldValues m;
  m.header(header_of(cycle));
  m.names({"t", "q.1", "tip.x"});
  m.units({"s", "rad or m", "m"});
  m.values({0.01 * static_cast<double>(cycle), 0.2, 3.5});
  return m;
}

msg::CommandPath command_path_sample(std::uint64_t cycle) {
  msg::CommandPath m;
  m.header(header_of(cycle));
  m.input_source("dds");
  m.deadman(false);
  m.scale(1.0);
  return m;
}

// The one byte in which `a` and `b` differ (a boolean false in one, true in the other).
std::size_t differing_byte(const Payload& a, const Payload& b) {
  if (a.size() != b.size()) throw std::logic_error("payloads of different sizes");
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] != b[i]) return i;
  }
  throw std::logic_error("payloads do not differ");
}

// A payload of `topic` whose boolean byte is 2.
Payload bad_bool(dds::Topic topic) {
  Payload p, q;
  switch (topic) {
    case dds::Topic::kOperatorCommand:
      p = operator_command_payload(1, "raw", {0.3, 0.0, 0.0}, false);
      q = operator_command_payload(1, "raw", {0.3, 0.0, 0.0}, true);
      break;
    case dds::Topic::kStatus: {
      msg::Status m = status_sample(1);
      p = serialized<msg::StatusPubSubType>(m);
      m.deadman(true);
      q = serialized<msg::StatusPubSubType>(m);
      break;
    }
    case dds::Topic::kJoints: {
      msg::JointState m = joints_sample(1, 4);
      p = serialized<msg::JointStatePubSubType>(m);
      m.prismatic()[3] = true;
      q = serialized<msg::JointStatePubSubType>(m);
      break;
    }
    case dds::Topic::kCommandPath: {
      msg::CommandPath m = command_path_sample(1);
      p = serialized<msg::CommandPathPubSubType>(m);
      m.deadman(true);
      q = serialized<msg::CommandPathPubSubType>(m);
      break;
    }
    case dds::Topic::kBase: {
      msg::BaseState m = base_sample(1);
      p = serialized<msg::BaseStatePubSubType>(m);
      m.shared_pump(true);
      q = serialized<msg::BaseStatePubSubType>(m);
      break;
    }
    case dds::Topic::kHydraulics:
    case dds::Topic::kFields:
      throw std::invalid_argument("hydraulics and the fields have no boolean");
  }
  p[differing_byte(p, q)] = 2;
  return p;
}

Payload base_payload(dds::Topic topic) {
  return topic == dds::Topic::kOperatorCommand
             ? operator_command_payload(1, "raw", {0.3, 0.0, 0.0}, true)
             : telemetry_payload(topic, 1);
}

// Serializes the bytes of a Payload as they are.
class RawType : public fdds::TopicDataType {
 public:
  explicit RawType(const std::string& name) {
    setName(name.c_str());
    m_typeSize = 64 * 1024;
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    const Payload& p = *static_cast<const Payload*>(data);
    if (p.size() > payload->max_size) return false;
    std::memcpy(payload->data, p.data(), p.size());
    payload->length = static_cast<std::uint32_t>(p.size());
    payload->encapsulation = CDR_LE;
    return true;
  }
  bool deserialize(SerializedPayload_t*, void*) override { return false; }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<std::uint32_t>(static_cast<Payload*>(data)->size()); };
  }
  void* createData() override { return new Payload(); }
  void deleteData(void* data) override { delete static_cast<Payload*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

}  // namespace

Payload operator_command_payload(std::uint64_t seq, const std::string& sender,
                                 const std::array<double, 3>& v_m_s, bool deadman) {
  msg::OperatorCommand m;
  m.seq(seq);
  m.sender(sender);
  m.v_m_s(v_m_s);
  m.deadman(deadman);
  return serialized<msg::OperatorCommandPubSubType>(m);
}

Payload telemetry_payload(dds::Topic topic, std::uint64_t cycle) {
  switch (topic) {
    case dds::Topic::kStatus:
      return serialized<msg::StatusPubSubType>(status_sample(cycle));
    case dds::Topic::kJoints:
      return serialized<msg::JointStatePubSubType>(joints_sample(cycle, 4));
    case dds::Topic::kHydraulics:
      return serialized<msg::HydraulicsPubSubType>(hydraulics_sample(cycle));
    case dds::Topic::kCommandPath:
      return serialized<msg::CommandPathPubSubType>(command_path_sample(cycle));
    case dds::Topic::kBase:
      return serialized<msg::BaseStatePubSubType>(base_sample(cycle));
    case dds::Topic::kFields:
      return serialized<msg::FieldValuesPubSubType>(fields_sample(cycle));
    case dds::Topic::kOperatorCommand:
      break;
  }
  throw std::invalid_argument("not a telemetry topic");
}

const char* to_string(Malformation m) {
  switch (m) {
    case Malformation::kBadBool:
      return "bad bool";
    case Malformation::kBadEncapsulation:
      return "bad encapsulation";
    case Malformation::kTruncated:
      return "truncated";
    case Malformation::kOverBound:
      return "sequence over its bound";
  }
  return "?";
}

std::vector<Malformation> malformations_of(dds::Topic topic) {
  std::vector<Malformation> m = {Malformation::kBadEncapsulation, Malformation::kTruncated};
  // Hydraulics and the fields have no boolean.
  if (topic != dds::Topic::kHydraulics && topic != dds::Topic::kFields) {
    m.push_back(Malformation::kBadBool);
  }
  if (topic == dds::Topic::kJoints) m.push_back(Malformation::kOverBound);
  return m;
}

Payload malformed_payload(dds::Topic topic, Malformation m) {
  switch (m) {
    case Malformation::kBadBool:
      return bad_bool(topic);
    case Malformation::kBadEncapsulation: {
      Payload p = base_payload(topic);
      p[0] = 0x12;  // the first byte is 0 in every CDR encapsulation; no kind is 0x34
      p[1] = 0x34;
      return p;
    }
    case Malformation::kTruncated: {
      Payload p = base_payload(topic);
      p.resize(std::max<std::size_t>(6, p.size() - 5));
      return p;
    }
    case Malformation::kOverBound:
      if (topic != dds::Topic::kJoints) throw std::invalid_argument("only joints have a bound");
      return serialized<msg::JointStatePubSubType>(joints_sample(1, 9));
  }
  throw std::invalid_argument("malformation");
}

struct RawWriter::Impl : public fdds::DataWriterListener {
  explicit Impl(const RawWriterOptions& o) {
    dds::ParticipantOptions p;
    p.domain_id = o.domain_id;
    p.name = o.participant_name;
    p.transport = o.transport;
    p.security = o.security;
    p.register_types = false;
    participant = dds::make_participant(p);
    const dds::TopicInfo& info = dds::topic_info(o.topic);
    fdds::TypeSupport type(new RawType(std::string(info.type_name)));
    if (type.register_type(participant.get()) != ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error("cannot register the raw type");
    }
    fdds::Topic* topic = participant->create_topic(
        std::string(info.dds_name), std::string(info.type_name), fdds::TOPIC_QOS_DEFAULT);
    fdds::Publisher* publisher = participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    if (topic == nullptr || publisher == nullptr) throw std::runtime_error("raw writer: DDS");
    // Reliable and volatile: matches every reader of the project (reliable or best effort).
    config::TopicSettings s;
    s.reliability = config::Reliability::kReliable;
    s.durability = config::Durability::kVolatile;
    s.depth = 8;
    writer = publisher->create_datawriter(topic, dds::writer_qos(s), this,
                                          fdds::StatusMask::publication_matched());
    if (writer == nullptr) throw std::runtime_error("raw writer: cannot create the writer");
  }
  ~Impl() override { participant.reset(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& s) override {
    matched.store(s.current_count);
  }

  std::atomic<int> matched{0};
  dds::ParticipantPtr participant;
  fdds::DataWriter* writer = nullptr;
};

RawWriter::RawWriter(const RawWriterOptions& options) : impl_(std::make_unique<Impl>(options)) {}

RawWriter::~RawWriter() = default;

bool RawWriter::write(const Payload& payload) {
  Payload copy = payload;
  return impl_->writer->write(&copy);
}

int RawWriter::matched_readers() const {
  return impl_->matched.load();
}

}  // namespace craneassist::test
