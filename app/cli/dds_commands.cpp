#include "dds_commands.hpp"

#include <csignal>
#include <cstdio>

#include "craneassist/config/config_error.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/tools.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {
namespace {

static_assert(dds::kToolOk == kExitOk && dds::kToolUsage == kExitUsage &&
              dds::kToolRuntime == kExitRuntime);

extern "C" void on_dds_tool_stop_signal(int) {
  dds::request_stop();
}

// SIGINT, SIGTERM and SIGHUP end the tool cleanly (exit 0) while it runs; the defaults after.
class StopOnSignal {
 public:
  StopOnSignal() {
    dds::reset_stop();
    struct sigaction sa = {};
    sa.sa_handler = on_dds_tool_stop_signal;  // no SA_RESTART: a wait ends at once
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGHUP, &sa, nullptr);  // the terminal or the ssh session went away
  }
  ~StopOnSignal() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::signal(SIGHUP, SIG_DFL);
  }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
};

void add_common_options(CLI::App& app, DdsToolArgs& args, const char* timeout_help) {
  app.add_option("--telemetry-config", args.config_file,
                 "DDS settings (docs/telemetry.md): domain_id, transport and type_propagation "
                 "(default: the embedded config/telemetry/default.yaml)")
      ->check(CLI::ExistingFile);
  app.add_option("--domain", args.domain_id,
                 "DDS domain id (default: the settings' domain_id, 0 in the shipped ones)")
      ->check(CLI::Range(0, 232));
  app.add_option("--timeout", args.timeout_s, timeout_help)->check(FiniteRange(1e-3, 1e6));
  app.add_option("--transport", args.transport,
                 "default (shared memory and UDP), udp (UDPv4 only) or shm (shared memory only); "
                 "default: the settings' transport")
      ->check(CLI::IsMember(names_of(config::kDdsTransports)));
}

// The settings with the options' overrides; nullopt (after saying why on stderr, with echo's and
// the dashboard's other errors: stdout is for the samples) when the file is bad.
std::optional<config::TelemetryConfig> tool_settings(const DdsToolArgs& args) {
  config::TelemetryConfig c;
  try {
    c = args.config_file.empty() ? config::default_telemetry_config()
                                 : config::load_telemetry_config(args.config_file);
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "craneassist: error: config: %s\n", e.what());
    return std::nullopt;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "craneassist: error: %s\n", e.what());
    return std::nullopt;
  }
  if (args.domain_id) c.domain_id = *args.domain_id;
  if (!args.transport.empty()) c.transport = config::parse_dds_transport(args.transport).value();
  return c;
}

// The settings and the options add_common_options() added, into the tool's options.
template <class ToolOptions>
void apply_common_options(ToolOptions& o, const DdsToolArgs& args,
                          const config::TelemetryConfig& settings) {
  o.domain_id = settings.domain_id;
  o.timeout_s = args.timeout_s;
  o.transport = settings.transport;
  o.type_propagation = settings.type_propagation;
}

}  // namespace

CLI::App* add_echo_command(CLI::App& cli, EchoArgs& args) {
  auto* echo = cli.add_subcommand(
      "echo", "Print the samples of one DDS topic as they arrive (docs/dashboard.md)");
  echo->add_option("topic", args.topic,
                   "status, joints, hydraulics, command_path, operator_command (or the DDS name, "
                   "craneassist/status, ...)")
      ->required();
  echo->add_option("--count", args.count, "Exit after this many samples (default: until Ctrl-C)")
      ->check(CLI::PositiveNumber);
  echo->add_option("--format", args.format,
                   "text: a block per sample, field names and SI units; csv: a header line, then "
                   "one row per sample")
      ->check(CLI::IsMember({"text", "csv"}))
      ->capture_default_str();
  add_common_options(*echo, args, "Fail (exit 3) when no sample arrives within this many seconds");
  return echo;
}

int run_echo_command(const EchoArgs& args) {
  const auto settings = tool_settings(args);
  if (!settings) return kExitUsage;
  dds::EchoOptions o;
  o.topic = args.topic;
  o.count = args.count;
  o.format = args.format == "csv" ? dds::EchoFormat::kCsv : dds::EchoFormat::kText;
  apply_common_options(o, args, *settings);
  StopOnSignal stop;
  return dds::run_echo(o);
}

CLI::App* add_dashboard_command(CLI::App& cli, DashboardArgs& args) {
  auto* dashboard = cli.add_subcommand(
      "dashboard",
      "Live terminal view of craneassist's DDS telemetry (docs/dashboard.md); q quits");
  dashboard->add_flag("--once", args.once,
                      "Print one plain snapshot once every telemetry topic has a sample, then "
                      "exit (also when stdout is not a terminal)");
  add_common_options(*dashboard, args,
                     "Fail (exit 3) when a telemetry topic has no sample within this many seconds");
  return dashboard;
}

int run_dashboard_command(const DashboardArgs& args) {
  const auto settings = tool_settings(args);
  if (!settings) return kExitUsage;
  dds::DashboardOptions o;
  o.once = args.once;
  apply_common_options(o, args, *settings);
  StopOnSignal stop;
  return dds::run_dashboard(o);
}

}  // namespace craneassist::cli
