// The telemetry publisher of `sim` and `replay` (telemetry_setup.hpp), with DDS.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>
#include <optional>

#include "craneassist/dds/telemetry_publisher.hpp"
#include "exit_codes.hpp"
#include "telemetry_observer.hpp"
#include "telemetry_setup.hpp"

namespace craneassist::cli {

struct Telemetry::Publishing {
  std::unique_ptr<dds::TelemetryPublisher> publisher;
  std::optional<TelemetryObserver> observer;
  int domain = 0;
  bool ros2 = false;
};

Telemetry::Telemetry() = default;
Telemetry::~Telemetry() = default;

control::CycleObserver* Telemetry::observer() {
  return publishing_ && publishing_->observer ? &*publishing_->observer : nullptr;
}

int Telemetry::open(const config::TelemetryConfig& settings, bool wanted,
                    const config::CraneConfig& cfg, const char* backend) {
  if (!wanted || !settings.enabled) return kExitOk;
  auto p = std::make_unique<Publishing>();
  try {
    p->publisher =
        std::make_unique<dds::TelemetryPublisher>(settings, cli::telemetry_info(cfg, backend));
  } catch (const std::exception& e) {
    spdlog::error("telemetry: {} (--no-telemetry runs without it)", e.what());
    return kExitRuntime;
  }
  p->observer.emplace(*p->publisher, cfg.model.dof());
  p->domain = settings.domain_id;
  publishing_ = std::move(p);
  spdlog::info(
      "telemetry: DDS domain {}, topics craneassist/status {:g} Hz, joints {:g} Hz, hydraulics "
      "{:g} Hz, command_path {:g} Hz ({})",
      settings.domain_id, settings.status.rate_hz, settings.joints.rate_hz,
      settings.hydraulics.rate_hz, settings.command_path.rate_hz, settings.source_name);
  if (settings.ros2.enabled) {
    spdlog::info(
        "telemetry: ROS 2 topics {0}/joint_states {1:g} Hz, {0}/craneassist/tip_velocity/command "
        "and .../reference {2:g} Hz (DDS names rt{0}/...; docs/ros.md)",
        settings.ros2.ros_namespace, settings.ros2.joint_states.rate_hz,
        settings.ros2.tip_velocity.rate_hz);
  }
  publishing_->ros2 = settings.ros2.enabled;
  return kExitOk;
}

void Telemetry::finish() {
  if (!publishing_) return;
  dds::TelemetryPublisher& publisher = *publishing_->publisher;
  publisher.close();
  const dds::PublisherStats s = publisher.stats();
  std::printf(
      "  telemetry: domain %d, %llu cycles, samples status %llu, joints %llu, hydraulics %llu, "
      "command_path %llu; %llu cycles dropped, %llu write errors\n",
      publishing_->domain, static_cast<unsigned long long>(s.frames_pushed),
      static_cast<unsigned long long>(s.samples_written[0]),
      static_cast<unsigned long long>(s.samples_written[1]),
      static_cast<unsigned long long>(s.samples_written[2]),
      static_cast<unsigned long long>(s.samples_written[3]),
      static_cast<unsigned long long>(s.frames_dropped),
      static_cast<unsigned long long>(s.write_errors));
  if (s.end_unacknowledged > 0) {
    std::printf(
        "  telemetry: the end of the run was not acknowledged on %d topic(s) within 0.5 s (a "
        "reader that left, or a slow network): watchers may not show it\n",
        s.end_unacknowledged);
  }
  std::printf(
      "  telemetry fields: %llu samples on craneassist/fields (every value of craneassist "
      "fields)\n",
      static_cast<unsigned long long>(s.samples_written[5]));
  if (s.samples_written[4] > 0) {  // a run with a wheeled base (sim --drive)
    std::printf("  telemetry base: %llu samples on craneassist/base\n",
                static_cast<unsigned long long>(s.samples_written[4]));
  }
  if (publishing_->ros2) {
    std::printf(
        "  telemetry ros2: samples joint_states %llu, tip_velocity/command %llu, "
        "tip_velocity/reference %llu\n",
        static_cast<unsigned long long>(s.ros2_samples_written[0]),
        static_cast<unsigned long long>(s.ros2_samples_written[1]),
        static_cast<unsigned long long>(s.ros2_samples_written[2]));
  }
  publishing_.reset();
}

}  // namespace craneassist::cli
