// The per-cycle control pipeline, read top to bottom (MoveIt Servo's shape). With full scaling
// (the default):
//   tip-velocity command
//   -> the path direction u: the reference velocity's (at rest: the command's)  scaling::TipScaler
//   -> redundancy resolution of u, f' and f'', joints kept off their ends       scaling::TipPath
//   -> speed limits along u: flow, cylinder speeds, end damping, power, tracking error,
//      singularity: one factor on the whole command
//   -> acceleration bounds from the ODE dynamics (load-sensing power, cylinder accelerations)
//   -> the reference tip velocity moved towards the scaled command along the straight segment
//      between them, jerk-limited                                                scaling::TipScaler
//   -> reference integration along the path (the reference runs on its own joint state q_ref)
//   -> valve commands: dead-zone inverse of the cylinder velocity reference plus P feedback on
//      the cylinder position error against the reference of one valve delay ago
// The other modes are baselines: kFlowOnly prescales the joint rates for flow and cylinder speed
// only (no power limit, no filter); kNone passes the command through unscaled.
// Constructed once with the model (the constructor allocates and may throw); update() allocates
// nothing and throws nothing (noexcept): the one dynamics call in the cycle,
// RigidBodyTerms::path_terms, reports a failed ODE step as a status, and the controller stops on
// it (see update()).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/control_loop.hpp"
#include "craneassist/dynamics/enum_names.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/payload_estimator.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/active_limit.hpp"
#include "craneassist/scaling/flow_prescaling.hpp"
#include "craneassist/scaling/swing_frequency.hpp"
#include "craneassist/scaling/tip_path.hpp"
#include "craneassist/scaling/tip_scaler.hpp"
#include "craneassist/valves/machine_interface.hpp"
#include "craneassist/valves/reference_follower.hpp"

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
};

// How a stop's settling ended, when the valves went to neutral (docs/safety.md).
enum class StopEnd {
  kNone,        // no stop, or still settling
  kAtRest,      // the measured tip and every cylinder slower than control.rest_speed
  kTimeout,     // still moving control.rest_timeout after the reference came to rest
  kUnmeasured,  // no valid measurement: the reference at rest is all there is
};

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

// The settings of the full scaling's tip path and tip scaler from a crane config: the
// controller's, and those of tests that run the two parts on their own.
scaling::TipPathConfig tip_path_config(const config::CraneConfig& config);
scaling::TipScalerConfig tip_scaler_config(const config::CraneConfig& config);
// The tip scaler's input of a cycle (tracking factor 1): the command, its direction u, what the
// tip path found for u (end damping, the stop a joint end leaves room for, a singular pose), and
// whether the input is stale.
scaling::TipScalerInput tip_scaler_input(const Eigen::Vector3d& command, const Eigen::Vector3d& u,
                                         const scaling::TipPathOutput& path, bool stale);

class Controller {
 public:
  Controller(const config::CraneConfig& config, const ControllerOptions& options);
  ~Controller();

  // Starts the reference at the measured configuration, at rest.
  void reset(const valves::MachineState& state);

  // One control period. An invalid measurement or a non-finite command brings the motion to a
  // jerk-limited stop along the current direction (kStopping, limit stale_input); the other
  // modes stop the reference at once. Then the machine settles on P feedback at the reference
  // (sections within control.activation_error closed) until it is measured at rest or
  // control.rest_timeout has passed, and the valves ramp to neutral at the slew-rate limit
  // (still kStopping; out.stop_end says why); with every valve neutral it holds (kStopped). The
  // first valid cycle after kStopped restarts the reference at the measured configuration (as
  // reset()). A cycle whose dynamics step fails (kFull; ODE out of memory) stops the same way
  // (kStopping, then kStopped; limit dynamics_failed, ref_power_w 0); each cycle tries the dynamics
  // again.
  ControllerStatus update(const valves::MachineState& state, const Eigen::Vector3d& v_cmd_m_s,
                          ControllerOutput& out) noexcept;

