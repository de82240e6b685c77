// Path-velocity decomposition of a tip-velocity command (algorithms.md section 1).
//
// The command v is split into a direction u and a speed |v|. Locally the path is the straight tip
// line x(s) = x0 + u s; its joint-space tangent f'(s) resolves u through the redundancy
// resolution (SNS), and f''(s) is the derivative of that resolution along the path (central
// finite difference). Scaling then changes only the scalar path speed, so the tip keeps the
// commanded direction.
//
// Direction changes are blended: u turns towards the commanded direction at an angular rate
// that keeps the tip's normal acceleration sdot * omega within direction_change_acceleration,
// and the speed requested along u is |v| cos(angle) (never negative), so reversing the stick
// slows the motion down, turns it at low speed and speeds it up again, with bounded joint
// accelerations throughout. At rest the direction follows the command at once.
//
// Extension-rate resolutions (pinv-actuator, min-flow, min-ls-power) are piecewise optimal: the
// optimum jumps when another cylinder comes to rest first. At path speed sdot, the extension's
// rate per unit path speed may change by at most a quarter of its acceleration limit times the
// period over sdot from one cycle to the next, so such a switch ramps the extension cylinder
// instead of stepping its velocity (the rest of the limit is the scaling's).
//
// End damping: a joint moving towards its limit caps the path speed at the speed from which a
// stop within the joint's acceleration and the path jerk covers the remaining distance; a joint
// at its limit is saturated in the redundancy resolution so the other joints carry on when they
// can. Moving away from a limit is never limited.
#pragma once

#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/dynamics/resolutions.hpp"
#include "craneassist/scaling/path_constraints.hpp"

namespace craneassist::scaling {

struct TipPathConfig {
  double period_s = 0.01;
  double direction_change_acceleration = 0.5;  // m/s^2, tip normal acceleration when turning
  double jerk_max = 5.0;                       // path jerk, m/s^3 (for the end-damping curve)
  double deceleration_max = 1.0;               // path deceleration, m/s^2 (end damping)
  // How the redundancy is resolved; the extension-rate resolutions fall back to the SNS when
  // no extension rate meets the bounds.
  dynamics::Resolution resolution = dynamics::Resolution::kPinvJoint;
};

struct TipPathOutput {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // u, unit
  double sdot_request = 0.0;                             // speed the operator asks for along u, m/s
  double sdot_joint_limit = 0.0;  // end-damping cap, m/s (+inf when no joint is near its end)
  int limiting_joint = -1;
  PathGeometry geometry;
};

class TipPath {
 public:
  TipPath(const dynamics::CraneModel& model, const TipPathConfig& config);

  void reset();

  // q: the reference configuration; v_cmd: the command (finite); sdot: the current path speed;
  // cylinder_force: the present cylinder forces (for min-ls-power; nullptr: none known).
  void update(const JointVector& q, const Eigen::Vector3d& v_cmd, double sdot, TipPathOutput& out,
              const JointVector* cylinder_force = nullptr);

 private:
  void resolve(const JointVector& q, const Eigen::Vector3d& u, JointVector& f1);

  const dynamics::CraneModel& model_;
  TipPathConfig config_;
  bool has_direction_ = false;
  Eigen::Vector3d direction_ = Eigen::Vector3d::UnitX();
  // Working data.
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jacobian_;
  dynamics::JointRateBounds bounds_;
  dynamics::SnsResult sns_;
  dynamics::ExtensionResolutionResult extension_;
  JointVector arms_, force_;
  const JointVector* cylinder_force_ = nullptr;
  // Extension rate per unit path speed of the last cycle, and this cycle's window around it.
  bool has_extension_rate_ = false;
  double extension_rate_ = 0.0;
  double extension_window_ = 0.0;  // +inf: no window
  JointVector q_shift_, f1_plus_, f1_minus_;
};

}  // namespace craneassist::scaling
