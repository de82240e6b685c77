// The DDS tools of the command line: `craneassist echo TOPIC` prints the samples of one topic,
// `craneassist dashboard` shows the telemetry live in the terminal (docs/dashboard.md). Both are
// plain subscribers: they work against any craneassist on the same DDS domain.
//
// Plain C++17 (no Fast DDS types): the C++20 command line includes it.
#pragma once

#include <cstdio>
#include <string>

#include "craneassist/config/telemetry_config.hpp"

namespace craneassist::dds {

// Exit codes, the same as the command line's (app/cli/exit_codes.hpp).
inline constexpr int kToolOk = 0;
inline constexpr int kToolUsage = 2;    // unknown topic, bad option
inline constexpr int kToolRuntime = 3;  // DDS could not be set up, or no data in time

enum class EchoFormat { kText, kCsv };

struct EchoOptions {
  std::string topic;  // short name (status, joints, ...) or DDS name (craneassist/status)
  int domain_id = 0;
  long count = 0;          // > 0: exit after this many samples; 0: until stopped
  double timeout_s = 0.0;  // > 0: fail (kToolRuntime) when no sample arrives this soon
  EchoFormat format = EchoFormat::kText;
  config::DdsTransport transport = config::DdsTransport::kDefault;
  config::TypePropagation type_propagation;  // the settings' type_propagation
  std::FILE* out = stdout;                   // the samples
  std::FILE* err = stderr;                   // discovery and error messages
};

struct DashboardOptions {
  int domain_id = 0;
  // One plain snapshot (no escape codes) as soon as every telemetry topic has delivered a
  // sample, then exit. Also when `out` is not a terminal.
  bool once = false;
  double timeout_s = 0.0;  // > 0: fail (kToolRuntime) when a telemetry topic stays silent
  config::DdsTransport transport = config::DdsTransport::kDefault;
  config::TypePropagation type_propagation;  // the settings' type_propagation
  double refresh_s = 0.1;                    // live view: redraw period
  // Also every value of the field table, from craneassist/fields (the snapshot waits for it).
  bool fields = false;
  std::FILE* out = stdout;
  std::FILE* err = stderr;
};

// Both return an exit code (kTool*). They run until done, or until request_stop().
int run_echo(const EchoOptions& options);
int run_dashboard(const DashboardOptions& options);

// Ends a running run_echo() or run_dashboard() within about 0.1 s; they then return kToolOk.
// Async-signal-safe: call it from a SIGINT or SIGTERM handler. The request stays until
// reset_stop().
void request_stop() noexcept;
bool stop_requested() noexcept;
void reset_stop() noexcept;

// The valid topic names, for messages: "status, joints, ... (or their DDS names, craneassist/...)".
std::string topic_names();

}  // namespace craneassist::dds
