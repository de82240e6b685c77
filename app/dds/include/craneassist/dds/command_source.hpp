// The DDS command input (`craneassist sim --input dds`, docs/remote-commands.md): a remote
// operator's OperatorCommand samples on craneassist/operator_command as an input::CommandSource.
//
// The source has its own DDS Security participant (the crane's identity, from
// commands.security of the DDS settings), separate from the open telemetry participant: only
// authenticated participants whose signed permissions allow publishing the topic can reach its
// reader. Fast DDS's listener thread stamps each sample on reception (steady_clock) and hands
// the latest one to poll() through a seqlock: poll() never blocks, allocates or throws.
//
// One operator at a time: the first writer whose sample arrives holds the command for as long as
// it sends; samples of other writers meanwhile are counted and dropped. Another writer takes it
// over only once the holder has been silent (or gone) for longer than the input monitor's stale
// timeout, when the monitor has stopped the crane on stale input, and the new holder's deadman
// reads released until it has sent it released (its own release and press re-arm the monitor).
// Samples with a non-finite component are passed on (the input monitor stops the crane at once)
// and counted. A sample that cannot be deserialized, or whose seq is not above
// every seq its writer sent before (a replay), is dropped and counted; it counts as missing (no
// fresh stamp), so a stream of them makes the input stale. The safety
// decisions stay with the input monitor: kNoData before the first sample, kDisconnected when every
// matched writer has gone after one was matched (the sample then goes stale too), kOk otherwise.
//
// Plain C++17: no Fast DDS types (the C++20 command line includes it).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/input/command_source.hpp"
#include "craneassist/input/input_monitor.hpp"

namespace craneassist::dds {

struct CommandInputStats {
  std::uint64_t samples = 0;        // accepted from the operator holding the command
  std::uint64_t non_finite = 0;     // of those, with a NaN or infinite component
  std::uint64_t lost = 0;           // gaps in the operator's seq (best effort: dropped samples)
  std::uint64_t other_senders = 0;  // dropped: another writer held the command
  // Dropped: not deserializable (a bool byte other than 0 or 1, a bad encapsulation, a cut-off
  // body, ...), from any writer. Counted as missing: only such samples make the input stale.
  std::uint64_t malformed = 0;
  // Dropped: a seq not above what the same writer sent before (a replayed or repeated sample),
  // from any writer. Counted as missing, like malformed ones.
  std::uint64_t replayed = 0;
  int owner_changes = 0;    // writers that took the command (the first one too)
  int matched_writers = 0;  // authenticated, permitted writers matched now
  int peak_matched_writers = 0;
  int writer_matches = 0;      // writers matched over the run
  double first_match_s = -1;   // first writer matched, s after the source started; -1: never
  double first_sample_s = -1;  // first sample accepted, s after the source started; -1: never
  std::string sender;          // the sender field of the latest accepted sample ("" before any)
};

class DdsCommandSource : public input::CommandSource {
 public:
  // Creates the secure participant (settings.domain_id, settings.transport) and the reader of
  // craneassist/operator_command with the settings.commands.topic QoS. stale_timeout_s: the
  // input monitor's (InputMonitorSettings::stale_timeout_s), the silence after which another
  // writer may take the command over. Throws std::invalid_argument when settings.commands is
  // not enabled, a security file is missing or stale_timeout_s is not positive,
  // std::runtime_error when DDS (or DDS Security: bad certificate, key, signature) fails.
  explicit DdsCommandSource(const config::TelemetryConfig& settings,
                            double stale_timeout_s = input::InputMonitorSettings{}.stale_timeout_s);
  ~DdsCommandSource() override;
  DdsCommandSource(const DdsCommandSource&) = delete;
  DdsCommandSource& operator=(const DdsCommandSource&) = delete;

  input::SourceState poll(input::OperatorCommand& out) noexcept override;
  const char* name() const noexcept override { return "dds"; }

  // Any thread (not the loop: the sender string is copied under a mutex).
  CommandInputStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Throws std::invalid_argument naming what is missing when `settings` cannot run the DDS
// command input: commands.enabled false, or a commands.security file not given (the message
// points to docs/remote-commands.md).
void check_command_input_settings(const config::TelemetryConfig& settings);

}  // namespace craneassist::dds
