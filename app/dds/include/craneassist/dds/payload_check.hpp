// Deserializing a payload of a craneassist topic the way every craneassist reader does, without
// DDS: for fuzzing and tests of what a reader does with bytes it cannot trust.
//
// Plain C++17: no Fast DDS types (the C++20 command line and tests include it).
#pragma once

#include <cstddef>
#include <cstdint>

#include "craneassist/dds/topics.hpp"

namespace craneassist::dds {

// Deserializes `size` bytes at `data` as one serialized sample of `topic`'s type (as it arrives
// from the network: the 4-byte CDR encapsulation header, then the CDR body) with the type the
// readers register (checked_types.hpp). True for a well-formed sample; false for anything else (a
// bool byte other than 0 or 1, a bad encapsulation, a cut-off body, a sequence over its IDL
// bound, ...). Never throws, whatever the bytes; `data` may be null when `size` is 0.
bool safe_deserialize_payload(Topic topic, const std::uint8_t* data, std::size_t size) noexcept;

}  // namespace craneassist::dds
