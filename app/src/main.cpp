// craneassist: boom-tip control for hydraulic cranes. The composition root: command line,
// config loading, wiring of the pipeline and the backend, the summary.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "craneassist/app/csv_log.hpp"
#include "craneassist/app/embedded_replays.hpp"
#include "craneassist/app/replay_runner.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/quantity.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"

namespace {

using namespace craneassist;

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;    // bad command line, config or replay file
constexpr int kExitRuntime = 3;  // the run itself failed

struct ReplayArgs {
  std::string replay_file;  // empty: the bundled demo
  std::string config_file;  // empty: the embedded reference crane
  std::string backend = "sim";
  std::string log_file = "craneassist-log.csv";
  bool no_log = false;
  bool no_scaling = false;
  bool realtime = false;
  double settle_s = 1.0;
  std::optional<double> payload_kg;
  std::string pump_max_flow;      // quantity text, e.g. "120 L/min"
  std::string prime_mover_power;  // quantity text, e.g. "60 kW"
};

// Applies a quantity given on the command line ("120 L/min") or throws CLI-style.
double cli_quantity(const std::string& option, const std::string& text, config::Dimension dim) {
  std::string error;
  const auto q = config::parse_quantity(text, dim, error);
  if (!q || q->si_values.size() != 1 || q->si_values[0] <= 0.0) {
    throw CLI::ValidationError(option, error.empty() ? "expected one positive value" : error);
  }
  return q->si_values[0];
}

void print_summary(const app::RunSummary& s, const config::CraneConfig& cfg,
                   const std::string& replay_name, const ReplayArgs& args, const app::CsvLog* log) {
  const double speedup = s.wall_time_s > 0.0 ? s.duration_s / s.wall_time_s : 0.0;
  std::printf("craneassist replay: %s on %s\n", replay_name.c_str(), cfg.model.name.c_str());
  std::printf("  backend %s, scaling %s, control %.0f Hz\n", args.backend.c_str(),
              args.no_scaling ? "off (--no-scaling)" : "flow prescaling", cfg.control.rate_hz);
  std::printf("  ran %.2f s of machine time in %.3f s (%.0fx real time), %d cycles\n", s.duration_s,
              s.wall_time_s, speedup, s.cycles);
  std::printf("  tip: path %.2f m, peak speed %.2f m/s\n", s.tip_path_m, s.peak_tip_speed_m_s);
  std::printf(
      "  tip direction error, commanded vs measured (steady, > 0.05 m/s): max %.2f deg, "
      "rms %.2f deg over %d cycles\n",
      s.max_direction_error_deg, s.rms_direction_error_deg, s.direction_samples);
  std::printf(
      "  pump: energy %.1f kJ, peak power %.1f kW (limit %.1f kW), peak flow %.0f L/min, "
      "saturated in %d cycles\n",
      s.energy_j / 1e3, s.peak_power_w / 1e3, cfg.model.pump.prime_mover_power_w / 1e3,
      s.peak_flow_m3_s * 60e3, s.pump_saturated_cycles);
  std::printf("  active limit (cycles):");
  for (std::size_t i = 0; i < s.limit_cycles.size(); ++i) {
    if (s.limit_cycles[i] > 0) {
      std::printf(" %s %d", scaling::to_string(static_cast<scaling::ActiveLimit>(i)),
                  s.limit_cycles[i]);
    }
  }
  std::printf("\n");
  if (log != nullptr) {
    std::printf("  log: %s (%zu rows%s)\n", log->path().c_str(), log->rows_written(),
                s.log_rows_dropped > 0 ? ", SOME DROPPED" : "");
  }
}

int run_replay_command(const ReplayArgs& args) {
  config::CraneConfig cfg;
  std::optional<input::Replay> loaded;
  try {
    cfg = args.config_file.empty() ? config::default_crane_config()
                                   : config::load_crane_config(args.config_file);
    if (args.payload_kg) config::set_payload_mass(cfg.model, *args.payload_kg);
    if (!args.pump_max_flow.empty()) {
      cfg.model.pump.max_flow_m3_s =
          cli_quantity("--pump-max-flow", args.pump_max_flow, config::Dimension::kFlow);
    }
    if (!args.prime_mover_power.empty()) {
      cfg.model.pump.prime_mover_power_w =
          cli_quantity("--prime-mover-power", args.prime_mover_power, config::Dimension::kPower);
    }
    if (args.replay_file.empty()) {
      loaded = input::Replay::parse(app::embedded::kDemoReplayCsv,
                                    "<bundled examples/replays/demo.csv>");
    } else {
      loaded = input::Replay::load_file(args.replay_file);
    }
  } catch (const config::ConfigError& e) {
    spdlog::error("config: {}", e.what());
    return kExitUsage;
  } catch (const input::ReplayError& e) {
    spdlog::error("replay: {}", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitUsage;
  }

  const input::Replay& replay = *loaded;
  const std::string replay_name(replay.source_name());
  try {
    sim_backend::SimBackend machine(cfg.model, {cfg.simulation.step_s, cfg.simulation.q_initial});
    std::optional<app::CsvLog> log;
    if (!args.no_log) log.emplace(args.log_file, cfg.model.dof());
    app::RunOptions options;
    options.controller.flow_prescaling = !args.no_scaling;
    options.realtime = args.realtime;
    options.settle_s = args.settle_s;
    spdlog::info("running {} ({:.1f} s) on {} with the {} backend{}", replay_name,
                 replay.end_time_s() + args.settle_s, cfg.model.name, machine.name(),
                 args.realtime ? ", paced at real time" : "");
    const app::RunSummary summary =
        app::run_replay(cfg, replay, machine, options, log ? &*log : nullptr);
    print_summary(summary, cfg, replay_name, args, log ? &*log : nullptr);
    if (summary.log_rows_dropped > 0) {
      spdlog::warn("the log writer fell behind: {} rows dropped", summary.log_rows_dropped);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"craneassist: boom-tip control for hydraulic cranes"};
  cli.set_version_flag("--version", "craneassist 0.1.0");
  cli.require_subcommand(1);
  spdlog::set_pattern("craneassist: %^%l%$: %v");

  ReplayArgs args;
  auto* replay = cli.add_subcommand(
      "replay", "Drive the crane from a replay file (default: the bundled demo) and log the run");
  replay
      ->add_option("file", args.replay_file,
                   "Replay CSV (t,v_x,v_y,v_z); see docs/replay-format.md")
      ->check(CLI::ExistingFile);
  replay
      ->add_option("--config", args.config_file,
                   "Crane config YAML (default: the embedded K70M reference crane)")
      ->check(CLI::ExistingFile);
  replay->add_option("--backend", args.backend, "Machine backend")
      ->check(CLI::IsMember({"sim"}))
      ->capture_default_str();
  replay->add_option("--log", args.log_file, "Per-cycle CSV log (docs/log-format.md)")
      ->capture_default_str();
  replay->add_flag("--no-log", args.no_log, "Do not write the log");
  replay->add_flag(
      "--no-scaling", args.no_scaling,
      "Pass the command through without flow prescaling (to see what scaling prevents)");
  replay->add_flag("--realtime", args.realtime,
                   "Pace the loop at real time (default: as fast as possible)");
  replay->add_option("--settle", args.settle_s, "Seconds to keep running after the last replay row")
      ->check(CLI::Range(0.0, 600.0))
      ->capture_default_str();
  replay->add_option("--payload", args.payload_kg, "Payload mass in the grapple, kg")
      ->check(CLI::Range(0.0, 100000.0));
  replay->add_option("--pump-max-flow", args.pump_max_flow,
                     "Override the pump's maximum flow, e.g. \"120 L/min\"");
  replay->add_option("--prime-mover-power", args.prime_mover_power,
                     "Override the power available to the pump, e.g. \"60 kW\"");

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2, like a bad config or replay.
    return cli.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  if (*replay) {
    try {
      return run_replay_command(args);
    } catch (const CLI::Error& e) {
      cli.exit(e);
      return kExitUsage;
    }
  }
  return kExitUsage;
}
