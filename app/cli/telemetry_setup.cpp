#include "telemetry_setup.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <exception>

#include "exit_codes.hpp"

namespace craneassist::cli {

void add_telemetry_options(CLI::App& command, TelemetryArgs& args, bool on_by_default) {
  if (on_by_default) {
    command.add_flag("--no-telemetry", args.off, "Do not publish DDS telemetry");
  } else {
    command.add_flag("--telemetry", args.on,
                     "Publish DDS telemetry while the replay runs (docs/telemetry.md)");
  }
  command
      .add_option("--telemetry-config", args.config_file,
                  "DDS settings YAML: domain, topic rates and QoS, command input "
                  "(default: the embedded config/telemetry/default.yaml)")
      ->check(CLI::ExistingFile);
  command.add_option("--domain", args.domain, "DDS domain id (overrides the settings file)")
      ->check(CLI::Range(0, 232));
}

config::TelemetryConfig load_telemetry_settings(const TelemetryArgs& args) {
  config::TelemetryConfig c = args.config_file.empty()
                                  ? config::default_telemetry_config()
                                  : config::load_telemetry_config(args.config_file);
  if (args.domain) c.domain_id = *args.domain;
  return c;
}

int Telemetry::open(const config::TelemetryConfig& settings, bool wanted,
                    const config::CraneConfig& cfg, const char* backend) {
  if (!wanted || !settings.enabled) return kExitOk;
  try {
    publisher_ =
        std::make_unique<dds::TelemetryPublisher>(settings, cli::telemetry_info(cfg, backend));
  } catch (const std::exception& e) {
    spdlog::error("telemetry: {} (--no-telemetry runs without it)", e.what());
    return kExitRuntime;
  }
  observer_.emplace(*publisher_, cfg.model.dof());
  domain_ = settings.domain_id;
  spdlog::info(
      "telemetry: DDS domain {}, topics craneassist/status {:g} Hz, joints {:g} Hz, hydraulics "
      "{:g} Hz, command_path {:g} Hz ({})",
      settings.domain_id, settings.status.rate_hz, settings.joints.rate_hz,
      settings.hydraulics.rate_hz, settings.command_path.rate_hz, settings.source_name);
  return kExitOk;
}

void Telemetry::finish() {
  if (!publisher_) return;
  publisher_->close();
  const dds::PublisherStats s = publisher_->stats();
  std::printf(
      "  telemetry: domain %d, %llu cycles, samples status %llu, joints %llu, hydraulics %llu, "
      "command_path %llu; %llu cycles dropped, %llu write errors\n",
      domain_, static_cast<unsigned long long>(s.frames_pushed),
      static_cast<unsigned long long>(s.samples_written[0]),
      static_cast<unsigned long long>(s.samples_written[1]),
      static_cast<unsigned long long>(s.samples_written[2]),
      static_cast<unsigned long long>(s.samples_written[3]),
      static_cast<unsigned long long>(s.frames_dropped),
      static_cast<unsigned long long>(s.write_errors));
  observer_.reset();
  publisher_.reset();
}

}  // namespace craneassist::cli
