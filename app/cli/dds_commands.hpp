// `craneassist echo TOPIC`, `craneassist dashboard` and `craneassist web`: DDS subscribers that
// print one topic's samples, show the telemetry live in the terminal (docs/dashboard.md) or serve
// it to the web view (docs/web.md#watching-a-run). They have no link to the control loop: they
// work against any craneassist on the same DDS domain.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "web_view.hpp"

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
  bool fields = false;  // --fields
};

struct WebWatchArgs : DdsToolArgs {
  std::string crane_file;   // --config: the crane the page draws (empty: the K70M reference)
  std::string base_file;    // --base: the wheeled base it draws (empty: the shipped one)
  WebArgs web;              // --web-listen, --web-rate
  double duration_s = 0.0;  // > 0: serve this long; 0: until Ctrl-C or SIGTERM
};

CLI::App* add_echo_command(CLI::App& cli, EchoArgs& args);
int run_echo_command(const EchoArgs& args);

CLI::App* add_dashboard_command(CLI::App& cli, DashboardArgs& args);
int run_dashboard_command(const DashboardArgs& args);

CLI::App* add_web_watch_command(CLI::App& cli, WebWatchArgs& args);
int run_web_watch_command(const WebWatchArgs& args);

}  // namespace craneassist::cli
