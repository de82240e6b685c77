// The loop's side of DDS telemetry: each cycle's log row becomes a dds::TelemetryFrame handed
// to the TelemetryPublisher's ring (copy only: no lock, no allocation, no I/O on the loop
// thread).
#pragma once

#include <cstdint>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"
#include "craneassist/dds/telemetry_frame.hpp"
#include "craneassist/dds/telemetry_publisher.hpp"

namespace craneassist::cli {

class TelemetryObserver final : public control::CycleObserver {
 public:
  TelemetryObserver(dds::TelemetryPublisher& publisher, int dof)
      : publisher_(publisher), dof_(dof) {}
  void on_cycle(const control::CycleRecord& cycle) noexcept override;

 private:
  dds::TelemetryPublisher& publisher_;
  int dof_;
  std::uint64_t cycle_ = 0;
  dds::TelemetryFrame frame_;
};

// What stays fixed for a run: model name, joint names, limits, pump mode.
dds::TelemetryInfo telemetry_info(const config::CraneConfig& config, const char* backend);

// Copies a log row into a telemetry frame (the cycle number is the caller's).
void to_frame(const control::LogRow& row, int dof, dds::TelemetryFrame& frame) noexcept;
// The reverse (`craneassist web`: a frame assembled from another process's telemetry). The
// frame's first `dof` joints; the row's others stay as they were.
void from_frame(const dds::TelemetryFrame& frame, control::LogRow& row) noexcept;

}  // namespace craneassist::cli
