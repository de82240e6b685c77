#include "craneassist/scaling/tip_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "craneassist/dynamics/cylinders.hpp"
#include "craneassist/scaling/scaling_filter.hpp"

namespace craneassist::scaling {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kAtLimit = 1e-4;         // rad or m: a joint this close to its end is saturated
constexpr double kFreeRate = 1e3;         // joint rate bound per unit path speed of a free joint
constexpr double kRestSpeed = 1e-3;       // m/s: below this the direction follows the command
constexpr double kDifferenceStep = 1e-5;  // m of path for f''
constexpr double kEndDecelerationShare = 0.8;  // of the joint's deceleration, kept as margin

// Rotates unit vector a towards unit vector b by at most max_angle (rad).
Eigen::Vector3d turn_towards(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double max_angle) {
  const double cos_angle = std::clamp(a.dot(b), -1.0, 1.0);
  const double angle = std::acos(cos_angle);
  if (angle <= max_angle) return b;
  Eigen::Vector3d axis = a.cross(b);
  if (axis.norm() < 1e-9) {  // opposite: turn about any axis normal to a
    axis = a.unitOrthogonal();
  }
  axis.normalize();
  return Eigen::AngleAxisd(max_angle, axis) * a;
}

}  // namespace

TipPath::TipPath(const dynamics::CraneModel& model, const TipPathConfig& config)
    : model_(model), config_(config) {
  const int n = model.dof();
  bounds_.lower.setZero(n);
  bounds_.upper.setZero(n);
  q_shift_.setZero(n);
  f1_plus_.setZero(n);
  f1_minus_.setZero(n);
  arms_.setZero(n);
  force_.setZero(n);  // no loads known: min-ls-power then minimises flow at the margin
}

void TipPath::reset() {
  has_direction_ = false;
  has_extension_rate_ = false;
  direction_ = Eigen::Vector3d::UnitX();
}

void TipPath::resolve(const JointVector& q, const Eigen::Vector3d& u, JointVector& f1) {
  const int n = model_.dof();
  for (int i = 0; i < n; ++i) {
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    bounds_.upper[i] = q[i] >= joint.q_max - kAtLimit ? 0.0 : kFreeRate;
    bounds_.lower[i] = q[i] <= joint.q_min + kAtLimit ? 0.0 : -kFreeRate;
  }
  dynamics::tip_jacobian(model_, kin_, q, jacobian_);
  if (config_.resolution != dynamics::Resolution::kPinvJoint) {
    dynamics::cylinder_arms(model_, q, arms_);
    dynamics::ExtensionResolutionInput in;
    in.jacobian = &jacobian_;
    in.v_tip = u;
    in.dc_dq = &arms_;
    in.bounds = &bounds_;
    in.cylinder_force = cylinder_force_ != nullptr ? cylinder_force_ : &force_;
    // Within the window around the last cycle's extension rate, when that leaves any rate.
    const double lower = bounds_.lower[3], upper = bounds_.upper[3];
    const double lo = std::max(lower, extension_rate_ - extension_window_);
    const double hi = std::min(upper, extension_rate_ + extension_window_);
    if (std::isfinite(extension_window_) && lo <= hi) {
      bounds_.lower[3] = lo;
      bounds_.upper[3] = hi;
      dynamics::resolve_by_extension(model_, config_.resolution, in, extension_);
      bounds_.lower[3] = lower;
      bounds_.upper[3] = upper;
    } else {
      extension_.feasible = false;
    }
    if (!extension_.feasible)
      dynamics::resolve_by_extension(model_, config_.resolution, in, extension_);
    if (extension_.feasible) {
      f1 = extension_.qdot;  // J f1 = u exactly
      return;
    }
  }
  dynamics::sns_velocity_ik(jacobian_, u, bounds_, sns_);
  // J f1 = u exactly when the saturated resolution can do the task at all.
  f1 = sns_.task_scale > 1e-6 ? JointVector(sns_.qdot / sns_.task_scale) : JointVector::Zero(n);
}

void TipPath::update(const JointVector& q, const Eigen::Vector3d& v_cmd, double sdot,
                     TipPathOutput& out, const JointVector* cylinder_force) {
  cylinder_force_ = cylinder_force;
  const int n = model_.dof();
  const double speed_cmd = v_cmd.norm();
  if (speed_cmd > 0.0) {
    const Eigen::Vector3d u_cmd = v_cmd / speed_cmd;
    if (!has_direction_ || sdot < kRestSpeed) {
      direction_ = u_cmd;
      has_direction_ = true;
    } else {
      const double omega_max = config_.direction_change_acceleration / sdot;
      direction_ = turn_towards(direction_, u_cmd, omega_max * config_.period_s);
    }
    out.sdot_request = speed_cmd * std::max(0.0, direction_.dot(u_cmd));
  } else {
    out.sdot_request = 0.0;  // stop along the current direction
  }
  out.direction = direction_;

  // The window for the extension rate (see the header).
  extension_window_ = std::numeric_limits<double>::infinity();
  const bool by_extension = config_.resolution != dynamics::Resolution::kPinvJoint && n == 4;
  if (by_extension && has_extension_rate_ && sdot > kRestSpeed) {
    const auto& cyl = model_.cylinders[3];
    const double arm = std::abs(dynamics::cylinder_arm(cyl, q[3]));
    extension_window_ = 0.25 * cyl.a_max_m_s2 / arm * config_.period_s / sdot;
  }

  auto& g = out.geometry;
  resolve(q, direction_, g.f1);
  // f'' = d f'/ds = (df'/dq) f', central difference along the path.
  q_shift_ = q + kDifferenceStep * g.f1;
  resolve(q_shift_, direction_, f1_plus_);
  q_shift_ = q - kDifferenceStep * g.f1;
  resolve(q_shift_, direction_, f1_minus_);
  g.f2 = (f1_plus_ - f1_minus_) / (2.0 * kDifferenceStep);
  resolve(q, direction_, g.f1);  // restore the working data for q
  if (by_extension) {
    extension_rate_ = g.f1[3];
    has_extension_rate_ = true;
  }
  dynamics::cylinder_arms(model_, q, g.dc_dq);
  g.d2c_dq2.resize(n);
  for (int i = 0; i < n; ++i) {
    g.d2c_dq2[i] =
        dynamics::cylinder_arm_slope(model_.cylinders[static_cast<std::size_t>(i)], q[i]);
  }

  // End damping.
  out.sdot_joint_limit = g.f1.isZero(0.0) ? 0.0 : kInf;
  out.limiting_joint = -1;
  for (int i = 0; i < n; ++i) {
    const double rate = g.f1[i];  // joint rate per unit path speed
    if (std::abs(rate) < 1e-12) continue;
    const auto& joint = model_.joints[static_cast<std::size_t>(i)];
    const auto& cyl = model_.cylinders[static_cast<std::size_t>(i)];
    const double distance = rate > 0.0 ? joint.q_max - q[i] : q[i] - joint.q_min;
    const double decel =
        kEndDecelerationShare *
        std::min(cyl.a_max_m_s2 / std::abs(g.dc_dq[i]), std::abs(rate) * config_.deceleration_max);
    const double jerk = std::abs(rate) * config_.jerk_max;
    const double margin = 2.0 * std::abs(rate) * sdot * config_.period_s;
    const double joint_speed =
        max_speed_to_stop_within(std::max(distance - margin, 0.0), decel, jerk);
    const double cap = joint_speed / std::abs(rate);
    if (cap < out.sdot_joint_limit) {
      out.sdot_joint_limit = cap;
      out.limiting_joint = i;
    }
  }
}

}  // namespace craneassist::scaling
