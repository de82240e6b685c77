// A DDS writer that sends whatever bytes it is given as the samples of a craneassist topic, and
// payloads to send with it: well-formed samples of each type with chosen values, and malformed
// ones (a bool byte other than 0 or 1, a bad encapsulation header, a cut-off body, a sequence
// longer than its IDL bound). For the tests of what craneassist's readers do with samples they
// cannot trust (docs/remote-commands.md, docs/telemetry.md).
//
// The writer's participant registers its own type under the topic's type name, without type
// information, so it matches craneassist's readers by name as any other implementation's would.
// With DDS Security files (the operator's identity) it writes to the secured command input.
//
// Plain C++17 header (no Fast DDS types): the C++20 tests include it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/topics.hpp"

namespace craneassist::test {

using Payload = std::vector<std::uint8_t>;

// A well-formed OperatorCommand as craneassist's CommandWriter would send it.
Payload operator_command_payload(std::uint64_t seq, const std::string& sender,
                                 const std::array<double, 3>& v_m_s, bool deadman);
// A well-formed sample of a telemetry topic (status, joints, hydraulics, command_path) with
// plausible values; `cycle` goes into its header.
Payload telemetry_payload(dds::Topic topic, std::uint64_t cycle);

enum class Malformation {
  kBadBool,           // a boolean byte that is 2 (Fast CDR throws BadParamException)
  kBadEncapsulation,  // the CDR encapsulation header is not one Fast CDR knows
  kTruncated,         // the body cut off in the middle
  kOverBound,         // a sequence longer than the IDL allows (joints: more than 8 entries)
};
const char* to_string(Malformation m);
// What each topic's type can get wrong (kBadBool only where the type has a boolean,
// kOverBound only for joints).
std::vector<Malformation> malformations_of(dds::Topic topic);
// A sample of `topic` (operator_command: seq 1, deadman held, moving) made malformed.
Payload malformed_payload(dds::Topic topic, Malformation m);

struct RawWriterOptions {
  int domain_id = 0;
  dds::Topic topic = dds::Topic::kOperatorCommand;
  config::SecurityFiles security;  // all six files (a secure participant), or none
  config::DdsTransport transport = config::DdsTransport::kDefault;
  std::string participant_name = "raw-writer";
};

class RawWriter {
 public:
  // Throws std::runtime_error when DDS cannot be set up.
  explicit RawWriter(const RawWriterOptions& options);
  ~RawWriter();
  RawWriter(const RawWriter&) = delete;
  RawWriter& operator=(const RawWriter&) = delete;

  // One sample with exactly these bytes as its serialized payload; false when the write failed.
  bool write(const Payload& payload);
  int matched_readers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace craneassist::test
