// `craneassist replay`: drive the crane from a replay file (default: the bundled demo) or execute
// a planned joint trajectory (--trajectory), on the simulator or a machine on the CAN bus, log
// the run and print its summary.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "craneassist/control/controller.hpp"
#include "craneassist/control/replay_runner.hpp"
#include "craneassist/control/run_statistics.hpp"
#include "foxglove_setup.hpp"
#include "machine_setup.hpp"
#include "telemetry_setup.hpp"

namespace craneassist::cli {

struct ReplayArgs {
  std::string replay_file;      // empty: the bundled demo
  std::string trajectory_file;  // a planned joint trajectory instead of a replay
  std::string config_file;      // empty: the embedded reference crane
  BackendArgs machine;          // the machine (empty values: the config's backend: and can:)
  TelemetryArgs telemetry;      // --telemetry: publish DDS telemetry during the replay
  FoxgloveArgs foxglove;        // --mcap FILE, --foxglove [HOST:]PORT (docs/foxglove.md)
  double freeze_at_s = -1.0;    // test hook: freeze the loop at this machine time
  double freeze_for_s = 0.0;
  std::string log_file = "craneassist-log.csv";
  bool no_log = false;
  bool no_scaling = false;
  std::string scaling = control::to_string(control::ScalingMode::kFull);
  std::string power_bound;  // empty: the config's
  std::string resolution;   // empty: the config's
  bool realtime = false;
  double settle_s = 1.0;
  std::optional<double> payload_kg;
  bool payload_known = false;    // tell the controller the payload (else the crane scale finds it)
  bool no_sway_damping = false;  // --no-sway-damping
  double wait_swing_deg =
      2.0;                    // a wait row waits for the swing within this (docs/replay-format.md)
  std::string initial;        // start pose, "NAME=VALUE UNIT, ..."; empty: the config's
  std::string pump_max_flow;  // quantity text, e.g. "120 L/min"
  std::string prime_mover_power;  // quantity text, e.g. "60 kW"
  std::string pump_mode;          // empty: the config's; ls or cp
  std::string supply_pressure;    // quantity text, e.g. "20 MPa", or a bare number in MPa
};

CLI::App* add_replay_command(CLI::App& cli, ReplayArgs& args);
// The summary's load lines (docs/loads.md): the crane scale against the simulated load, the load
// moment against the chart, a load above a port relief. Shared by replay and sim.
void print_load_line(const control::LoadSummary& load, bool known, bool chart);
// The swing line (nothing when no cycle measured the swing).
void print_swing_line(const control::SwingSummary& swing, const config::CraneConfig& cfg);
// The waits and cycle time lines of a replay with wait rows (nothing without).
void print_wait_lines(const control::RunSummary& summary, const control::WaitSettings& settings,
                      double replay_end_s);
// The summary's stop lines (docs/safety.md): how the last stop ended (the measured tip speed when
// the valves went neutral, at rest or after the rest timeout) and, over every stop, spool steps,
// reverse kicks and load pressures. end_stop: the run ended by that stop ("end of run", else
// "stop"). Shared by replay and sim.
void print_stop_lines(const control::StopSummary& stop, bool end_stop, double stop_time_s,
                      double run_peak_spool_step, double stop_step_bound);
int run_replay_command(const ReplayArgs& args);

}  // namespace craneassist::cli
