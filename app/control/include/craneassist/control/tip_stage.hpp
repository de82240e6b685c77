// The tip-scaling stage of the controller: from the operator's tip-velocity command to the joint
// reference of this cycle (q_ref, qdot_ref), one update(in, out) -> status per period (Ruckig's
// shape). A stage owns everything between the command and the reference: the path direction,
// the redundancy resolution, the scaling and the integration of the reference. Two stages:
//
//   PathScalingStage  (ScalingMode::kFull) the product's scaling, in this order each cycle:
//     the path direction u: the reference velocity's (at rest: the command's)   scaling::TipScaler
//     -> redundancy resolution of u, f' and f'', joints kept off their ends      scaling::TipPath
//     -> the tracking-error slow-down, the sway damping's pendulum, the rated capacity
//        limiter's refusal of an outward motion (docs/loads.md)
//     -> speed limits along u (flow, cylinder speeds, end damping, power, tracking error,
//        singularity: one factor on the whole command), acceleration bounds from the ODE
//        dynamics, the jerk-limited move towards the scaled command             scaling::TipScaler
//     -> the reference integrated along the path: q += f' ds + f'' ds^2 / 2, in the joint ranges
//   PrescalingStage   (kFlowOnly, kNone) the baselines: the command resolved by the SNS, joints
//     kept off their ends, then (kFlowOnly) one factor for the pump flow and the cylinder
//     speeds (scaling::flow_prescale), integrated at the period; no filter, no power limit.
//
// Constructed once (allocates, may throw); update() and reset() allocate nothing and throw
// nothing.
#pragma once

#include <memory>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller_output.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/dynamics/rigid_body_terms.hpp"
#include "craneassist/scaling/flow_prescaling.hpp"
#include "craneassist/scaling/swing_frequency.hpp"
#include "craneassist/scaling/tip_path.hpp"
#include "craneassist/scaling/tip_scaler.hpp"
#include "craneassist/valves/machine_interface.hpp"

namespace craneassist::control {

// The settings of the full scaling's tip path and tip scaler from a crane config: the stage's,
// and those of tests that run the two parts on their own.
scaling::TipPathConfig tip_path_config(const config::CraneConfig& config);
scaling::TipScalerConfig tip_scaler_config(const config::CraneConfig& config);
// The tip scaler's input of a cycle (tracking factor 1): the command, its direction u, what the
// tip path found for u (end damping, the stop a joint end leaves room for, a singular pose), and
// whether the input is stale.
scaling::TipScalerInput tip_scaler_input(const Eigen::Vector3d& command, const Eigen::Vector3d& u,
                                         const scaling::TipPathOutput& path, bool stale);

struct TipStageInput {
  // The operator's tip velocity, finite (a non-finite one arrives as zero with stale set), m/s.
  Eigen::Vector3d command = Eigen::Vector3d::Zero();
  // The measurement or the command is not valid: the motion stops (jerk-limited with kFull, at
  // once in the baselines; limit stale_input).
  bool stale = false;
  const valves::MachineState* state = nullptr;  // this cycle's measurement (never null)
  // The reference of one valve delay ago (the tracking error's; ReferenceFollower).
  const JointVector* delayed_q_ref = nullptr;
  const LoadOutput* load = nullptr;  // the crane scale and the limiter, this cycle (never null)
};

enum class TipStageStatus {
  kMoving,  // the reference moves, or is still decelerating
  kAtRest,  // the reference is at rest: velocity and acceleration exactly zero
};

class TipStage {
 public:
  virtual ~TipStage() = default;
  // The reference at q, at rest.
  virtual void reset(const JointVector& q) noexcept = 0;
  // One period: writes q_ref, qdot_ref, ref_tip_velocity_m_s, scale, flow_demand_m3_s, limit,
  // the path scaling's s..sddot_max, tip_error_m, ref_power_w, the sway periods and
  // load.refused of out.
  virtual TipStageStatus update(const TipStageInput& in, ControllerOutput& out) noexcept = 0;
  // The reference the next update() resolves at.
  virtual const JointVector& q_ref() const noexcept = 0;
  // The joint motion the last update() chose and the tip speed it gives (J x): the full
  // scaling's f' (tip speed 1 per unit path speed), the baselines' resolved command (zero when
  // stale). The polytope's speed along the controller's resolution reads it.
  virtual const JointVector& resolved_motion() const noexcept = 0;
  virtual double resolved_tip_speed() const noexcept = 0;
  // This cycle's dynamics step failed (kFull: ODE out of memory; the baselines have none).
  virtual bool dynamics_failed() const noexcept { return false; }
  // The payload the dynamics use, kg (kFull; ignored by the baselines).
  virtual void set_payload_model_kg(double kg) noexcept { (void)kg; }
  // The ODE dynamics probe (kFull; nullptr otherwise). For tests: its fail_steps_for_testing().
  virtual dynamics::RigidBodyTerms* dynamics() noexcept { return nullptr; }
};

// ScalingMode::kFull.
class PathScalingStage final : public TipStage {
 public:
  explicit PathScalingStage(const config::CraneConfig& config);
  void reset(const JointVector& q) noexcept override;
  TipStageStatus update(const TipStageInput& in, ControllerOutput& out) noexcept override;
  const JointVector& q_ref() const noexcept override { return q_ref_; }
  const JointVector& resolved_motion() const noexcept override { return tip_out_.geometry.f1; }
  double resolved_tip_speed() const noexcept override { return 1.0; }
  bool dynamics_failed() const noexcept override { return scaler_out_.dynamics_failed; }
  void set_payload_model_kg(double kg) noexcept override;
  dynamics::RigidBodyTerms* dynamics() noexcept override { return terms_.get(); }

