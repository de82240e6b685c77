#include "checked_types.hpp"

#include <cstring>
#include <limits>

#include "craneassist/dds/payload_check.hpp"

namespace craneassist::dds {

namespace fdds = eprosima::fastdds::dds;
namespace msg = craneassist::msg;

DeserializeRecord& deserialize_record() noexcept {
  thread_local DeserializeRecord record;
  return record;
}

bool take_next_valid(fdds::DataReader& reader, void* data, fdds::SampleInfo& info,
                     std::uint64_t& malformed) {
  DeserializeRecord& record = deserialize_record();
  for (;;) {
    const std::uint64_t failures_before = record.failures;
    record.last_failed = false;
    const bool taken = reader.take_next_sample(data, &info) == ReturnCode_t::RETCODE_OK;
    malformed += record.failures - failures_before;
    if (!taken) return false;
    // The sample handed over is the one deserialized last (when it has data).
    if (info.valid_data && !record.last_failed) return true;
  }
}

namespace {

template <typename Generated>
bool deserialize_as(const std::uint8_t* data, std::size_t size) {
  static CheckedPubSubType<Generated> type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<std::uint32_t>(size);
  typename Generated::type sample;
  return type.deserialize(&payload, &sample);
}

}  // namespace

bool safe_deserialize_payload(Topic topic, const std::uint8_t* data, std::size_t size) noexcept {
  if (size > std::numeric_limits<std::uint32_t>::max() || (data == nullptr && size > 0)) {
    return false;
  }
  try {
    switch (topic) {
      case Topic::kStatus:
        return deserialize_as<msg::StatusPubSubType>(data, size);
      case Topic::kJoints:
        return deserialize_as<msg::JointStatePubSubType>(data, size);
      case Topic::kHydraulics:
        return deserialize_as<msg::HydraulicsPubSubType>(data, size);
      case Topic::kCommandPath:
        return deserialize_as<msg::CommandPathPubSubType>(data, size);
      case Topic::kOperatorCommand:
        return deserialize_as<msg::OperatorCommandPubSubType>(data, size);
      case Topic::kBase:
        return deserialize_as<msg::BaseStatePubSubType>(data, size);
      case Topic::kFields:
        return deserialize_as<msg::FieldValuesPubSubType>(data, size);
    }
  } catch (...) {  // out of memory for the payload's copy
  }
  return false;
}

}  // namespace craneassist::dds
