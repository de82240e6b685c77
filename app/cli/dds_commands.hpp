// `craneassist echo TOPIC` and `craneassist dashboard`: DDS subscribers that print one topic's
// samples or show the telemetry live (docs/dashboard.md). They need no crane config and have
// no link to the control loop: they work against any craneassist on the same DDS domain.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace craneassist::cli {

struct EchoArgs {
  std::string topic;
  int domain_id = 0;  // default: the shipped telemetry config's
  long count = 0;     // 0: until Ctrl-C or SIGTERM
  double timeout_s = 0.0;
  std::string format = "text";
  std::string transport = "default";
};

struct DashboardArgs {
  int domain_id = 0;
  bool once = false;
  double timeout_s = 0.0;
  std::string transport = "default";
};

CLI::App* add_echo_command(CLI::App& cli, EchoArgs& args);
int run_echo_command(const EchoArgs& args);

CLI::App* add_dashboard_command(CLI::App& cli, DashboardArgs& args);
int run_dashboard_command(const DashboardArgs& args);

}  // namespace craneassist::cli
