// What the controller gives each cycle (ControllerOutput), its options and its scaling modes:
// shared by the controller, its stages (tip_stage.hpp) and what reads a cycle (the log row,
// telemetry, statistics).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <optional>
#include <string_view>

#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/scaling/active_limit.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

using dynamics::JointVector;

enum class ScalingMode {
  kFull,      // power-limited, jerk-bounded path scaling
  kFlowOnly,  // uniform flow and cylinder-speed prescaling only
  kNone,      // no scaling (what a machine without craneassist does)
};
inline constexpr std::array kScalingModes{ScalingMode::kFull, ScalingMode::kFlowOnly,
                                          ScalingMode::kNone};
const char* to_string(ScalingMode mode);  // "full", "flow", "none" (replay --scaling)
inline std::optional<ScalingMode> parse_scaling_mode(std::string_view text) {
  return parse_name(kScalingModes, text);
}

struct ControllerOptions {
  ScalingMode mode = ScalingMode::kFull;
  // How often a command reaches the valves (MachineInterface::command_period_s; 0: every cycle).
  double valve_command_period_s = 0.0;
  // true: the config's payload is the load in the grapple (the papers' comparisons, replay
  // --payload-known); false: nobody says, the crane scale finds it out (docs/loads.md).
  bool payload_known = false;
  // Fill the flow manipulability polytope's figures each cycle (PolytopeProbe). The control
  // loop turns it on when a log or an observer reads them (CycleObserver::reads_polytope).
  bool polytope = false;
};

// How a stop's settling ended, when the valves went to neutral (docs/safety.md).
enum class StopEnd {
  kNone,        // no stop, or still settling
  kAtRest,      // the measured tip and every cylinder slower than control.rest_speed
  kTimeout,     // still moving control.rest_timeout after the reference came to rest
  kUnmeasured,  // no valid measurement: the reference at rest is all there is
};

// The rated capacity limiter's thresholds on the load-moment ratio (docs/loads.md): a warning at
// 90 %, the trip at 100 %, released below 95 %; and a load's reach, its horizontal distance from
// the slew axis (crane frame: y up), as the load chart reads it.
inline constexpr double kOverloadWarning = 0.9;
inline constexpr double kOverloadTrip = 1.0;
inline constexpr double kOverloadRelease = 0.95;
inline double horizontal_reach_m(const Eigen::Vector3d& tip) {
  return std::hypot(tip.x(), tip.z());
}

// The load in the grapple as the controller sees it (docs/loads.md).
struct LoadOutput {
  double estimate_kg = 0.0;   // the crane scale (the config's payload when it is known)
  double sigma_kg = 0.0;      // its standard error (0 when known)
  bool converged = false;     // true when known
  bool weighed = false;       // the scale has had a measurement (both chamber pressures) at all
  double model_kg = 0.0;      // what the dynamics use: the estimate, or the rated load before it
                              // has converged (never less)
  double reach_m = 0.0;       // measured tip's horizontal distance from the slew axis
  double rated_kg = 0.0;      // the load chart's rated load at that reach (0: no chart)
  double moment_ratio = 0.0;  // estimate / rated: the load moment against the chart (0: no chart)
  bool warning = false;       // moment_ratio at or above 90 %
  bool overload = false;      // the limiter has tripped (100 %; released below 95 %)
  bool refused = false;       // this cycle's motion would raise the load moment: slowed to rest
  bool relief = false;        // a chamber at the load-holding valves' port relief: it creeps
};

struct ControllerOutput {
  valves::ValveCommand valves;
  JointVector q_ref, qdot_ref;
  Eigen::Vector3d ref_tip_velocity_m_s = Eigen::Vector3d::Zero();
  double scale = 1.0;             // reference tip speed over commanded tip speed
  double flow_demand_m3_s = 0.0;  // of the unscaled command
  scaling::ActiveLimit limit = scaling::ActiveLimit::kNone;
  // Path scaling (kFull; zero otherwise).
  double s = 0.0, sdot = 0.0, sddot = 0.0, sdddot = 0.0;
  double sddot_min = 0.0, sddot_max = 0.0;
  double tip_error_m = 0.0;  // filtered tracking error used for the slow-down
  double ref_power_w = 0.0;  // pump power (LS, or p_s Q) the model predicts for the reference
  // The flow manipulability polytope at the configuration this cycle resolved (docs/polytope.md,
  // dynamics/flow_polytope.hpp), with the cylinder speeds and pump flow the scaling in use
  // allows (the full scaling keeps control.flow_reserve of both, the flow-only prescaling of
  // the flow only):
  //   avail_speed_m_s           the fastest tip speed along the stick's direction (the last one
  //                             while the stick is released) over every joint motion (LP);
  //   avail_speed_resolved_m_s  the fastest along the joint motion this controller chose: the
  //                             scaling's flow and cylinder-speed bound (full scaling: along the
  //                             path direction u; flow-only and none: along the command; 0 with
  //                             no command);
  //   polytope_dim              the dimension of the tip polytope: 3 (a solid), 2 (flat: a
  //                             planar arm, or a singular pose of a spatial one), 1 or 0 (a
  //                             segment or a point: no motion left across it);
  //   polytope_volume_m3_s3     its volume (0 unless polytope_dim is 3);
  //   polytope_area_m2_s2       its area in its plane when flat (polytope_dim 2; else 0): a
  //                             planar arm's measure.
  double avail_speed_m_s = 0.0;
  double avail_speed_resolved_m_s = 0.0;
  int polytope_dim = 0;
  double polytope_volume_m3_s3 = 0.0;
  double polytope_area_m2_s2 = 0.0;
  LoadOutput load;
  // A stop: how its settling ended (kNone until the valves start to go neutral).
  StopEnd stop_end = StopEnd::kNone;
  // The sway damping's pendulum (docs/sway.md): the model's period with the load the scale has
  // found, the period the shaper is tuned to (the model's tuned to the measured swing), and the
  // periods the swing sensor measured so far (0 while damped on the model; all 0 without a
  // hanging grapple or with the damping off).
  double sway_model_period_s = 0.0, sway_period_s = 0.0;
  int sway_measured_periods = 0;
};

// The controller's status is the cycle status of the loop (control_loop.hpp).
using ControllerStatus = CycleStatus;

}  // namespace craneassist::control
