// The fixed-rate control loop driven by a replay: read the machine, run the controller, write
// the valves, log, and let one period pass (as fast as the backend allows, or paced at real time).
#pragma once

#include <array>
#include <vector>

#include "craneassist/app/controller.hpp"
#include "craneassist/app/csv_log.hpp"
#include "craneassist/app/cycle_observer.hpp"
#include "craneassist/app/motion_quality.hpp"
#include "craneassist/input/replay.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::app {

struct RunOptions {
  ControllerOptions controller;
  bool realtime = false;  // pace the loop at the control rate
  double settle_s = 1.0;  // keep running this long after the last replay row
  // Direction statistics count a cycle when the reference direction has been on the command
  // (within 0.5 deg, i.e. direction blending done) this long and the measured tip moves faster
  // than min_speed_m_s.
  double steady_after_s = 0.5;
  double min_speed_m_s = 0.05;
  // Test hook (the CAN watchdog tests): at this machine time the loop stops for freeze_for_s
  // without reading or writing, as a hung control thread would. Negative: never.
  double freeze_at_s = -1.0;
  double freeze_for_s = 0.0;
  std::vector<CycleObserver*> observers;  // called each cycle with the log row (telemetry)
};

struct RunSummary {
  int cycles = 0;
  double duration_s = 0.0;   // machine time
  double wall_time_s = 0.0;  // computer time
  double energy_j = 0.0;
  double peak_power_w = 0.0;
  double peak_flow_m3_s = 0.0;
  double peak_tip_speed_m_s = 0.0;
  double tip_path_m = 0.0;
  // Angle between commanded and measured tip velocity (steady cycles, see RunOptions).
  double max_direction_error_deg = 0.0;
  double rms_direction_error_deg = 0.0;
  int direction_samples = 0;
  // Angle between commanded and reference tip velocity (what the controller asked for).
  double max_reference_direction_error_deg = 0.0;
  int pump_saturated_cycles = 0;
  double peak_path_jerk = 0.0;   // max |sdddot| of the reference (full scaling)
  int stopped_cycles = 0;        // the controller stopping or stopped (kStopping, kStopped)
  int input_stop_cycles = 0;     // cycles in a stop row of the replay (a non-finite command)
  int neutral_valve_cycles = 0;  // kStopped: at rest with every valve neutral
  std::array<int, scaling::kActiveLimitCount> limit_cycles{};  // indexed by scaling::ActiveLimit
  std::size_t log_rows_dropped = 0;
  MotionQualityResult feel;  // stall events and lateral speed (motion_quality.hpp)
};

RunSummary run_replay(const config::CraneConfig& config, const input::Replay& replay,
                      valves::MachineInterface& machine, const RunOptions& options, CsvLog* log);

// Angle between two vectors in degrees (0 when either is zero).
double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace craneassist::app
