// `craneassist echo TOPIC` and `craneassist dashboard`: DDS subscribers that print one topic's
// samples or show the telemetry live (docs/dashboard.md). They need no crane config and have
// no link to the control loop: they work against any craneassist on the same DDS domain.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace craneassist::cli {

// Both read the DDS settings (domain, transport, type_propagation) from --telemetry-config FILE
// or the shipped default; --domain and --transport override them.
struct DdsToolArgs {
  std::string config_file;
  std::optional<int> domain_id;
  std::string transport;  // "": the settings'
  double timeout_s = 0.0;
};

struct EchoArgs : DdsToolArgs {
  std::string topic;
  long count = 0;  // 0: until Ctrl-C or SIGTERM
  std::string format = "text";
};

struct DashboardArgs : DdsToolArgs {
  bool once = false;
};

CLI::App* add_echo_command(CLI::App& cli, EchoArgs& args);
int run_echo_command(const EchoArgs& args);

CLI::App* add_dashboard_command(CLI::App& cli, DashboardArgs& args);
int run_dashboard_command(const DashboardArgs& args);

}  // namespace craneassist::cli
