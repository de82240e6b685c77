// The flow manipulability polytope of the cycle (docs/polytope.md, dynamics/flow_polytope.hpp):
// an observer of the controller, run only when something reads it (the CSV log, telemetry, the
// web view, Foxglove; ControlLoop asks the task for it). It costs 81 sign patterns, a hull and
// an LP per cycle, about a fifth of the controller's time, and changes nothing the machine does.
//
// At the configuration the cycle resolved at, with the cylinder speeds and pump flow the scaling
// in use allows (the full scaling keeps control.flow_reserve of both, the flow-only prescaling
// of the flow only), it fills ControllerOutput's avail_speed_m_s, avail_speed_resolved_m_s,
// polytope_dim, polytope_volume_m3_s3 and polytope_area_m2_s2. No allocation after
// construction, no exception.
#pragma once

#include <Eigen/Core>

#include "craneassist/config/crane_config.hpp"
#include "craneassist/control/controller_output.hpp"
#include "craneassist/dynamics/flow_polytope.hpp"
#include "craneassist/dynamics/kinematics.hpp"

namespace craneassist::control {

class PolytopeProbe {
 public:
  PolytopeProbe(const config::CraneConfig& config, ScalingMode mode);

  // q: where the cycle resolved; command: the stick's tip velocity (zero when stale; the last
  // direction is kept while it is released); motion, tip_speed: the joint motion the controller
  // chose and its tip speed (TipStage::resolved_motion, resolved_tip_speed).
  void update(const JointVector& q, const Eigen::Vector3d& command, const JointVector& motion,
              double tip_speed, ControllerOutput& out) noexcept;

 private:
  const dynamics::CraneModel& model_;
  dynamics::FlowPolytopeSettings settings_;
  dynamics::FlowPolytope polytope_;
  dynamics::JointVelocitySet set_;
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jacobian_;
  JointVector arms_;
  Eigen::Vector3d stick_direction_ = Eigen::Vector3d::UnitX();
};

}  // namespace craneassist::control
