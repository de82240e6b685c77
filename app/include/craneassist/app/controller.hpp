// The per-cycle control pipeline, read top to bottom (MoveIt Servo's shape):
//   tip-velocity command
//   -> redundancy resolution (joint-limited pseudo-inverse, SNS)
//   -> flow prescaling (pump flow and cylinder speeds, uniform so the tip keeps its direction)
//   -> reference integration (the reference runs on its own joint state q_ref)
//   -> valve commands (dead-zone inverse of the cylinder velocity reference plus P feedback on
//      the cylinder position error)
// Constructed once with the model; update() allocates nothing and throws nothing.
#pragma once

#include <vector>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/scaling/active_limit.hpp"
#include "craneassist/scaling/flow_prescaling.hpp"
#include "craneassist/valves/machine_interface.hpp"
#include "craneassist/valves/proportional_valves.hpp"

namespace craneassist::app {

using dynamics::JointVector;

struct ControllerOptions {
  bool flow_prescaling = true;  // false: --no-scaling (what a machine without craneassist does)
};

struct ControllerOutput {
  valves::ValveCommand valves;
  JointVector q_ref, qdot_ref;
  Eigen::Vector3d ref_tip_velocity_m_s = Eigen::Vector3d::Zero();
  double scale = 1.0;  // total factor applied to the commanded tip speed
  double flow_demand_m3_s = 0.0;
  scaling::ActiveLimit limit = scaling::ActiveLimit::kNone;
};

enum class ControllerStatus { kRunning, kStopped };

class Controller {
 public:
  Controller(const config::CraneConfig& config, const ControllerOptions& options);

  // Starts the reference at the measured configuration.
  void reset(const valves::MachineState& state);

  // One control period. An invalid measurement or a non-finite command stops the motion
  // (neutral valves, kStaleInput) and returns kStopped.
  ControllerStatus update(const valves::MachineState& state, const Eigen::Vector3d& v_cmd_m_s,
                          ControllerOutput& out);

  double period_s() const { return period_s_; }

 private:
  void stop(ControllerOutput& out);

  const dynamics::CraneModel& model_;
  ControllerOptions options_;
  double period_s_;
  double flow_reserve_;
  valves::ProportionalValves valves_;
  // Per-cycle working data (Pinocchio's Data), preallocated.
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jacobian_;
  dynamics::JointRateBounds bounds_;
  dynamics::SnsResult sns_;
  scaling::FlowPrescalingResult prescale_;
  JointVector dc_dq_, qddot_max_, c_ref_, c_meas_;
  valves::ProportionalValvesInput valve_in_;
  JointVector q_ref_;
  // Cylinder position references of the last cycles: the P term compares the measurement with
  // the reference of one valve delay (transport delay plus spool lag) ago, so the valve's own
  // dead time is not mistaken for a tracking error (a Smith-predictor-style compensation).
  std::vector<JointVector> c_ref_history_;
  std::size_t history_head_ = 0;
};

}  // namespace craneassist::app