  double period_s() const { return period_s_; }
  // The ODE dynamics probe of kFull (nullptr in the other modes). For tests: its
  // fail_steps_for_testing() hook makes the cycle's dynamics step fail.
  dynamics::RigidBodyTerms* dynamics_for_testing() noexcept { return terms_.get(); }
  // How often a command reaches the valves (ControllerOptions::valve_command_period_s).
  void set_valve_command_period(double period_s);

 private:
  void update_full(const valves::MachineState& state, const Eigen::Vector3d& v_cmd, bool stale,
                   ControllerOutput& out) noexcept;
  void update_rate_prescaled(const Eigen::Vector3d& v_cmd, ControllerOutput& out) noexcept;
  // This cycle's dynamics step failed (kFull only).
  bool dynamics_failed() const noexcept;
  // The polytope's figures of ControllerOutput at q, the configuration the cycle resolved at.
  void update_polytope(const JointVector& q, const Eigen::Vector3d& v_cmd, bool stale,
                       ControllerOutput& out) noexcept;

  const dynamics::CraneModel& model_;
  ControllerOptions options_;
  double period_s_;
  double flow_reserve_;
  double tracking_error_ok_m_;
  double tracking_alpha_;
  valves::ReferenceFollower follower_;
  std::unique_ptr<dynamics::RigidBodyTerms> terms_;
  std::unique_ptr<scaling::TipPath> tip_path_;
  std::unique_ptr<scaling::TipScaler> scaler_;
  // Per-cycle working data (Pinocchio's Data), preallocated.
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jacobian_;
  dynamics::JointRateBounds bounds_;
  dynamics::SnsResult sns_;
  scaling::FlowPrescalingResult prescale_;
  scaling::TipPathOutput tip_out_;
  scaling::TipScalerOutput scaler_out_;
  JointVector dc_dq_, qddot_max_;
  JointVector q_ref_;
  // The flow manipulability polytope's working data.
  dynamics::FlowPolytopeSettings polytope_settings_;
  dynamics::FlowPolytope polytope_;
  dynamics::JointVelocitySet polytope_set_;
  dynamics::TaskJacobian polytope_jacobian_;
  JointVector polytope_arms_;
  Eigen::Vector3d stick_direction_ = Eigen::Vector3d::UnitX();
  double tip_error_filtered_m_ = 0.0;
  bool neutral_ = false;  // the last update returned kStopped (valves neutral)
  // The end of a stop: settle on the reference, then ramp the valves to neutral.
  ControllerStatus finish_stop(const valves::MachineState& state, bool state_ok,
                               ControllerOutput& out) noexcept;
  // The measured tip and every cylinder slower than control.rest_speed.
  bool measured_at_rest(const valves::MachineState& state) noexcept;
  double rest_speed_m_s_ = 0.005;
  double hold_error_m_ = 0.0;
  long rest_timeout_cycles_ = 0, rest_confirm_cycles_ = 1;
  long settle_cycles_ = 0, rest_cycles_ = 0;
  StopEnd stop_end_ = StopEnd::kNone;  // decided: the valves go (or are) neutral
  dynamics::TaskJacobian rest_jacobian_;
  JointVector rest_arms_;
  // The crane scale and the rated capacity limiter (docs/loads.md).
  void update_load(const valves::MachineState& state, ControllerOutput& out) noexcept;
  config::LoadChart chart_;
  double known_payload_kg_ = 0.0;
  std::unique_ptr<dynamics::PayloadEstimator> estimator_;
  bool overload_ = false;
  bool refusing_ = false;  // the limiter refuses the outward motion (held while pushed on)
  double deceleration_max_ = 1.0, jerk_max_ = 1.0;  // the scaling's, for the stop ahead
  bool sway_damping_ = false;   // the grapple hangs and scaling.sway_damping is on
  bool sway_measured_ = false;  // scaling.sway_frequency: measured
  scaling::SwingFrequencyEstimator swing_frequency_;
};

}  // namespace craneassist::control
