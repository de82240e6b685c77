#include "dds_commands.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "crane_options.hpp"
#include "craneassist/config/base_config.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/config/telemetry_config.hpp"
#include "craneassist/dds/telemetry_watch.hpp"
#include "craneassist/dds/tools.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"
#include "telemetry_observer.hpp"

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

// Runs a tool (dds::run_echo, dds::run_dashboard) with its own options o and the settings and
// common options, ending cleanly on a signal; kExitUsage when the settings file is bad.
template <class ToolOptions, class Run>
int run_tool(const DdsToolArgs& args, ToolOptions o, Run run) {
  const auto settings = tool_settings(args);
  if (!settings) return kExitUsage;
  apply_common_options(o, args, *settings);
  StopOnSignal stop;
  return run(o);
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
  dds::EchoOptions o;
  o.topic = args.topic;
  o.count = args.count;
  o.format = args.format == "csv" ? dds::EchoFormat::kCsv : dds::EchoFormat::kText;
  return run_tool(args, o, dds::run_echo);
}

CLI::App* add_dashboard_command(CLI::App& cli, DashboardArgs& args) {
  auto* dashboard = cli.add_subcommand(
      "dashboard",
      "Live terminal view of craneassist's DDS telemetry (docs/dashboard.md); q quits");
  dashboard->add_flag("--once", args.once,
                      "Print one plain snapshot once every telemetry topic has a sample, then "
                      "exit (also when stdout is not a terminal)");
  dashboard->add_flag("--fields", args.fields,
                      "Also every value of the field table (craneassist/fields, with its unit; "
                      "craneassist fields)");
  add_common_options(*dashboard, args,
                     "Fail (exit 3) when a telemetry topic has no sample within this many seconds");
  return dashboard;
}

int run_dashboard_command(const DashboardArgs& args) {
  dds::DashboardOptions o;
  o.once = args.once;
  o.fields = args.fields;
  return run_tool(args, o, dds::run_dashboard);
}

CLI::App* add_web_watch_command(CLI::App& cli, WebWatchArgs& args) {
  auto* web = cli.add_subcommand(
      "web",
      "Serve the web view (3-D crane, gauges, live plots) of a craneassist sim or replay running "
      "elsewhere, from its DDS telemetry; a view only (docs/web.md#watching-a-run)");
  add_config_option(*web, args.crane_file)
      ->description(
          "The crane config of the watched run: the page draws its geometry (default: "
          "the embedded K70M reference crane)");
  web->add_option("--base", args.base_file,
                  "The wheeled base config of a run on a base (sim --drive): the page draws its "
                  "chassis and wheels (default: the embedded config/machines/mobile_base.yaml)")
      ->check(CLI::ExistingFile);
  web->add_option("--web-listen", args.web.listen,
                  "Where the page is served, ADDR:PORT (port 0: any free port)")
      ->capture_default_str();
  web->add_option("--web-rate", args.web.frame_rate_hz, "Frames per second streamed to each page")
      ->check(FiniteRange(1.0, 100.0))
      ->capture_default_str();
  web->add_option("--duration", args.duration_s,
                  "Serve this many seconds, then exit (default: until Ctrl-C)")
      ->check(FiniteRange(1e-3, 1e7));
  add_common_options(*web, args,
                     "Fail (exit 3) when no telemetry arrives within this many seconds (default: "
                     "wait)");
  return web;
}

namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// What the watched run says that the page cannot draw right: another crane's joints.
void warn_if_other_crane(const dds::WatchedRun& run, const config::CraneConfig& cfg) {
  std::vector<std::string> expected;
  for (const auto& j : cfg.model.joints) expected.push_back(j.name);
  if (!run.joint_names.empty() && run.joint_names != expected) {
    spdlog::warn(
        "web: the watched crane's joints ({}) are not --config's ({}): the page draws --config's "
        "crane; give the watched run's config",
        joined(run.joint_names), joined(expected));
  } else if (!run.crane.empty() && run.crane != cfg.model.name) {
    spdlog::warn("web: watching crane '{}' while --config is '{}'", run.crane, cfg.model.name);
  }
}

}  // namespace

// The page's status of a watched run that went silent before it said it stopped.
constexpr const char* kLost = "lost";
constexpr const char* kLostReason = "no telemetry: the watched run died or its network failed";

