// The per-cycle control pipeline, read top to bottom as named stages (MoveIt Servo's shape):
//
//   measurement -> the crane scale and the rated capacity limiter         update_load
//   tip-velocity command -> the tip-scaling stage: path direction, redundancy resolution,
//     speed limits, acceleration bounds from the ODE dynamics, jerk-limited motion, the
//     reference integrated (q_ref, qdot_ref)                                TipStage
//     (tip_stage.hpp)
//   -> the flow manipulability polytope, when an observer reads it          PolytopeProbe
//   -> a stop's end: settle on the reference, then every valve to neutral   finish_stop
//   -> valve commands: dead-zone inverse of the cylinder velocity reference plus P feedback on
//      the cylinder position error against the reference of one valve delay ago
//                                                                            ReferenceFollower
//
// The scaling mode picks the stage: kFull the power-limited, jerk-bounded path scaling; the
// baselines kFlowOnly (flow and cylinder-speed prescaling only) and kNone (unscaled).
// Constructed once with the model (the constructor allocates and may throw); update() allocates
// nothing and throws nothing (noexcept): the one dynamics call in the cycle,
// RigidBodyTerms::path_terms, reports a failed ODE step as a status, and the controller stops on
// it (see update()).
#pragma once

#include <memory>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller_output.hpp"
#include "craneassist/control/polytope_probe.hpp"
#include "craneassist/control/tip_stage.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/payload_estimator.hpp"
#include "craneassist/valves/machine_interface.hpp"
#include "craneassist/valves/reference_follower.hpp"

namespace craneassist::control {

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
  dynamics::RigidBodyTerms* dynamics_for_testing() noexcept { return stage_->dynamics(); }
  // How often a command reaches the valves (ControllerOptions::valve_command_period_s).
  void set_valve_command_period(double period_s);
  // The flow manipulability polytope's figures of ControllerOutput (PolytopeProbe): on, each
  // update fills them; off (ControllerOptions::polytope false), they stay zero.
  void set_polytope(bool on);

 private:
  // The end of a stop: settle on the reference, then ramp the valves to neutral.
  ControllerStatus finish_stop(const valves::MachineState& state, bool state_ok,
                               ControllerOutput& out) noexcept;
  // The measured tip and every cylinder slower than control.rest_speed.
  bool measured_at_rest(const valves::MachineState& state) noexcept;
  // The crane scale and the rated capacity limiter (docs/loads.md).
  void update_load(const valves::MachineState& state, ControllerOutput& out) noexcept;

  const config::CraneConfig& config_;
  const dynamics::CraneModel& model_;
  ControllerOptions options_;
  double period_s_;
  valves::ReferenceFollower follower_;
  std::unique_ptr<TipStage> stage_;
  std::unique_ptr<PolytopeProbe> polytope_;  // null while nothing reads it
  // Per-cycle working data (Pinocchio's Data), preallocated.
  dynamics::KinematicsData kin_;
  JointVector q_resolved_;  // where the stage resolved this cycle (for the polytope only)
  bool neutral_ = false;    // the last update returned kStopped (valves neutral)
  double rest_speed_m_s_ = 0.005;
  double hold_error_m_ = 0.0;
  long rest_timeout_cycles_ = 0, rest_confirm_cycles_ = 1;
  long settle_cycles_ = 0, rest_cycles_ = 0;
  StopEnd stop_end_ = StopEnd::kNone;  // decided: the valves go (or are) neutral
  dynamics::TaskJacobian rest_jacobian_;
  JointVector rest_arms_;
  config::LoadChart chart_;
  double known_payload_kg_ = 0.0;
  std::unique_ptr<dynamics::PayloadEstimator> estimator_;
  bool overload_ = false;
};

}  // namespace craneassist::control
