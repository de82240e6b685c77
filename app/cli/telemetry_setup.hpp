// DDS telemetry of `craneassist sim` and `craneassist replay`: the options, the settings file
// (config/telemetry/default.yaml or --telemetry-config), and the publisher with its loop
// observer. One place for both commands. The options and settings are always there
// (telemetry_setup.cpp); the publisher is built from app/dds (telemetry_dds.cpp), or in a build
// without DDS (CRANEASSIST_DDS=OFF) runs without telemetry and says so (telemetry_none.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/control/control_loop.hpp"

namespace craneassist::cli {

struct TelemetryArgs {
  bool on = false;            // replay: --telemetry (replay publishes only when asked)
  bool off = false;           // sim: --no-telemetry
  std::string config_file;    // --telemetry-config FILE; empty: the embedded default
  std::optional<int> domain;  // --domain N overrides the file's domain_id
  bool ros2 = false;          // --ros2: also the standard ROS 2 topics (settings ros2.enabled)

  // replay: whether the options ask for telemetry.
  bool asked() const { return on || ros2 || !config_file.empty(); }
};

// sim (publishes by default, as the settings file says): --no-telemetry, --telemetry-config,
// --domain, --ros2. replay (off by default): --telemetry, --telemetry-config and --ros2 (both
// imply --telemetry), --domain.
void add_telemetry_options(CLI::App& command, TelemetryArgs& args, bool on_by_default);

// Reads the settings file and applies --domain; throws config::ConfigError.
config::TelemetryConfig load_telemetry_settings(const TelemetryArgs& args);

class Telemetry {
 public:
  Telemetry();
  ~Telemetry();
  Telemetry(const Telemetry&) = delete;
  Telemetry& operator=(const Telemetry&) = delete;

  // Starts publishing when `wanted` (and the settings enable it); returns kExitOk, or logs why
  // DDS could not start and returns kExitRuntime. Without DDS: warns and returns kExitOk.
  int open(const config::TelemetryConfig& settings, bool wanted, const config::CraneConfig& cfg,
           const char* backend);
  // The loop observer, or nullptr when not publishing.
  control::CycleObserver* observer();
  // Publishes the last frames, prints the counters line.
  void finish();

 private:
  struct Publishing;
  std::unique_ptr<Publishing> publishing_;
};

}  // namespace craneassist::cli