int run_web_watch_command(const WebWatchArgs& args) {
  const auto settings = tool_settings(args);
  if (!settings) return kExitUsage;
  config::CraneConfig cfg;
  config::BaseConfig base;
  try {
    cfg = load_crane(args.crane_file);
    base = config::load_base_or_default(args.base_file);
  } catch (...) {
    return input_error_exit("config");
  }
  WebView view;
  // The base is drawn only while the watched run sends one (craneassist/base).
  if (const int rc = view.open(args.web, cfg, /*commands=*/false, &base.model); rc != kExitOk) {
    return rc;
  }
  std::unique_ptr<dds::TelemetryWatch> watch;
  try {
    dds::WatchOptions o;
    o.domain_id = settings->domain_id;
    o.transport = settings->transport;
    o.type_propagation = settings->type_propagation;
    o.status = settings->status;
    watch = std::make_unique<dds::TelemetryWatch>(o);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  spdlog::info("web: watching the telemetry on DDS domain {} (a view only: drive with `sim --web`)",
               settings->domain_id);
  StopOnSignal stop;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto elapsed_s = [&] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  // A run that goes silent before it says it stopped has died (or its network has): after three
  // periods of its fastest topic, at least 1 s (the dashboard's STALE), the page says so.
  const double fastest_hz =
      std::max({settings->status.rate_hz, settings->joints.rate_hz, settings->hydraulics.rate_hz,
                settings->command_path.rate_hz});
  const double lost_after_s = std::max(1.0, fastest_hz > 0.0 ? 3.0 / fastest_hz : 1.0);
  dds::TelemetryFrame frame;
  control::LogRow row;
  std::uint64_t seen = 0;  // 0: nothing received yet
  bool announced = false;
  bool lost = false;
  bool told_incompatible = false;  // checked every 100 polls (0.5 s)
  unsigned polls = 0;
  double last_sample_s = 0.0;
  std::string last_status;
  int rc = kExitOk;
  while (!dds::stop_requested()) {
    if (args.duration_s > 0.0 && elapsed_s() >= args.duration_s) break;
    if (watch->latest(frame, seen)) {
      last_sample_s = elapsed_s();
      if (lost) {
        lost = false;
        spdlog::info("web: receiving from the watched run again");
      }
      from_frame(frame, row);
      view.publish(row);
      if (!announced) {  // once the status (the crane's name) and the joints are in
        const dds::WatchedRun run = watch->run();
        if (!run.crane.empty() && !run.joint_names.empty()) {
          announced = true;
          spdlog::info("web: receiving from crane '{}' ({} backend), {:.2f} s after start",
                       run.crane, run.backend, elapsed_s());
          warn_if_other_crane(run, cfg);
        }
      }
      if (last_status != frame.status) {
        last_status = frame.status;
        if (last_status == "stopped") {
          spdlog::info("web: the watched run stopped{}{}", *frame.stop_reason ? ": " : "",
                       frame.stop_reason);
        }
      }
    } else if (seen != 0 && !lost && last_status != "stopped" &&
               elapsed_s() - last_sample_s > lost_after_s) {
      lost = true;
      last_status = kLost;
      frame.status = kLost;
      frame.stop_reason = kLostReason;
      from_frame(frame, row);
      view.publish(row);
      spdlog::warn(
          "web: no telemetry from the watched run for {:.1f} s before it said it stopped: "
          "it died, or its network failed",
          elapsed_s() - last_sample_s);
    } else if (seen == 0 && args.timeout_s > 0.0 && elapsed_s() > args.timeout_s) {
      const dds::WatchedRun run = watch->run();
      spdlog::error(
          "web: no telemetry on DDS domain {} within {:g} s ({} writers discovered; is a sim "
          "running, or a replay with --telemetry, on this domain? docs/telemetry.md)",
          settings->domain_id, args.timeout_s, run.writers);
      rc = kExitRuntime;
      break;
    }
    if (!told_incompatible && ++polls % 100 == 0 && watch->run().status_incompatible > 0) {
      told_incompatible = true;
      spdlog::warn(
          "web: a run publishes its status with a QoS that does not give the {}, {} status this "
          "watcher asks for (from {}): its status and end will not show; give `web` the run's "
          "--telemetry-config",
          to_string(settings->status.reliability), to_string(settings->status.durability),
          settings->source_name);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const dds::WatchedRun run = watch->run();
  std::printf("  web watch: %llu samples from crane '%s', %llu malformed\n%s\n",
              static_cast<unsigned long long>(run.samples), run.crane.c_str(),
              static_cast<unsigned long long>(run.malformed), view.report().c_str());
  return rc;
}

}  // namespace craneassist::cli
