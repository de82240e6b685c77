// Joint-limited pseudo-inverse redundancy resolution with null-space saturation (SNS):
// F. Flacco, A. De Luca, O. Khatib, "Motion control of redundant robots under joint
// constraints: saturation in the null space" (ICRA 2012), single-task version.
//
// Solves J qdot = s v_tip for the smallest-norm qdot within per-joint velocity bounds. A joint
// that would leave its bounds is saturated at its bound and the task is re-solved with the
// others; when no feasible combination keeps the full task, the task is scaled down uniformly
// (0 < s < 1), so the tip direction is kept. Fixed-size, no allocation, at most n iterations.
#pragma once

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

struct JointRateBounds {
  JointVector lower, upper;
};

// Bounds that respect joint velocity limits and bring a joint to rest at its position limit
// within its acceleration limit (qdot^2 <= 2 a (distance to the limit)), and at the latest in one
// period. All arguments per joint; positions in the joint's units.
void joint_rate_bounds(const CraneModel& model, const JointVector& q, const JointVector& qdot_max,
                       const JointVector& qddot_max, double period_s, JointRateBounds& out);

struct SnsResult {
  JointVector qdot;
  double task_scale = 1.0;  // s: 1 when the full task is met
  int saturated_joints = 0;
};

void sns_velocity_ik(const TaskJacobian& jacobian, const Eigen::Vector3d& v_tip,
                     const JointRateBounds& bounds, SnsResult& out);

}  // namespace craneassist::dynamics
