// A replay run: the replay file's rows as the command of the tip controller, through the one
// control loop (control_loop.hpp), with the run's statistics and optional observers (telemetry).
// As fast as the backend allows, or paced at real time.
#pragma once

#include <vector>

#include "craneassist/control/controller.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/control/run_statistics.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

struct RunOptions {
  ControllerOptions controller;
  bool realtime = false;  // pace the loop at the control rate
  double settle_s = 1.0;  // keep running this long after the last replay row
  RunStatisticsOptions statistics;
  // Test hook (the CAN watchdog tests): at this machine time the loop stops for freeze_for_s
  // without reading or writing, as a hung control thread would. Negative: never.
  double freeze_at_s = -1.0;
  double freeze_for_s = 0.0;
  std::vector<CycleObserver*> observers;  // called each cycle (telemetry)
};

RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log);

}  // namespace craneassist::control
