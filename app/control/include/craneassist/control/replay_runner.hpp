// A replay run: the replay file's rows as the command of the tip controller, through the one
// control loop (control_loop.hpp), with the run's statistics and optional observers (telemetry).
// As fast as the backend allows, or paced at real time.
#pragma once

#include <vector>

#include "craneassist/control/controller.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/run_statistics.hpp"
#include "craneassist/control/tip_command_task.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

struct RunOptions {
  ControllerOptions controller;
  bool realtime = false;  // pace the loop at the control rate
  double settle_s = 1.0;  // keep running this long after the last replay row
  RunStatisticsOptions statistics;
  // How the replay's wait rows wait (docs/replay-format.md#waits); the window defaults to the
  // config's slowest swing period (wait_settings()).
  WaitSettings waits;
  // Test hook (the CAN watchdog tests): at this machine time the loop stops for freeze_for_s
  // without reading or writing, as a hung control thread would. Negative: never.
  double freeze_at_s = -1.0;
  double freeze_for_s = 0.0;
  std::vector<CycleObserver*> observers;  // called each cycle (telemetry)
};

// The wait settings for a crane: the window one period of its slowest swing (the grapple with the
// heaviest load its config allows; 0.5 s when nothing hangs), the rest speed the controller's.
WaitSettings wait_settings(const config::CraneConfig& config,
                           double swing_rad = 2.0 * M_PI / 180.0);

// The summary's waits and cycle time are in RunSummary::waits (a replay without wait rows: none).
RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log);

}  // namespace craneassist::control
