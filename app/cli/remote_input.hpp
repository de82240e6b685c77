// The remote operator input of `craneassist sim --input dds` (DDS Security,
// docs/remote-commands.md), behind a seam: built from app/dds (remote_input_dds.cpp), or in a
// build without DDS (CRANEASSIST_DDS=OFF) refused with a clear message (remote_input_none.cpp).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/input/command_source.hpp"

namespace craneassist::cli {

// What the input dropped and who took the command, for the log (docs/remote-commands.md).
struct RemoteInputEvents {
  std::uint64_t malformed = 0;  // samples that could not be deserialized
  std::uint64_t replayed = 0;   // samples whose seq was not new for their writer
  int operator_changes = 0;     // writers that took the command (the first one too)
};

struct RemoteInput {
  std::unique_ptr<input::CommandSource> source;
  // The operator now sending (OperatorCommand.sender), "" before the first sample. Any thread.
  std::function<std::string()> sender;
  // The counts so far. Any thread, while `source` is alive.
  std::function<RemoteInputEvents()> events;
  // The run's summary line ("  dds input: ..."). Call while `source` is alive.
  std::function<std::string()> report;
};

// False in a build without DDS.
bool remote_input_available();

// Throws std::invalid_argument naming what is missing when `settings` cannot run the input.
void check_remote_input_settings(const config::TelemetryConfig& settings);

// Opens the input (its own DDS Security participant); stale_timeout_s is the input monitor's
// (another operator takes the command over only after the holder has been silent that long).
// Throws std::runtime_error when DDS fails.
RemoteInput open_remote_input(const config::TelemetryConfig& settings, double stale_timeout_s);

}  // namespace craneassist::cli
