// craneassist's DDS types as this project registers them (internal to the dds module: Fast DDS
// types, C++17): the fastddsgen-generated PubSubTypes with a deserialize() that never throws and
// rejects what the IDL does not allow.
//
// The generated deserialize() catches only Fast CDR's NotEnoughMemoryException: a bool byte other
// than 0 or 1 or a bad encapsulation header throws BadParamException, on the thread that takes
// the sample (Fast DDS's listener thread for the command input and the dashboard), and nothing
// there catches it: std::terminate. CheckedPubSubType catches every exception, also checks the
// IDL's sequence bounds (Fast CDR does not), and on failure leaves a default sample (zero
// velocity, deadman released) rather than a partly read one, and returns false. Fast DDS 2.9.1
// then drops the sample; take_next_valid() counts it.
#pragma once

#include <fastdds/rtps/common/SerializedPayload.h>

#include <cstdint>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "craneassist_msgs.h"
#include "craneassist_msgsPubSubTypes.h"

namespace craneassist::dds {

// What the checked types' deserialize() did on the calling thread: how many payloads failed so
// far and whether the latest one did. Fast DDS deserializes on the thread that takes a sample,
// inside take_next_sample().
struct DeserializeRecord {
  std::uint64_t failures = 0;
  bool last_failed = false;
};
DeserializeRecord& deserialize_record() noexcept;

// The IDL's bounds that Fast CDR does not check (JointState: every sequence at most 8 long).
inline bool within_bounds(const craneassist::msg::JointState& m) noexcept {
  constexpr std::size_t kMax = 8;  // sequence<..., 8> in craneassist_msgs.idl
  return m.names().size() <= kMax && m.prismatic().size() <= kMax && m.q().size() <= kMax &&
         m.q_ref().size() <= kMax && m.qdot().size() <= kMax && m.cylinder_pos_m().size() <= kMax &&
         m.cylinder_vel_m_s().size() <= kMax && m.load_pressure_pa().size() <= kMax &&
         m.spool().size() <= kMax;
}
template <typename T>
bool within_bounds(const T&) noexcept {
  return true;
}

template <typename Generated>
class CheckedPubSubType : public Generated {
 public:
  using type = typename Generated::type;

  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    bool ok = false;
    if (payload != nullptr && data != nullptr) {
      try {
        ok = Generated::deserialize(payload, data) && within_bounds(*static_cast<type*>(data));
      } catch (...) {  // Fast CDR's BadParamException and whatever else: a bad sample
        ok = false;
      }
    }
    DeserializeRecord& record = deserialize_record();
    record.last_failed = !ok;
    if (!ok) {
      ++record.failures;
      if (data != nullptr) {
        try {
          *static_cast<type*>(data) = type();
        } catch (...) {
        }
      }
    }
    return ok;
  }
};

// Takes the next sample with valid data from `reader` into `data` (an object of the reader's
// type). Samples that failed to deserialize are counted in `malformed` and never handed over
// (Fast DDS 2.9.1 drops them itself; should a version hand one over, it is skipped here), and
// samples without data (disposed, unregistered) are skipped. False when no sample is left.
bool take_next_valid(eprosima::fastdds::dds::DataReader& reader, void* data,
                     eprosima::fastdds::dds::SampleInfo& info, std::uint64_t& malformed);

}  // namespace craneassist::dds
