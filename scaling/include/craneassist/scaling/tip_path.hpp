// The tip path of one control cycle (docs/algorithms.md section 1): the straight tip line
// x(s) = x0 + u s along the reference direction u, resolved into joint space.
//
// f'(s) resolves u through the redundancy resolution: for a four-joint loader exactly on the
// solution line (dynamics/null_space_resolution.hpp), otherwise by the SNS. f''(s) is the
// derivative of that resolution along the path (central finite difference). Scaling then changes
// only the scalar path speed, so the tip keeps the direction.
//
// Joint ends, ahead of time. Each joint moving towards an end may move, per metre of tip path, at
// most its distance to the end over the path's stopping distance from the intended speed (and no
// faster than its cylinder can decelerate): the velocity bounds shaped from the position limits
// of Flacco et al., per unit path speed. The resolution keeps every joint inside them through the
// null space while the other joints can do the task, and an end-avoidance term that grows inside
// the end zone (the last 10 % of its range) hands the motion over to the other joints
// before the bound is reached. So the tip does not slow down for a joint end as long as the other
// joints can carry on. When they cannot (the edge of the workspace along u), the end damping
// below caps the path speed at the speed from which a stop within the joint's deceleration and
// the path jerk covers the remaining distance: the tip stops smoothly at the edge, and moving
// back is never limited.
//
// Hydraulics, ahead of time. Cylinder speeds and the pump flow at the intended speed are bounds
// of the same resolution, so the null space also serves "as fast as the hydraulics allow".
//
// Smoothness. The optimum moves, and with piecewise costs (min-flow, min-ls-power) it jumps when
// another cylinder comes to rest first. The solution follows it along the null space with the
// jerk-limited filter of the scaling (minimum time, no overshoot): the null-space part of each
// joint's acceleration within half its limit, ramped in 0.3 s. Bounded joint jerk matters on a
// real valve: a spool's lag turns joint jerk into tracking error, and unequal errors bend the tip
// path.
//
// Singular poses. The tip over the slew axis makes the lateral direction unreachable (J loses
// rank); the boom stretched straight with the extension at its end does the same for a radial
// motion. Near them the joint rates per unit path speed grow without bound: the cylinder-speed
// caps of the scaling fall to zero with the distance (TipScaler reads them ahead along f''), so
// the tip slows smoothly and approaches the pose asymptotically; every joint stays within its
// speed, and moving away is never limited. near_singular says so.
#pragma once

#include <Eigen/Core>
#include <array>

#include "craneassist/dynamics/kinematics.hpp"
#include "craneassist/dynamics/null_space_resolution.hpp"
#include "craneassist/dynamics/redundancy.hpp"
#include "craneassist/dynamics/resolutions.hpp"
#include "craneassist/scaling/path_constraints.hpp"

namespace craneassist::scaling {

struct TipPathConfig {
  double period_s = 0.01;
  double jerk_max = 5.0;          // path jerk, m/s^3 (end damping)
  double deceleration_max = 1.0;  // path deceleration, m/s^2 (end damping)
  double flow_reserve = 0.0;      // share of pump flow and cylinder speeds kept (hydraulic bounds)
  dynamics::Resolution resolution = dynamics::Resolution::kPinvJoint;
  // End avoidance: the term acts within this share of a joint's range from an end, with this
  // weight where the joint is halfway into the zone (0: off).
  double end_zone = 0.1;
  double end_weight = 1.0;
  // A pose is near singular when the weakest direction's tip speed at full cylinder speeds is
  // below this, m/s.
  double singularity_speed = 0.25;
};

struct TipPathInput {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // u, unit
  double sdot = 0.0;                                     // present path speed, m/s (>= 0)
  double intended_speed = 0.0;  // the speed the motion heads for, m/s (>= sdot; shapes bounds)
  // The present cylinder forces, N (min-ls-power resolves at them), when known; unknown: the
  // resolution assumes no loads (min-ls-power then minimises flow at the margin). Copied in
  // update(); TipPath keeps no reference to the caller's data.
  bool forces_known = false;
  JointVector cylinder_force;  // one per joint when forces_known
};

struct TipPathOutput {
  PathGeometry geometry;
  double sdot_joint_limit = 0.0;  // end damping, m/s (+inf when no joint is near its end)
  int limiting_joint = -1;
  // Path length left before the first joint reaches its end (less a margin; +inf: none) and
  // the path deceleration and jerk a stop may use (the cylinders' accelerations along f'): the
  // scaler brakes when a stop from its present speed and acceleration needs that length.
  double end_distance_m = 0.0;
  double stop_deceleration_m_s2 = 0.0;
  double stop_jerk_m_s3 = 0.0;
  dynamics::NullSpaceStatus status = dynamics::NullSpaceStatus::kOptimal;
  // Tip speed in the weakest direction with every cylinder at full speed (joints pinned at an end
  // left out), m/s, and whether the direction leans into it at a near-singular pose.
  double weakest_speed_m_s = 0.0;
  bool near_singular = false;
};

class TipPath {
 public:
  TipPath(const dynamics::CraneModel& model, const TipPathConfig& config);

  // Forgets the previous solution (no window on the next update).
  void reset();

  // q: the reference configuration. No allocation, no exception.
  void update(const JointVector& q, const TipPathInput& in, TipPathOutput& out) noexcept;

 private:
  struct Shape {  // per-update values shared by the three resolves
    double intended_speed = 0.0;
    double stop_length = 0.0;  // path length to stop from the intended speed
    double sdot = 0.0;         // present path speed
    bool smooth = false;       // move the null coordinate jerk-limited from the previous solution
  };
  void resolve(const JointVector& q, const Eigen::Vector3d& u, const Shape& shape, JointVector& f1,
               dynamics::NullSpaceStatus& status) noexcept;
  void weakest_direction(const Eigen::Vector3d& u, const JointVector& arms,
                         TipPathOutput& out) noexcept;

  const dynamics::CraneModel& model_;
  TipPathConfig config_;
  // The previous cycle's f', direction and null-coordinate rate (1/s), and whether there are any.
  bool has_previous_ = false;
  JointVector previous_f1_;
  double null_rate_ = 0.0, null_rate_next_ = 0.0;
  JointVector target_f1_, heading_f1_;  // the resolution's optimum (of the last resolve, at q)
  Eigen::Vector3d previous_u_ = Eigen::Vector3d::UnitX();
  // Working data.
  JointVector joint_accel_max_;                      // at the configuration being resolved
  std::array<bool, dynamics::kMaxJoints> at_end_{};  // pinned at an end
  dynamics::KinematicsData kin_;
  dynamics::TaskJacobian jacobian_, jacobian_at_q_;
  dynamics::SolutionLine line_;
  dynamics::NullSpaceProblem problem_;
  dynamics::NullSpaceResult result_;
  dynamics::JointRateBounds bounds_;
  dynamics::SnsResult sns_;
  JointVector arms_, q_shift_, f1_plus_, f1_minus_;
  JointVector force_;  // the present update's cylinder forces (zero: unknown); problem_ reads it
};

}  // namespace craneassist::scaling
