// DDS samples (app/dds/idl/craneassist_msgs.idl): bytes as a DataReader receives them, for every
// topic type, through the type support every craneassist reader registers (checked_types.hpp: the
// generated one, never throwing, with the IDL's bounds checked; the first input byte picks the
// type, the rest is the serialized payload with its encapsulation). A sample that deserializes is
// handed to what consumes it: `craneassist echo` (text and CSV), the dashboard's view, and for
// the operator's command the input monitor of the DDS command input. Serialized again it gives
// bytes that deserialize to a sample that serializes to the same bytes.
//
// Plain C++17, like the dds module (Debian's Fast CDR headers are not C++20-clean).
#include <fastrtps/rtps/common/SerializedPayload.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "checked_types.hpp"
#include "craneassist/input/input_monitor.hpp"
#include "craneassist_msgsPubSubTypes.h"
#include "fuzz_check.hpp"
#include "sample_views.hpp"

namespace msg = craneassist::msg;
using eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

std::FILE* null_out() {
  static std::FILE* out = std::fopen("/dev/null", "w");
  return out;
}

// The bytes into the readers' deserialize. False when it refuses them (never an exception).
template <typename PubSubType, typename T>
bool deserialize(const std::uint8_t* data, std::size_t size, T& sample) {
  craneassist::dds::CheckedPubSubType<PubSubType> type;
  SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  return type.deserialize(&payload, &sample);
}

template <typename PubSubType, typename T>
std::vector<std::uint8_t> serialize(T& sample) {
  PubSubType type;
  SerializedPayload_t payload(type.getSerializedSizeProvider(&sample)());
  FUZZ_CHECK(type.serialize(&sample, &payload), "a deserialized sample serializes");
  return {payload.data, payload.data + payload.length};
}

// Serialize -> deserialize -> serialize: the same bytes.
template <typename PubSubType, typename T>
void check_round_trip(T& sample) {
  const std::vector<std::uint8_t> bytes = serialize<PubSubType>(sample);
  T again;
  FUZZ_CHECK((deserialize<PubSubType>(bytes.data(), bytes.size(), again)),
             "a serialized sample deserializes");
  FUZZ_CHECK(serialize<PubSubType>(again) == bytes, "serialization round trip");
}

template <typename PubSubType, typename T>
void check_topic(const std::uint8_t* data, std::size_t size) {
  T sample;
  if (!deserialize<PubSubType>(data, size, sample)) return;
  craneassist::dds::echo_sample(sample, craneassist::dds::EchoFormat::kText, null_out());
  craneassist::dds::echo_sample(sample, craneassist::dds::EchoFormat::kCsv, null_out());
  if constexpr (std::is_same_v<T, msg::Status>) {
    (void)craneassist::dds::dashboard_view(&sample, nullptr, nullptr, nullptr);
  } else if constexpr (std::is_same_v<T, msg::JointState>) {
    (void)craneassist::dds::dashboard_view(nullptr, &sample, nullptr, nullptr);
  } else if constexpr (std::is_same_v<T, msg::Hydraulics>) {
    (void)craneassist::dds::dashboard_view(nullptr, nullptr, &sample, nullptr);
  } else if constexpr (std::is_same_v<T, msg::CommandPath>) {
    (void)craneassist::dds::dashboard_view(nullptr, nullptr, nullptr, &sample);
  } else if constexpr (std::is_same_v<T, msg::BaseState>) {
    (void)craneassist::dds::dashboard_view(nullptr, nullptr, nullptr, nullptr, &sample);
  } else if constexpr (std::is_same_v<T, msg::OperatorCommand>) {
    // What the DDS command input passes on (DdsCommandSource::poll) through the input monitor.
    craneassist::input::InputMonitor monitor(craneassist::input::InputMonitorSettings{});
    craneassist::input::OperatorCommand command;
    command.stamp_s = 1.0;
    command.v_m_s = {sample.v_m_s()[0], sample.v_m_s()[1], sample.v_m_s()[2]};
    command.deadman = sample.deadman();
    craneassist::input::MonitorOutput out;
    for (int cycle = 0; cycle < 3; ++cycle) {
      if (cycle == 1) command.deadman = false;  // release and press: the monitor arms
      if (cycle == 2) command.deadman = sample.deadman();
      monitor.update(craneassist::input::SourceState::kOk, command, 1.0 + 0.01 * cycle, out);
      FUZZ_CHECK(!out.enabled || (out.v_m_s.allFinite() && out.v_m_s.cwiseAbs().maxCoeff() <=
                                                               monitor.settings().max_speed_m_s),
                 "the monitor passes only finite commands within the speed limit");
    }
  }
  check_round_trip<PubSubType>(sample);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t* payload = data + 1;
  const std::size_t length = size - 1;
  switch (data[0] % 7) {
    case 0:
      check_topic<msg::StatusPubSubType, msg::Status>(payload, length);
      break;
    case 1:
      check_topic<msg::JointStatePubSubType, msg::JointState>(payload, length);
      break;
    case 2:
      check_topic<msg::HydraulicsPubSubType, msg::Hydraulics>(payload, length);
      break;
    case 3:
      check_topic<msg::CommandPathPubSubType, msg::CommandPath>(payload, length);
      break;
    case 4:
      check_topic<msg::OperatorCommandPubSubType, msg::OperatorCommand>(payload, length);
      break;
    case 6:
      check_topic<msg::BaseStatePubSubType, msg::BaseState>(payload, length);
      break;
    default: {
      msg::Header header;  // the type every telemetry sample starts with
      if (deserialize<msg::HeaderPubSubType>(payload, length, header)) {
        check_round_trip<msg::HeaderPubSubType>(header);
      }
      break;
    }
  }
  return 0;
}
