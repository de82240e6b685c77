// The 2R experiment of "Real-time trajectory scaling algorithm for hydraulic manipulators subject
// to limited on-board power" (section 4): a planar two-link arm follows the joint path
//     f(s) = [pi/6 - sin s, -pi/6 - 0.5 sin s]
// at a requested path speed, scaled by the jerk-bounded filter under either power bound, on the
// simulated arm with its load-sensing pump. The paper's finding, which this reproduces: the older
// sum-of-actuator-powers bound lets the real LS pump exceed P_max, the LS bound does not.
#pragma once

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/csv_log.hpp"
#include "craneassist/scaling/path_constraints.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::studies {

struct SinePathOptions {
  double sdot_request = 2.0;  // rad/s of the path parameter
  double duration_s = 8.0;
  double jerk_max = 1000.0;  // the paper's |sdddot| < 1000
  double acceleration_max = 100.0;
  scaling::PowerBound power_bound = scaling::PowerBound::kLoadSensing;
  // The simulated pump's power-limiting valve. Off by default, as in the paper's simulation:
  // the measured pump power then shows what the trajectory demands of the prime mover (with
  // the limiter on, an excess shows as flow starvation instead).
  bool pump_power_limiter = false;
};

struct SinePathSummary {
  long cycles = 0;
  double s_final = 0.0;
  double peak_pump_power_w = 0.0;        // measured by the simulated pump
  double peak_planned_ls_power_w = 0.0;  // LS power of the reference, from the model
  long cycles_power_limited = 0;         // the pump's power limiter held the flow back
  double peak_path_jerk = 0.0;
  double energy_j = 0.0;
};

// The model must have two joints within whose ranges f(s) lies. The machine is the simulated arm
// (sim_backend), built by the caller from machine_model(config, options).
SinePathSummary run_sine_path(const config::CraneConfig& config, const SinePathOptions& options,
                              valves::MachineInterface& machine, control::CsvLog* log);

// The model the simulated arm runs with: the config's, without the power limiter unless
// options.pump_power_limiter.
dynamics::CraneModel machine_model(const config::CraneConfig& config,
                                   const SinePathOptions& options);

// The path and its derivatives.
void sine_path(double s, dynamics::JointVector& q, dynamics::JointVector& f1,
               dynamics::JointVector& f2);

}  // namespace craneassist::studies
