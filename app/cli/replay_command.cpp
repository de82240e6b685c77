#include "replay_command.hpp"

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>

#include "crane_options.hpp"
#include "craneassist/config/crane_config.hpp"
#include "craneassist/config/quantity.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/control/trajectory_runner.hpp"
#include "craneassist/dynamics/inverse_kinematics.hpp"
#include "craneassist/dynamics/resolutions.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/offline/sim_setup.hpp"
#include "craneassist/sim_backend/sim_backend.hpp"
#include "craneassist/valves/reference_follower.hpp"
#include "embedded_replays.hpp"
#include "exit_codes.hpp"
#include "machine_setup.hpp"
#include "option_checks.hpp"
#include "telemetry_setup.hpp"

namespace craneassist::cli {
namespace {

// A pressure given on the command line: a quantity ("200 bar", "20 MPa") or a bare number in MPa.
double cli_pressure(const std::string& option, const std::string& text) {
  char* end = nullptr;
  const double mpa = std::strtod(text.c_str(), &end);
  if (end != text.c_str() && *end == '\0' && std::isfinite(mpa)) return mpa * 1e6;
  return cli_quantity(option, text, config::Dimension::kPressure);
}

const char* power_bound_name(dynamics::PowerBound b, dynamics::PumpMode mode) {
  switch (b) {
    case dynamics::PowerBound::kLoadSensing:
      return mode == dynamics::PumpMode::kConstantPressure ? "constant-pressure, p_s Q"
                                                           : "load-sensing";
    case dynamics::PowerBound::kActuatorPowerSum:
      return "actuator power sum (baseline)";
    case dynamics::PowerBound::kNone:
      return "none";
  }
  return "?";
}

// The pump line of a run summary: mode, energy, peaks.
void print_pump_line(double energy_j, double peak_power_w, double peak_flow_m3_s,
                     long saturated_cycles, const config::CraneConfig& cfg) {
  const auto& pump = cfg.model.pump;
  char pump_name[64];
  if (pump.mode == dynamics::PumpMode::kConstantPressure) {
    std::snprintf(pump_name, sizeof pump_name, "constant-pressure %.1f MPa",
                  dynamics::supply_pressure_ceiling_pa(pump) * 1e-6);
  } else {
    std::snprintf(pump_name, sizeof pump_name, "load-sensing");
  }
  std::printf(
      "  pump %s: energy %.1f kJ, peak power %.1f kW (limit %.1f kW), peak flow %.0f L/min, "
      "saturated in %ld cycles\n",
      pump_name, energy_j / 1e3, peak_power_w / 1e3, pump.prime_mover_power_w / 1e3,
      peak_flow_m3_s * 60e3, saturated_cycles);
}

// The payload as the run starts: the simulated load and whether the controller is told.
std::string payload_text(const config::CraneConfig& cfg, bool known) {
  char text[160];
  std::snprintf(text, sizeof text, "%.0f kg (%s)", dynamics::payload_mass_kg(cfg.model),
                known ? "told to the controller" : "unannounced: the crane scale weighs it");
  return text;
}

// Stall events and, on a one-line replay, the lateral tip speed (docs/scaling.md#operator-feel).
void print_feel_line(const control::MotionQualityResult& f) {
  if (f.one_line) {
    std::printf(
        "  operator feel: %d stall events; tip speed across the command line: peak %.3f m/s over "
        "50 ms at %.2f s (%.3f m/s in one cycle)\n",
        f.stall_events, f.lateral_peak_m_s, f.lateral_peak_t_s, f.lateral_peak_cycle_m_s);
  } else {
    std::printf("  operator feel: %d stall events (commands not on one line: no lateral figure)\n",
                f.stall_events);
  }
}

}  // namespace

void print_stop_lines(const control::StopSummary& st, bool end_stop, double stop_time_s,
                      double run_peak_spool_step, double stop_step_bound) {
  if (st.stops == 0) return;
  std::printf("  %s: stopped in %.2f s, ", end_stop ? "end of run" : "stop", stop_time_s);
  const double v = st.tip_speed_at_neutral_m_s;
  switch (st.end) {
    case control::StopEnd::kAtRest:
      std::printf("at rest (tip %.3f m/s) when the valves went neutral\n", v);
      break;
    case control::StopEnd::kTimeout:
      std::printf(
          "NOT AT REST at the rest timeout (tip %.3f m/s): valves neutral on a moving crane\n", v);
      break;
    case control::StopEnd::kUnmeasured:
      std::printf("no measurement: valves neutral with the reference at rest\n");
      break;
    case control::StopEnd::kNone:
      std::printf("then valves neutral\n");
      break;
  }
  std::printf(
      "  stops: %ld to neutral valves, tip at most %.3f m/s then (%ld after the rest timeout, %ld "
      "without a measurement); spool step at most %.2f per cycle (run %.2f, limit %.2f), %ld "
      "cycles fully open against the stop's side; load pressure in stops up to %.1f MPa "
      "(%.1f MPa before)\n",
      st.stops, st.max_tip_speed_at_neutral_m_s, st.timeouts, st.unmeasured, st.peak_spool_step,
      run_peak_spool_step, stop_step_bound, st.full_reverse_cycles, st.peak_load_pressure_pa * 1e-6,
      st.steady_load_pressure_pa * 1e-6);
}

void print_swing_line(const control::SwingSummary& s, const config::CraneConfig& cfg) {
  if (!s.measured) return;
  const bool damped = cfg.scaling.sway_damping && cfg.model.grapple.hangs();
  std::printf("  swing: peak %.1f deg", s.peak_deg);
  if (s.released)
    std::printf(", %.1f deg from 1 s after the stick's last release", s.after_release_deg);
  std::printf(", %.1f deg in the last second (sway damping %s", s.end_deg,
              damped ? "on" : "off: --no-sway-damping or scaling.sway_damping");
  if (damped && s.measured_periods > 0) {
    std::printf(", tuned to the measured swing: period %.2f s, the model's %.2f s, %d measured",
                s.period_s, s.model_period_s, s.measured_periods);
  } else if (damped && s.model_period_s > 0.0) {
    std::printf(", on the model's period %.2f s", s.model_period_s);
  }
  std::printf(")\n");
}

void print_wait_lines(const control::RunSummary& s, const control::WaitSettings& settings,
                      double replay_end_s) {
  const control::WaitSummary& w = s.waits;
  if (w.waits == 0) return;
  std::printf(
      "  waits: %ld for the grapple to settle (swing within %.1f deg for %.2f s), %.2f s in all, "
      "longest %.2f s, %ld timed out (%.0f s)",
      w.waits, settings.swing_rad * 180.0 / M_PI, settings.window_s, w.total_s, w.longest_s,
      w.timed_out, settings.timeout_s);
  if (std::isfinite(w.residual_swing_deg)) {
    std::printf("; residual swing %.1f deg (from 1 s into a wait)", w.residual_swing_deg);
  }
  std::printf("\n  cycle time: %.2f s (the replay's %.2f s and %.2f s waiting)\n", s.cycle_time_s,
              replay_end_s, w.total_s);
}

void print_load_line(const control::LoadSummary& l, bool known, bool chart) {
  if (!known && !l.weighed) {
    std::printf(
        "  load: NOT WEIGHED: the machine gave no chamber pressures (both chambers of every "
        "cylinder); the dynamics assumed the chart's rated load and the rated capacity limiter "
        "could not act (--payload-known tells the controller)\n");
    return;
  }
  std::printf("  load: %s %.1f kg", known ? "told" : "estimated", l.estimate_kg);
  if (!known) std::printf(" (+-%.1f kg%s)", l.sigma_kg, l.converged ? "" : ", not converged");
  if (l.truth_known) {
    std::printf(", simulated %.1f kg", l.truth_kg);
    if (!known) {
      std::printf("; error at rest max %.1f kg over %ld cycles, moving max %.1f kg over %ld cycles",
                  l.max_error_rest_kg, l.rest_samples, l.max_error_moving_kg, l.moving_samples);
    }
  }
  std::printf("\n");
  if (chart) {
    std::printf(
        "  load moment: peak %.0f %% of the chart, warning (90 %%) in %ld cycles, overload in %ld "
        "(motion refused in %ld)",
        l.peak_moment_ratio * 100.0, l.warning_cycles, l.overload_cycles, l.refused_cycles);
    if (l.overload_cycles > 0) std::printf(": OVERLOADED");
    std::printf("\n");
  }
  if (l.relief_cycles > 0) {
    std::printf(
        "  LOAD ABOVE A PORT RELIEF in %ld cycles: the boom sank at the load-holding valve's "
        "relief flow\n",
        l.relief_cycles);
  }
}

namespace {

void print_summary(const control::RunSummary& s, const config::CraneConfig& cfg,
                   const std::string& replay_name, const control::RunOptions& options,
                   double replay_end_s, const control::CsvLog* log, const char* backend) {
  const control::ControllerOptions& controller = options.controller;
  const control::ScalingMode mode = controller.mode;
  const double speedup = s.wall_time_s > 0.0 ? s.duration_s / s.wall_time_s : 0.0;
  std::printf("craneassist replay: %s on %s\n", replay_name.c_str(), cfg.model.name.c_str());
  std::printf("  backend %s, resolution %s, scaling %s, control %.0f Hz, payload %s\n", backend,
              config::resolution_description(cfg).c_str(),
              mode == control::ScalingMode::kFull
                  ? (std::string("full (power bound: ") +
                     power_bound_name(cfg.scaling.power_bound, cfg.model.pump.mode) + ")")
                        .c_str()
              : mode == control::ScalingMode::kFlowOnly ? "flow prescaling only"
                                                        : "none",
              cfg.control.rate_hz, payload_text(cfg, controller.payload_known).c_str());
  std::printf("  ran %.2f s of machine time in %.3f s (%.0fx real time), %ld cycles\n",
              s.duration_s, s.wall_time_s, speedup, s.cycles);
  std::printf("  tip: path %.2f m, peak speed %.2f m/s\n", s.tip_path_m, s.peak_tip_speed_m_s);
  std::printf(
      "  tip direction error, commanded vs measured (steady, > 0.05 m/s): max %.2f deg, "
      "rms %.2f deg over %ld cycles; from the tip's displacement over %.0f ms: max %.2f deg, "
      "rms %.2f deg; p95 (velocity) %.2f deg\n",
      s.max_direction_error_deg, s.rms_direction_error_deg, s.direction_samples,
      s.position_window_s * 1e3, s.max_position_direction_error_deg,
      s.rms_position_direction_error_deg, s.p95_direction_error_deg);
  print_pump_line(s.energy_j, s.peak_power_w, s.peak_flow_m3_s, s.pump_saturated_cycles, cfg);
  if (s.stopped_cycles > 0) {
    std::printf(
        "  stopped: %ld cycles stopping or stopped (%ld in stop rows: input not valid), valves "
        "neutral in %ld\n",
        s.stopped_cycles, s.input_stop_cycles, s.neutral_valve_cycles);
  }
  if (s.end_stop && s.stop_cycles <= 1) std::printf("  end of run: at rest, valves neutral\n");
  const bool end = s.end_stop && s.stop_cycles > 1;
  print_stop_lines(
      s.stop, end, end ? static_cast<double>(s.stop_cycles) / cfg.control.rate_hz : s.stop.time_s,
      s.peak_spool_step, valves::max_spool_step(cfg.model.valves, 1.0 / cfg.control.rate_hz));
  if (mode == control::ScalingMode::kFull) {
    std::printf("  path jerk: peak %.2f m/s^3 (bound %.2f)\n", s.peak_path_jerk,
                cfg.scaling.jerk_max_m_s3);
  }
  print_feel_line(s.feel);
  print_load_line(s.load, controller.payload_known, !cfg.load_chart.empty());
  print_swing_line(s.swing, cfg);
  print_wait_lines(s, options.waits, replay_end_s);
  std::printf("  active limit (cycles):");
  for (std::size_t i = 0; i < s.limit_cycles.size(); ++i) {
    if (s.limit_cycles[i] > 0) {
      std::printf(" %s %ld", scaling::to_string(static_cast<scaling::ActiveLimit>(i)),
                  s.limit_cycles[i]);
    }
  }
  std::printf("\n");
  if (log != nullptr) {
    std::printf("  log: %s (%zu rows%s)\n", log->path().c_str(), log->rows_written(),
                s.log_rows_dropped > 0 ? ", SOME DROPPED" : "");
  }
}

void print_trajectory_summary(const control::TrajectoryRunSummary& s,
                              const config::CraneConfig& cfg, const input::JointTrajectory& traj,
                              const std::string& name, const control::CsvLog* log) {
  const double speedup = s.wall_time_s > 0.0 ? s.duration_s / s.wall_time_s : 0.0;
  std::printf("craneassist replay --trajectory: %s on %s\n", name.c_str(), cfg.model.name.c_str());
  for (const auto& c : traj.comments) std::printf("  | %s\n", c.c_str());
  std::printf("  ran %.2f s of machine time in %.3f s (%.0fx real time), %ld cycles\n",
              s.duration_s, s.wall_time_s, speedup, s.cycles);
  std::printf("  tip vs plan: max %.1f mm, rms %.1f mm (start %.1f mm)\n", s.max_tip_error_m * 1e3,
              s.rms_tip_error_m * 1e3, s.start_error_m * 1e3);
  print_pump_line(s.energy_j, s.peak_power_w, s.peak_flow_m3_s, s.pump_saturated_cycles, cfg);
  if (s.invalid_state_cycles > 0) {
    std::printf("  NO VALID MEASUREMENT in %ld cycles (valves neutral)\n", s.invalid_state_cycles);
  }
  if (log != nullptr) {
    std::printf("  log: %s (%zu rows%s)\n", log->path().c_str(), log->rows_written(),
                s.log_rows_dropped > 0 ? ", SOME DROPPED" : "");
  }
}

// replay --trajectory: execute a plan (craneassist research plan) in the simulator, starting at its
// first configuration.
int run_trajectory_command(const ReplayArgs& args, const config::CraneConfig& cfg) {
  std::optional<input::JointTrajectory> traj;
  if (uses_can_backend(args.machine, cfg)) {
    spdlog::error("--trajectory runs on the simulated crane only (use --backend sim)");
    return kExitUsage;
  }
  try {
    // The plan must be for this crane: its joint count, every position within the joint ranges.
    input::TrajectoryLimits limits;
    for (const auto& joint : cfg.model.joints) {
      const bool revolute = joint.type == dynamics::JointType::kRevolute;
      limits.joints.push_back({joint.name, joint.q_min, joint.q_max, revolute ? "rad" : "m"});
    }
    traj = input::JointTrajectory::load_file(args.trajectory_file, limits);
  } catch (const input::FileError& e) {
    spdlog::error("trajectory: {}", e.what());
    return kExitUsage;
  }
  try {
    sim_backend::SimSettings settings = offline::sim_settings(cfg);
    settings.q_initial = traj->q(0);
    sim_backend::SimBackend machine(cfg.model, settings);
    std::optional<control::CsvLog> log;
    if (!args.no_log) log.emplace(args.log_file, cfg.model.dof());
    control::TrajectoryRunOptions options;
    options.settle_s = args.settle_s;
    const auto summary =
        control::run_trajectory(cfg, *traj, machine, options, log ? &*log : nullptr);
    print_trajectory_summary(summary, cfg, *traj, args.trajectory_file, log ? &*log : nullptr);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

}  // namespace

int run_replay_command(const ReplayArgs& args) {
  config::CraneConfig cfg;
  std::optional<input::Replay> loaded;
  config::TelemetryConfig telemetry_settings;
  MachineInputs machine_inputs;
  try {
    cfg = load_crane(args.config_file);
    apply_crane_options(cfg, {args.payload_kg, args.initial, args.resolution,
                              !uses_can_backend(args.machine, cfg), args.no_sway_damping});
    if (!args.power_bound.empty()) {
      cfg.scaling.power_bound = dynamics::parse_power_bound(args.power_bound).value();
    }
    // The pump overrides, each through its config field's range check.
    if (!args.pump_max_flow.empty()) {
      const double q =
          cli_quantity("--pump-max-flow", args.pump_max_flow, config::Dimension::kFlow);
      apply_override("--pump-max-flow", [&] { config::set_pump_max_flow(cfg.model, q); });
    }
    if (!args.prime_mover_power.empty()) {
      const double p =
          cli_quantity("--prime-mover-power", args.prime_mover_power, config::Dimension::kPower);
      apply_override("--prime-mover-power", [&] { config::set_prime_mover_power(cfg.model, p); });
    }
    auto& pump = cfg.model.pump;
    if (args.pump_mode == "ls") pump.mode = dynamics::PumpMode::kLoadSensing;
    if (args.pump_mode == "cp") pump.mode = dynamics::PumpMode::kConstantPressure;
    if (!args.supply_pressure.empty()) {
      const double p = cli_pressure("--supply-pressure", args.supply_pressure);
      apply_override("--supply-pressure", [&] { config::set_supply_pressure(cfg.model, p); });
    }
    config::apply_energy_optimal(cfg);  // the pump mode may have changed
    if (pump.mode == dynamics::PumpMode::kConstantPressure && !(pump.supply_pressure_pa > 0.0)) {
      throw CLI::ValidationError("--pump-mode",
                                 "constant-pressure needs a supply pressure "
                                 "(hydraulics.pump.supply_pressure or "
                                 "--supply-pressure)");
    }
    if (!args.trajectory_file.empty()) {
      if (!args.replay_file.empty()) {
        throw CLI::ValidationError("--trajectory", "give a replay file or --trajectory, not both");
      }
      return run_trajectory_command(args, cfg);
    }
    telemetry_settings = load_telemetry_settings(args.telemetry);
    apply_backend_options(cfg, args.machine);
    machine_inputs = load_machine_inputs(cfg, args.machine);
    if (args.replay_file.empty()) {
      loaded =
          input::Replay::parse(embedded::kDemoReplayCsv, "<bundled examples/replays/demo.csv>");
    } else {
      loaded = input::Replay::load_file(args.replay_file);
    }
  } catch (...) {
    return input_error_exit("replay");
  }

  const input::Replay& replay = *loaded;
  const std::string replay_name(replay.source_name());
  try {
    Machine machines;
    if (const int rc = machines.open(cfg, args.machine, machine_inputs); rc != kExitOk) return rc;
    valves::MachineInterface& machine = machines.get();
    Telemetry telemetry;
    const bool telemetry_wanted = args.telemetry.asked();
    if (const int rc = telemetry.open(telemetry_settings, telemetry_wanted, cfg, machine.name());
        rc != kExitOk) {
      return rc;
    }
    std::optional<control::CsvLog> log;
    if (!args.no_log) log.emplace(args.log_file, cfg.model.dof());
    control::RunOptions options;
    if (control::CycleObserver* o = telemetry.observer()) options.observers.push_back(o);
    options.realtime = args.realtime || machine.real_time();
    FoxgloveOutputs foxglove;
    if (const int rc = foxglove.open(args.foxglove, cfg, false, options.realtime); rc != kExitOk) {
      return rc;
    }
    foxglove.add_observers(options.observers);
    options.controller.mode = args.no_scaling ? control::ScalingMode::kNone
                                              : control::parse_scaling_mode(args.scaling).value();
    options.controller.payload_known = args.payload_known;
    options.settle_s = args.settle_s;
    options.freeze_at_s = args.freeze_at_s;
    options.freeze_for_s = args.freeze_for_s;
    options.waits = control::wait_settings(cfg, args.wait_swing_deg * M_PI / 180.0);
    spdlog::info("running {} ({:.1f} s{}) on {} with the {} backend{}", replay_name,
                 replay.end_time_s() + args.settle_s, replay.has_waits() ? " and its waits" : "",
                 cfg.model.name, machine.name(), options.realtime ? ", paced at real time" : "");
    const control::RunSummary summary =
        control::run_replay(cfg, replay, machine, options, log ? &*log : nullptr);
    print_summary(summary, cfg, replay_name, options, replay.end_time_s(), log ? &*log : nullptr,
                  machine.name());
    telemetry.finish();
    if (const int rc = foxglove.finish(); rc != kExitOk) return rc;
    if (summary.log_rows_dropped > 0) {
      spdlog::warn("the log writer fell behind: {} rows dropped", summary.log_rows_dropped);
    }
    if (summary.machine_fault) spdlog::error("the machine reported a fault: run stopped");
    if (const int rc = machines.finish(); rc != kExitOk) return rc;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return kExitRuntime;
  }
  return kExitOk;
}

CLI::App* add_replay_command(CLI::App& cli, ReplayArgs& args) {
  auto* replay = cli.add_subcommand(
      "replay", "Drive the crane from a replay file (default: the bundled demo) and log the run");
  replay
      ->add_option("file", args.replay_file,
                   "Replay CSV (t,v_x,v_y,v_z); see docs/replay-format.md")
      ->check(CLI::ExistingFile);
  replay
      ->add_option("--trajectory", args.trajectory_file,
                   "Execute a planned joint trajectory (craneassist research plan; "
                   "docs/trajectory-format.md) instead of a replay, from its first configuration")
      ->check(CLI::ExistingFile);
  add_config_option(*replay, args.config_file);
  add_backend_options(*replay, args.machine);
  add_telemetry_options(*replay, args.telemetry, false);
  add_foxglove_options(*replay, args.foxglove);
  replay->add_option("--test-freeze-at", args.freeze_at_s)->check(FiniteNumber())->group("");
  replay->add_option("--test-freeze-for", args.freeze_for_s)->check(FiniteNumber())->group("");
  replay->add_option("--log", args.log_file, "Per-cycle CSV log (docs/log-format.md)")
      ->capture_default_str();
  replay->add_flag("--no-log", args.no_log, "Do not write the log");
  replay
      ->add_option("--scaling", args.scaling,
                   "full: power-limited, jerk-bounded path scaling; flow: flow and cylinder-speed "
                   "prescaling only; none: the command unscaled")
      ->check(CLI::IsMember(names_of(control::kScalingModes)))
      ->capture_default_str();
  replay->add_flag("--no-scaling", args.no_scaling,
                   "Same as --scaling none (to see what scaling prevents)");
  replay
      ->add_option("--power-bound", args.power_bound,
                   "Override the config's power bound: load_sensing, actuator_sum (the older "
                   "baseline) or none")
      ->check(CLI::IsMember(names_of(dynamics::kPowerBounds)));
  add_resolution_option(*replay, args.resolution, "for the run");
  replay->add_flag("--realtime", args.realtime,
                   "Pace the loop at real time (default: as fast as possible)");
  replay->add_option("--settle", args.settle_s, "Seconds to keep running after the last replay row")
      ->check(FiniteRange(0.0, 600.0))
      ->capture_default_str();
  add_payload_option(*replay, args.payload_kg);
  add_sway_option(*replay, args.no_sway_damping);
  replay
      ->add_option("--wait-swing", args.wait_swing_deg,
                   "A wait row holds the replay until the grapple's swing stays within this many "
                   "degrees for a swing period (docs/replay-format.md#waits)")
      ->check(FiniteRange(0.01, 90.0))
      ->capture_default_str();
  replay->add_flag("--payload-known", args.payload_known,
                   "Tell the controller the payload (--payload, the config's, and the replay's "
                   "load_kg) instead of letting the crane scale estimate it (docs/loads.md)");
  add_initial_option(*replay, args.initial);
  replay->add_option("--pump-max-flow", args.pump_max_flow,
                     "Override the pump's maximum flow, e.g. \"120 L/min\"");
  replay->add_option("--prime-mover-power", args.prime_mover_power,
                     "Override the power available to the pump, e.g. \"60 kW\"");
  replay
      ->add_option("--pump-mode", args.pump_mode,
                   "Override the config's pump mode: ls (load sensing) or cp (constant pressure "
                   "at the supply pressure)")
      ->check(CLI::IsMember({"ls", "cp"}));
  replay->add_option("--supply-pressure", args.supply_pressure,
                     "Override the constant-pressure setpoint, e.g. \"20 MPa\" (a bare number "
                     "is MPa)");
  return replay;
}

}  // namespace craneassist::cli
