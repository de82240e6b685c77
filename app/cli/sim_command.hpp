// `craneassist sim`: the live loop, driven by an operator (keyboard in the terminal, an evdev or
// SDL joystick) or a replay file, with optional log and recording. On the simulated crane by
// default; with --backend can (or `backend: can` in the crane config) it drives the machine on
// the CAN bus.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "foxglove_setup.hpp"
#include "machine_setup.hpp"
#include "telemetry_setup.hpp"
#include "web_view.hpp"

namespace craneassist::cli {

struct SimArgs {
  std::string config_file;         // empty: the embedded reference crane
  std::vector<std::string> input;  // keyboard | evdev | sdl | replay FILE; empty: keyboard
  std::string joystick_file;       // mapping YAML; empty: the embedded gamepad default
  std::string device;              // evdev: device path (overrides the mapping's)
  double duration_s = 0.0;         // 0: until q, Ctrl-C or SIGTERM
  std::string log_file;            // empty: no log
  std::string record_file;         // empty: no recording
  bool no_realtime = false;        // --input replay only: as fast as possible
  bool rt = false;                 // --rt: lock memory and SCHED_FIFO priority 80
  bool lock_memory = false;        // --lock-memory
  int rt_priority = 0;             // --rt-priority N (SCHED_FIFO); 0: none
  int cpu = -1;                    // --cpu N: pin the loop thread; -1: none
  std::optional<double> payload_kg;
  bool payload_known = false;
  bool no_sway_damping = false;  // --no-sway-damping
  std::string resolution;        // empty: the config's
  std::string initial;    // start pose "NAME=VALUE UNIT, ..." (sim backend); empty: the config's
  BackendArgs machine;    // empty values: the config's backend: and can:
  bool drive = false;     // --drive: the crane on the simulated wheeled base
  std::string base_file;  // --base FILE (implies --drive); empty: the embedded base
  std::string pump;       // --pump shared|separate; empty: the base config's
  TelemetryArgs telemetry;
  FoxgloveArgs foxglove;  // --mcap FILE, --foxglove [HOST:]PORT (docs/foxglove.md)
  WebArgs web;
  // --input goal (docs/mhsb.md#the-k70m-a-goal-for-sim): the first goal, later ones, the
  // planner's weights, grid and posture table file.
  std::string goal;
  std::vector<std::string> goal_at;
  std::string goal_weights = "1,0,0";
  std::string goal_grid;
  std::string goal_table;
  double goal_speed_m_s = 0.5;
};

CLI::App* add_sim_command(CLI::App& cli, SimArgs& args);
int run_sim_command(const SimArgs& args);

}  // namespace craneassist::cli
