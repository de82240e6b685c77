#include "research/experiment_command.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <optional>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/studies/sine_path_experiment.hpp"
#include "exit_codes.hpp"
#include "option_checks.hpp"

namespace craneassist::cli {

int run_experiment_command(const ExperimentArgs& args) {
  config::CraneConfig cfg;
  try {
    cfg = args.config_file.empty() ? config::planar_2r_config()
                                   : config::load_crane_config(args.config_file);
  } catch (const config::ConfigError& e) {
    spdlog::error("config: {}", e.what());
    return kExitUsage;
  }
  if (cfg.model.dof() != 2) {
    spdlog::error("config: {}: the 2R experiment needs a two-joint model", cfg.source_name);
    return kExitUsage;
  }
  try {
    studies::SinePathOptions options;
    options.sdot_request = args.speed;
    options.duration_s = args.duration_s;
    options.jerk_max = args.jerk_max;
    options.power_bound = dynamics::parse_power_bound(args.power_bound).value();
    dynamics::JointVector q0, f1, f2;
    studies::sine_path(0.0, q0, f1, f2);
    options.pump_power_limiter = args.pump_limiter;
    sim_backend::SimSettings settings = offline::sim_settings(cfg);
    settings.q_initial = q0;
    sim_backend::SimBackend machine(studies::machine_model(cfg, options), settings);
    std::optional<control::CsvLog> log;
    if (!args.no_log) log.emplace(args.log_file, cfg.model.dof());
    const auto s = studies::run_sine_path(cfg, options, machine, log ? &*log : nullptr);
    if (log) log->close();
    const double p_max = cfg.model.pump.prime_mover_power_w;
    std::printf("craneassist experiment-2r: %s, f(s) = [pi/6 - sin s, -pi/6 - 0.5 sin s]\n",
                cfg.model.name.c_str());
    std::printf("  power bound %s, requested sdot %.2f 1/s, jerk bound %.0f, %ld cycles\n",
                dynamics::to_string(options.power_bound), args.speed, args.jerk_max, s.cycles);
    std::printf("  path covered s = %.2f in %.1f s, peak path jerk %.1f\n", s.s_final,
                args.duration_s, s.peak_path_jerk);
    std::printf(
        "  pump power: measured peak %.2f kW, model-predicted LS peak %.2f kW, limit %.2f kW"
        " (%+.1f %%)\n",
        s.peak_pump_power_w / 1e3, s.peak_planned_ls_power_w / 1e3, p_max / 1e3,
        100.0 * (s.peak_pump_power_w / p_max - 1.0));
    std::printf("  simulated pump power limiter %s, engaged in %ld cycles; energy %.1f kJ\n",
                args.pump_limiter ? "on" : "off", s.cycles_power_limited, s.energy_j / 1e3);
    if (log) std::printf("  log: %s (%zu rows)\n", log->path().c_str(), log->rows_written());
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

CLI::App* add_experiment_command(CLI::App& cli, ExperimentArgs& args) {
  auto* experiment = cli.add_subcommand(
      "experiment-2r",
      "Reproduce the 2R experiment of the power-limited scaling paper on the simulated arm");
  experiment
      ->add_option("--config", args.config_file, "Two-joint arm config (default: embedded 2R)")
      ->check(CLI::ExistingFile);
  experiment
      ->add_option("--power-bound", args.power_bound,
                   "load_sensing (the correct LS bound), actuator_sum (the older baseline) "
                   "or none")
      ->check(CLI::IsMember(names_of(dynamics::kPowerBounds)))
      ->capture_default_str();
  experiment->add_option("--speed", args.speed, "Requested path speed, 1/s")
      ->check(FiniteRange(0.01, 20.0))
      ->capture_default_str();
  experiment->add_option("--duration", args.duration_s, "Seconds to run")
      ->check(FiniteRange(0.1, 600.0))
      ->capture_default_str();
  experiment->add_option("--jerk", args.jerk_max, "Path jerk bound, 1/s^3")
      ->check(FiniteRange(1.0, 1e6))
      ->capture_default_str();
  experiment->add_option("--log", args.log_file, "Per-cycle CSV log")->capture_default_str();
  experiment->add_flag("--no-log", args.no_log, "Do not write the log");
  experiment->add_flag("--pump-limiter", args.pump_limiter,
                       "Keep the simulated pump's power limiter (default: off, so the measured "
                       "power shows what the trajectory demands)");
  return experiment;
}

}  // namespace craneassist::cli
