// Non-redundant inverse kinematics of a K70M-type loader given its extension (paper 000 eqs.
// 33-35).
//
// With the extension q4 (or its rate) chosen, slew, lift and tilt follow uniquely: slew from the
// tip's bearing, lift and tilt from a two-link problem in the vertical plane whose second link
// is the offset L2 plus the telescope L3 + q4. The tilt is taken folded down (q3 < 0 side), as on
// the machine.
#pragma once

#include "craneassist/dynamics/model.hpp"

namespace craneassist::dynamics {

enum class IkStatus { kOk, kUnreachable, kOutsideJointLimits, kSingular };

const char* to_string(IkStatus status);

// True when the model has the loader structure this solver assumes (slew, lift, tilt revolute,
// extension prismatic, DH pattern of paper 000 table 2).
bool is_loader_structure(const CraneModel& model);

// Joint positions reaching tip (crane frame) with extension q4. q_out[3] = q4. kOutsideJointLimits
// still fills q_out with the geometric solution.
IkStatus solve_given_extension(const CraneModel& model, const Eigen::Vector3d& tip_m, double q4,
                               JointVector& q_out);

// Velocity level (paper 000 eq. 34): q_r_dot = [J1 J2 J3]^-1 (v_tip - J4 q4dot), with the tip
// Jacobian J of the current configuration. qdot_out[3] = q4dot.
IkStatus resolve_rates_given_extension(const TaskJacobian& jacobian, const Eigen::Vector3d& v_tip,
                                       double q4dot, JointVector& qdot_out);

}  // namespace craneassist::dynamics
