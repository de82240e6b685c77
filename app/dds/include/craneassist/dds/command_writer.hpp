// The operator's side of the DDS command input (`craneassist remote`, docs/remote-commands.md):
// a participant with the operator's DDS Security identity and a writer of
// craneassist/operator_command. write() is called at the console's fixed rate; the caller thread
// writes (no thread of its own).
//
// Plain C++17: no Fast DDS types (the C++20 command line includes it).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "craneassist/config/telemetry_config.hpp"

namespace craneassist::dds {

struct CommandWriterOptions {
  int domain_id = 0;
  config::DdsTransport transport = config::DdsTransport::kDefault;
  config::TypePropagation type_propagation;  // the settings' type_propagation
  std::string participant_name = "craneassist-remote";
  config::TopicSettings topic;     // reliability and depth (commands.topic of the settings)
  config::SecurityFiles security;  // every file, or none with `insecure`
  // No DDS Security at all: only to show that such a participant cannot command the crane.
  bool insecure = false;
  std::string sender;  // the OperatorCommand.sender field
};

struct CommandWriterStats {
  std::uint64_t samples_written = 0;
  std::uint64_t write_errors = 0;
  int matched_readers = 0;  // now
  int peak_matched_readers = 0;
  double first_match_s = -1;  // first reader matched, s after construction; -1: never
};

class CommandWriter {
 public:
  // Throws std::invalid_argument when security is incomplete (and not insecure), or given with
  // insecure; std::runtime_error when DDS fails (with security: a bad certificate, key or
  // signature, or permissions that do not allow publishing the topic).
  explicit CommandWriter(const CommandWriterOptions& options);
  ~CommandWriter();
  CommandWriter(const CommandWriter&) = delete;
  CommandWriter& operator=(const CommandWriter&) = delete;

  // One sample (seq increases by one per call); false when the write failed.
  bool write(const std::array<double, 3>& v_m_s, bool deadman);
  int matched_readers() const;
  CommandWriterStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace craneassist::dds
