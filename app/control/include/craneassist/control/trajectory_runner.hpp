// Executes a planned joint trajectory (input::JointTrajectory, from `craneassist research plan`) on
// a machine: the joint reference is sampled every control period and followed with the valves'
// reference follower (dead-zone inverse feed-forward plus P feedback), without path scaling: the
// plan already respects the cylinder limits. Because the plan is known in advance, the reference
// is previewed by the valve delay plus the spool time constant, so the machine, which lags its
// valves by that much, tracks the plan in time rather than behind it.
#pragma once

#include <Eigen/Core>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/input/joint_trajectory.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

struct TrajectoryRunOptions {
  bool preview = true;    // feed the reference ahead by the valve delay plus time constant
  double settle_s = 1.0;  // keep running (holding the last sample) after the end
};

struct TrajectoryRunSummary {
  long cycles = 0;
  double duration_s = 0.0, wall_time_s = 0.0;
  double energy_j = 0.0;  // pump energy measured by the backend
  double peak_power_w = 0.0, peak_flow_m3_s = 0.0;
  // Measured tip against the plan's tip at the same time.
  double max_tip_error_m = 0.0, rms_tip_error_m = 0.0;
  double start_error_m = 0.0;  // tip distance between the machine and the plan at the start
  long pump_saturated_cycles = 0;
  long invalid_state_cycles = 0;  // cycles without a valid measurement (valves neutral)
  std::size_t log_rows_dropped = 0;
};

// Throws std::invalid_argument when the trajectory's joint count differs from the model's.
TrajectoryRunSummary run_trajectory(const config::CraneConfig& config,
                                    const input::JointTrajectory& trajectory,
                                    valves::MachineInterface& machine,
                                    const TrajectoryRunOptions& options, CsvLog* log);

}  // namespace craneassist::control
