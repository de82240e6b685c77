// Watches the telemetry of a running craneassist (`craneassist web`, docs/web.md#watching-a-run):
// subscribes to the four telemetry topics and assembles the latest sample of each into one
// TelemetryFrame, as the publishing loop had it. Plain C++17 (no Fast DDS types).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/telemetry_frame.hpp"

namespace craneassist::dds {

struct WatchOptions {
  int domain_id = 0;
  config::DdsTransport transport = config::DdsTransport::kDefault;
  config::TypePropagation type_propagation;
  std::string participant_name = "craneassist-web";
  // The watched run's status topic as it publishes it (the telemetry settings' `status`): the
  // status reader takes its reliability and durability, so that the end of a run (`stopped`,
  // the last sample a run sends) is delivered and acknowledged, not dropped as a best-effort
  // sample can be. The other topics are read best-effort (the latest sample is enough).
  config::TopicSettings status{10.0, config::Reliability::kReliable,
                               config::Durability::kTransientLocal, 1};
};

// What the watched run says about itself (its latest status and joints samples).
struct WatchedRun {
  std::string crane;    // Status.crane
  std::string backend;  // Status.backend
  std::vector<std::string> joint_names;
  std::uint64_t samples = 0;    // every topic, so far
  std::uint64_t malformed = 0;  // dropped: could not be deserialized
  int writers = 0;              // matched on this side, all topics
  // Status writers not matched because their QoS does not give what the status reader asks
  // (WatchOptions::status): a run published with other telemetry settings.
  int status_incompatible = 0;
};

class TelemetryWatch {
 public:
  // Throws std::runtime_error when DDS cannot be set up.
  explicit TelemetryWatch(const WatchOptions& options);
  ~TelemetryWatch();
  TelemetryWatch(const TelemetryWatch&) = delete;
  TelemetryWatch& operator=(const TelemetryWatch&) = delete;

  // The latest state into `out` when a sample arrived since `seen` (then `seen` is updated);
  // false otherwise. The joints sample's header sets cycle, t_s and stamp_ns. The text fields
  // point to interned copies that live as long as the program (TelemetryFrame's rule).
  bool latest(TelemetryFrame& out, std::uint64_t& seen) const;
  WatchedRun run() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace craneassist::dds
