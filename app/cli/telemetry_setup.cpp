#include "telemetry_setup.hpp"

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
  command.add_flag("--ros2", args.ros2,
                   std::string("Also publish the standard ROS 2 topics /joint_states and "
                               "/craneassist/tip_velocity/{command,reference} (docs/ros.md)") +
                       (on_by_default ? "" : "; implies --telemetry"));
}

config::TelemetryConfig load_telemetry_settings(const TelemetryArgs& args) {
  config::TelemetryConfig c = args.config_file.empty()
                                  ? config::default_telemetry_config()
                                  : config::load_telemetry_config(args.config_file);
  if (args.domain) c.domain_id = *args.domain;
  if (args.ros2) c.ros2.enabled = true;
  return c;
}

}  // namespace craneassist::cli