 private:
  void update_tracking(const TipStageInput& in) noexcept;
  void update_sway(const TipStageInput& in, ControllerOutput& out) noexcept;
  bool refuse_outward(const Eigen::Vector3d& command, const Eigen::Vector3d& u,
                      const LoadOutput& load) noexcept;

  const dynamics::CraneModel& model_;
  double tracking_error_ok_m_;
  double tracking_alpha_;
  std::unique_ptr<dynamics::RigidBodyTerms> terms_;
  scaling::TipPath tip_path_;
  scaling::TipScaler scaler_;
  scaling::TipPathInput path_in_;
  scaling::TipPathOutput tip_out_;
  scaling::TipScalerInput scaler_in_;
  scaling::TipScalerOutput scaler_out_;
  dynamics::KinematicsData kin_;
  JointVector q_ref_, dc_dq_;
  double tip_error_filtered_m_ = 0.0;
  // The rated capacity limiter (docs/loads.md).
  config::LoadChart chart_;
  bool refusing_ = false;  // refuses the outward motion (held while pushed on)
  double deceleration_max_ = 1.0, jerk_max_ = 1.0;  // the scaling's, for the stop ahead
  bool sway_damping_ = false;   // the grapple hangs and scaling.sway_damping is on
  bool sway_measured_ = false;  // scaling.sway_frequency: measured
  scaling::SwingFrequencyEstimator swing_frequency_;
};

// ScalingMode::kFlowOnly and kNone.
class PrescalingStage final : public TipStage {
 public:
  PrescalingStage(const config::CraneConfig& config, bool prescale);
  void reset(const JointVector& q) noexcept override { q_ref_ = q; }
  TipStageStatus update(const TipStageInput& in, ControllerOutput& out) noexcept override;
  const JointVector& q_ref() const noexcept override { return q_ref_; }
  const JointVector& resolved_motion() const noexcept override { return motion_; }
  double resolved_tip_speed() const noexcept override { return tip_speed_; }

 private:
  const dynamics::CraneModel& model_;
  bool prescale_;  // kFlowOnly: the flow and cylinder-speed factor; kNone: the command as it is
  double period_s_;
  double flow_reserve_;
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jacobian_;
  dynamics::JointRateBounds bounds_;
  dynamics::SnsResult sns_;
  scaling::FlowPrescalingResult prescale_result_;
  JointVector dc_dq_, qddot_max_, q_ref_, motion_;
  double tip_speed_ = 0.0;
};

// The stage of a scaling mode.
std::unique_ptr<TipStage> make_tip_stage(const config::CraneConfig& config, ScalingMode mode);

}  // namespace craneassist::control
