// Uniform flow prescaling of a joint-rate reference (docs/algorithms.md section 2; "Real-time
// trajectory scaling algorithm for hydraulic manipulators subject to limited on-board power"
// section 3.2, "Flow-limited path-following control of a double Ackermann steered hydraulic
// mobile manipulator" eq. 15).
//
// With cylinder velocities v_i = (dc_i/dq_i) qdot_i, the pump flow they need is
// Q = sum_i Aflow_i(sign v_i) |v_i|. One common factor
//     scale = min(1, Q_max / Q, min_i v_max_i / |v_i|)
// brings every cylinder within its speed and the pump within its flow, and because all joints
// are scaled alike the tip keeps its direction.
#pragma once

#include "craneassist/dynamics/model.hpp"
#include "craneassist/scaling/active_limit.hpp"

namespace craneassist::scaling {

struct FlowPrescalingResult {
  double scale = 1.0;
  double flow_demand_m3_s = 0.0;  // of the unscaled reference
  ActiveLimit limit = ActiveLimit::kNone;
  int limiting_cylinder = -1;  // for kCylinderSpeed
};

// dc_dq: torque arms at the current configuration; qdot: the unscaled joint-rate reference;
// flow_reserve: fraction of Q_max kept back for feedback corrections (Q_max (1 - reserve) is
// the flow the reference may use).
void flow_prescale(const dynamics::CraneModel& model, const dynamics::JointVector& dc_dq,
                   const dynamics::JointVector& qdot, double flow_reserve,
                   FlowPrescalingResult& out);

}  // namespace craneassist::scaling
